"""Lifted distributional Gauss curvature of Regge metrics: the §4 example of
Gopalakrishnan–Neunteufel–Schöberl–Wardetzky (2024).

    python -m igl_hhj.benchmarks.regge_convergence [--out DIR] [--levels 1 2 3 4 5 6] [--quick]
    python -m igl_hhj.benchmarks.regge_convergence --timing [--timing-levels 6 7 8]

Metric of the graph of ``f = (x²+y²)/2 - (x⁴+y⁴)/12`` on ``(0, 1)²``; right and
bottom sides Dirichlet (``K̄`` prescribed), left and top Neumann (``κ̄`` and the
corner angle of ``ḡ``); perturbed structured meshes with ``2^(2l+1)`` triangles
(recipe and seed of the design note ``regge.md``).  ``g_h`` = canonical Regge
interpolant of degree k (eq. 3.1), ``K_h`` ∈ Lagrange ``P^p``:

* main runs ``p = k`` for ``k = 1, 2, 3`` (Definition 2.3): L2, H⁻¹ (H⁻¹ = ``‖w‖_H¹`` of
  the ``P^{p+2}`` solution of ``-Δw = K̄ - K_h``) and broken H¹_h errors (Corollary 3.9,
  r = 1), and the densitized errors ``‖K_h ω_h - K̄ ω̄‖`` of the same ``K_h``
  (Theorem 3.1, Corollary 3.2; ``ω_h = √det g_h``);
* the Euclidean-mass lifting (the Euclidean L² projection of ``K_h ω_h``) against ``K̄ ω̄``;
* controls: ``p = k + 1`` (the older choice, one order less), ``p = k + 2`` (two orders
  less) and ``p = k - 1`` (one order less), as observed in the paper's closing remarks,
  and ``k = 0``, ``p = 1`` (angle deficits: no L2 convergence).

Writes ``regge.md`` (tables with the reference numbers of ``regge.md`` beside
ours), ``regge.json`` and ``regge_convergence.png`` to ``--out`` (default
``./benchmark-results/``).  EOC = ``log2(e_{l-1} / e_l)`` (h halves per level).

``--timing``: wall time of ``igl_hhj.regge.gauss_curvature(V, F)`` (the P1 lifting of the
angle deficits, ``M K_h = Θ`` solved by the lumped-preconditioned compiled PCG) on
icosphere(l), beside a sparse LU of the same mass matrix (the previous solver) and
``igl.gaussian_curvature`` (angle deficits only, no solve), with the largest difference
between the two liftings.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

# --------------------------------------------------------------------------- reference data
#: Reference numbers from the design note ``shared/design/regge.md`` (an independent
#: implementation of the same definitions on the same meshes, seed 0):
#: (k, l) -> (‖K_h - K̄‖_L2, ‖K_h - K̄‖_H⁻¹), K_h ∈ P^k.
REFERENCE = {
    (1, 4): (5.5821e-04, 7.6273e-06), (1, 5): (1.3225e-04, 8.6741e-07), (1, 6): (3.2502e-05, 1.0651e-07),
    (2, 4): (2.2474e-05, 2.1779e-07), (2, 5): (2.7699e-06, 1.3421e-08), (2, 6): (3.5078e-07, 8.5455e-10),
    (3, 4): (3.3812e-07, 1.8918e-09), (3, 5): (2.3274e-08, 6.7515e-11), (3, 6): (1.4668e-09, 2.1319e-12),
}
#: Reference rates (regge.md "Controls"): k = 1 lifted to P^2 and k = 0 lifted to P^1.
REFERENCE_CONTROLS = {"k=1, p=2": "L2 rate 0.95, H⁻¹ rate 1.92",
                      "k=0, p=1": "L2 stalls at ≈ 1.4e-2, H⁻¹ rate ≈ 1"}
#: Paper 004, §4 / targets.md: proven and observed rates for p = k: L2 k+1, H⁻¹ k+2
#: (Theorem 3.1/3.8, Corollary 3.2/3.9 with r = 0); the broken H¹_h norm (r = 1): k.
PAPER_RATES = {1: (2, 3), 2: (3, 4), 3: (4, 5)}
#: Corollary 3.2 / 3.9 with r = 1, l = k + 1: ‖·‖_{H¹_h} = O(h^k).
PAPER_H1_RATE = {1: 1, 2: 2, 3: 3}
#: Paper §4, closing remarks (observed, not proven): lifting degree p = k + 2 loses two
#: orders against p = k, p = k - 1 (k ≥ 2) loses one: (L2, H⁻¹) rates.
PAPER_CONTROL_RATES = {"p=k+2": lambda k: (k - 1, k), "p=k-1": lambda k: (k, k + 1),
                       "p=k+1": lambda k: (k, k + 1)}


def solve_example(k, l, p=None, densitized=False):
    """Run the §4 example once; returns a dict of errors and timings.

    ``densitized=False`` (Definition 2.3, the ``ω_h``-weighted lifting ``K_h``): ``L2``,
    ``Hm1``, ``H1`` (broken H¹_h) of ``K_h - K̄`` and ``L2_dens``, ``Hm1_dens``, ``H1_dens`` of
    ``K_h ω_h - K̄ ω̄`` — the densitized error of Theorem 3.1 / Corollary 3.2, the pointwise
    product of the same ``K_h`` with ``ω_h = √det g_h``.  ``densitized=True``: the lifting
    with the Euclidean mass matrix (``∫ (Kω)_h u dx = K̃ω(g_h)(u)``, i.e. the Euclidean L²
    projection of ``K_h ω_h`` onto ``V_h^p``), errors against ``K̄ ω̄``."""
    from ..regge import interpolate, lift_gauss_curvature
    from ..regge import examples as ex

    p = max(k, 1) if p is None else p
    t0 = time.perf_counter()
    P, F = ex.structured_square(l, seed=0)
    gh = interpolate(P, F, ex.graph_metric, k)
    Kh = lift_gauss_curvature(gh, p, dirichlet=ex.graph_dirichlet,
                              dirichlet_values=(ex.graph_densitized_curvature if densitized
                                                else ex.graph_gauss_curvature),
                              neumann_curvature=ex.graph_boundary_geodesic_curvature,
                              densitized=densitized)
    t1 = time.perf_counter()
    exact = ex.graph_densitized_curvature if densitized else ex.graph_gauss_curvature
    grad = ex.graph_densitized_curvature_gradient if densitized else ex.graph_gauss_curvature_gradient
    out = dict(k=k, l=l, p=p, densitized=densitized, faces=int(F.shape[0]), dofs=int(Kh.space.n_dofs),
               h=float(np.sqrt(2) * 2.0 ** -l), L2=Kh.l2_error(exact), Hm1=Kh.h_minus1_error(exact),
               H1=Kh.h1_error(exact, grad), t_lift=t1 - t0)
    if not densitized:
        dens = ex.graph_densitized_curvature
        out.update(L2_dens=Kh.l2_error(dens, times_omega_h=True),
                   Hm1_dens=Kh.h_minus1_error(dens, times_omega_h=True),
                   H1_dens=Kh.h1_error(dens, ex.graph_densitized_curvature_gradient, times_omega_h=True))
    out["t_total"] = time.perf_counter() - t0
    return out


def _eoc(es):
    es = np.asarray(es, dtype=float)
    return [None] + list(np.log2(es[:-1] / es[1:]))


def _control_jobs(ks, levels):
    jobs = [(f"k={k}, p={k + 1}", k, k + 1, levels) for k in ks if k <= 2]
    jobs += [(f"k={k}, p={k + 2}", k, k + 2, levels) for k in ks]
    jobs += [(f"k={k}, p={k - 1}", k, k - 1, levels) for k in ks if k >= 2]
    return jobs


def run(levels=(1, 2, 3, 4, 5, 6), ks=(1, 2, 3), controls=True, densitized=True,
        control_levels=None, progress=False):
    """Run the study. Returns a dict ``{"runs": [...], "levels": ...}``; each run is a
    list of per-level dicts (see :func:`solve_example`) with ``eoc_<error>``.

    Runs: ``p = k`` (with the densitized errors of the same ``K_h``); with
    ``densitized`` the Euclidean-mass lifting; with ``controls`` the liftings
    ``p = k + 1`` (k ≤ 2), ``p = k + 2``, ``p = k - 1`` (k ≥ 2) and ``k = 0, p = 1``."""
    levels = list(levels)
    control_levels = list(control_levels or [l for l in levels if l <= 5])
    jobs = [(f"k={k}, p={k}", k, k, False, levels) for k in ks]
    if densitized:
        jobs += [(f"k={k}, p={k}, Euclidean-mass lifting", k, k, True, levels) for k in ks]
    if controls:
        jobs += [(name, k, p, False, lv) for name, k, p, lv in _control_jobs(ks, control_levels)]
        jobs += [("k=0, p=1", 0, 1, False, levels)]
    bar = None
    if progress:
        try:
            from tqdm import tqdm
            bar = tqdm(total=sum(len(j[4]) for j in jobs), desc="regge_convergence", disable=None)
        except ImportError:
            bar = None
    runs = {}
    for name, k, p, dens, lv in jobs:
        rows = []
        for l in lv:
            rows.append(solve_example(k, l, p, dens))
            if bar is not None:
                bar.update(1)
        for key in ("L2", "Hm1", "H1", "L2_dens", "Hm1_dens", "H1_dens"):
            if key in rows[0]:
                for r, e in zip(rows, _eoc([r[key] for r in rows])):
                    r["eoc_" + key] = e
        runs[name] = rows
    if bar is not None:
        bar.close()
    return {"runs": runs, "levels": levels}


def _f(x, fmt="{:.4e}"):
    return "—" if x is None else fmt.format(x)


def _control_rates(k, p):
    key = {k + 2: "p=k+2", k - 1: "p=k-1", k + 1: "p=k+1"}.get(p)
    return key, (PAPER_CONTROL_RATES[key](k) if key else None)


def markdown(result):
    lines = ["# Regge metric layer: §4 example of Gopalakrishnan et al. 2024", "",
             "Quarter domain (0,1)², mixed Dirichlet/Neumann, perturbed structured meshes (seed 0). "
             "EOC = log2(e_{l-1}/e_l). Reference = design note `regge.md` (independent "
             "implementation, same meshes); paper rates: L2 k+1, H⁻¹ k+2, broken H¹_h k for p = k "
             "(Theorem 3.1/3.8, Corollary 3.2/3.9 with r = 0, 1).", ""]
    for name, rows in result["runs"].items():
        k, p = rows[0]["k"], rows[0]["p"]
        main = (p == k and not rows[0]["densitized"])
        if main and k in PAPER_RATES:
            lines += [f"## {name}  (paper rates: L2 {PAPER_RATES[k][0]}, H⁻¹ {PAPER_RATES[k][1]}, "
                      f"H¹_h {PAPER_H1_RATE[k]})", ""]
        elif rows[0]["densitized"]:
            lines += [f"## {name}", "",
                      "The Euclidean mass matrix instead of the ω_h-weighted one: the Euclidean L² "
                      "projection of K_h ω_h onto V_h^p (not the paper's densitized quantity, which is "
                      "the product K_h ω_h of the table above), errors against K̄ ω̄.", ""]
        else:
            key, rates = _control_rates(k, p)
            lines += [f"## {name}" + (f"  (paper §4, observed: L2 {rates[0]}, H⁻¹ {rates[1]})"
                                      if rates and key != "p=k+1" else ""), ""]
        if main:
            lines += ["| l | #T | ‖K_h−K̄‖_L2 | EOC | reference | ‖K_h−K̄‖_H⁻¹ | EOC | reference | "
                      "‖K_h−K̄‖_H¹_h | EOC | time [s] |",
                      "|---|---|---|---|---|---|---|---|---|---|---|"]
        else:
            lines += ["| l | #T | L2 error | EOC | H⁻¹ error | EOC | H¹_h error | EOC | time [s] |",
                      "|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            ref = REFERENCE.get((k, r["l"])) if main else None
            if main:
                lines.append(f"| {r['l']} | {r['faces']} | {_f(r['L2'])} | {_f(r['eoc_L2'], '{:.2f}')} | "
                             f"{_f(ref and ref[0])} | {_f(r['Hm1'])} | {_f(r['eoc_Hm1'], '{:.2f}')} | "
                             f"{_f(ref and ref[1])} | {_f(r['H1'])} | {_f(r['eoc_H1'], '{:.2f}')} | "
                             f"{r['t_total']:.2f} |")
            else:
                lines.append(f"| {r['l']} | {r['faces']} | {_f(r['L2'])} | {_f(r['eoc_L2'], '{:.2f}')} | "
                             f"{_f(r['Hm1'])} | {_f(r['eoc_Hm1'], '{:.2f}')} | {_f(r['H1'])} | "
                             f"{_f(r['eoc_H1'], '{:.2f}')} | {r['t_total']:.2f} |")
        if main and "L2_dens" in rows[0]:
            lines += ["", f"Densitized error of the same K_h (Theorem 3.1, Corollary 3.2: "
                      f"K_h ω_h − K̄ ω̄, ω_h = √det g_h), and pure / densitized:", "",
                      "| l | ‖K_hω_h−K̄ω̄‖_L2 | EOC | pure/dens. | ‖·‖_H⁻¹ | EOC | pure/dens. | "
                      "‖·‖_H¹_h | EOC |",
                      "|---|---|---|---|---|---|---|---|---|"]
            for r in rows:
                lines.append(f"| {r['l']} | {_f(r['L2_dens'])} | {_f(r['eoc_L2_dens'], '{:.2f}')} | "
                             f"{r['L2'] / r['L2_dens']:.3f} | {_f(r['Hm1_dens'])} | "
                             f"{_f(r['eoc_Hm1_dens'], '{:.2f}')} | {r['Hm1'] / r['Hm1_dens']:.3f} | "
                             f"{_f(r['H1_dens'])} | {_f(r['eoc_H1_dens'], '{:.2f}')} |")
        if name in REFERENCE_CONTROLS:
            lines += ["", f"Reference (regge.md): {REFERENCE_CONTROLS[name]}."]
        lines.append("")
    return "\n".join(lines)


def plot(result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), dpi=110)
    for ax, key, title in zip(axes, ("L2", "Hm1"), ("‖K_h − K̄‖_L2", "‖K_h − K̄‖_H⁻¹")):
        hs_all = set()
        for name, rows in result["runs"].items():
            if rows[0]["densitized"]:
                continue
            h = np.array([r["h"] for r in rows])
            e = np.array([r[key] for r in rows])
            hs_all.update(h.tolist())
            k, p = rows[0]["k"], rows[0]["p"]
            main = p == k
            style = {0: "-", 1: "--", 2: "-.", -1: ":"}[p - k] if k else "-"
            line, = ax.loglog(h, e, style, marker="o" if main else ".", ms=4, label=name,
                              color=f"C{k}" if k else "0.45", lw=1.6 if main else 1.1)
            if main and k in PAPER_RATES and len(h) >= 3:
                rate = PAPER_RATES[k][0 if key == "L2" else 1]
                hh = h[-3:]
                ax.loglog(hh, 0.5 * e[-1] * (hh / hh[-1]) ** rate, ":", color=line.get_color(), lw=1)
                ax.text(hh[-1], 0.35 * e[-1], f"h^{rate}", fontsize=7, color=line.get_color(),
                        ha="right", va="top")
        hs = sorted(hs_all)
        ax.set_xticks(hs)
        ax.set_xticklabels([f"{x:.3g}" for x in hs], fontsize=7)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("h = √2·2^-l  (thin dotted: paper rate)")
        ax.set_title(title)
        ax.grid(True, which="major", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("Lifted Gauss curvature of Regge metrics (Gopalakrishnan et al. 2024, §4); colour: k, "
                 "line: p = k solid, k+1 dashed, k+2 dash-dot, k−1 dotted", fontsize=10)
    fig.tight_layout()
    fig.canvas.draw()
    image = np.asarray(fig.canvas.buffer_rgba())
    plt.close(fig)
    from ..viewer.render import save_png
    if not save_png(path, image):                        # Pillow missing: matplotlib's RGB PNG
        import matplotlib.image
        matplotlib.image.imsave(path, image)


def timing_study(levels=(6, 7, 8), repeat=2):
    """Rows of (#V, seconds of gauss_curvature, of the same lifting by SuperLU, of
    igl.gaussian_curvature, max |difference| of the two liftings)."""
    import igl
    import scipy.sparse.linalg as spla

    from ..mesh import TriangleMesh
    from ..regge import gauss_curvature
    from ..regge.edge_metric import angle_defect, intrinsic_mass_matrix
    from ..surfaces import icosphere

    def best(fn):
        t_min, out = np.inf, None
        for _ in range(repeat):
            t = time.perf_counter()
            out = fn()
            t_min = min(t_min, time.perf_counter() - t)
        return t_min, out

    def superlu(V, F):
        m = TriangleMesh(V, F)
        l_sq = m.edge_lengths ** 2
        M = intrinsic_mass_matrix(l_sq, m.F, m.n_vertices)
        return spla.splu(M.tocsc()).solve(angle_defect(l_sq, m.F, boundary="natural"))

    rows = []
    for level in levels:
        V, F = icosphere(level)
        t_pcg, K = best(lambda: gauss_curvature(V, F))
        t_lu, K_lu = best(lambda: superlu(V, F))
        t_igl, _ = best(lambda: igl.gaussian_curvature(V, F))
        rows.append({"n_vertices": len(V), "pcg": t_pcg, "superlu": t_lu, "igl_angle_defect": t_igl,
                     "max_diff": float(np.abs(K - K_lu).max())})
    return rows


def timing_markdown(rows):
    lines = ["| #V | gauss_curvature (PCG) s | same lifting by SuperLU s | igl.gaussian_curvature s | max diff |",
             "|---|---|---|---|---|"]
    lines += [f"| {r['n_vertices']:,} | {r['pcg']:.3f} | {r['superlu']:.3f} | {r['igl_angle_defect']:.3f} | "
              f"{r['max_diff']:.1e} |" for r in rows]
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="benchmark-results", help="output folder (default ./benchmark-results/)")
    ap.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4, 5, 6],
                    help="mesh levels l (2^l x 2^l squares, each cut in two; default 1-6)")
    ap.add_argument("--quick", action="store_true", help="levels 1-4 only")
    ap.add_argument("--no-plot", action="store_true", help="no matplotlib plot")
    ap.add_argument("--timing", action="store_true",
                    help="only the timing of gauss_curvature on icosphere meshes")
    ap.add_argument("--timing-levels", type=int, nargs="+", default=[6, 7, 8],
                    help="icosphere levels of --timing (default 6 7 8: 41k, 164k, 655k vertices)")
    args = ap.parse_args(argv)
    if args.timing:
        print(timing_markdown(timing_study(args.timing_levels)))
        return
    levels = [1, 2, 3, 4] if args.quick else args.levels
    res = run(levels=levels, progress=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = markdown(res)
    (out / "regge.md").write_text(md)
    (out / "regge.json").write_text(json.dumps(res, indent=1))
    if not args.no_plot:
        plot(res, out / "regge_convergence.png")
    print(md)
    print(f"\nwrote {out / 'regge.md'}")


if __name__ == "__main__":
    main()
