"""Lifted distributional Gauss curvature of Regge metrics: the §4 example of
Gopalakrishnan–Neunteufel–Schöberl–Wardetzky (2024).

    python -m igl_hhj.benchmarks.regge_convergence [--out DIR] [--levels 1 2 3 4 5 6] [--quick]
    python -m igl_hhj.benchmarks.regge_convergence --timing [--timing-levels 6 7 8]

Metric of the graph of ``f = (x²+y²)/2 - (x⁴+y⁴)/12`` on ``(0, 1)²``; right and
bottom sides Dirichlet (``K̄`` prescribed), left and top Neumann (``κ̄`` and the
corner angle of ``ḡ``); perturbed structured meshes with ``2^(2l+1)`` triangles
(recipe and seed of the design note ``regge.md``).  ``g_h`` = canonical Regge
interpolant of degree k (eq. 3.1), ``K_h`` ∈ Lagrange ``P^p``:

* main runs ``p = k`` for ``k = 1, 2, 3`` (Definition 2.3): L2 and H⁻¹ errors
  (H⁻¹ = ``‖w‖_H¹`` of the ``P^{p+2}`` solution of ``-Δw = K̄ - K_h``), also for
  the densitized lifting ``K_h ω_h`` vs ``K̄ ω̄`` (Remark 3.3);
* controls: ``p = k + 1`` (the older choice, one order less) and ``k = 0``,
  ``p = 1`` (angle deficits: no L2 convergence).

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
#: Paper 004, §4 / targets.md: proven and observed rates for p = k: L2 k+1, H⁻¹ k+2.
PAPER_RATES = {1: (2, 3), 2: (3, 4), 3: (4, 5)}


def solve_example(k, l, p=None, densitized=False):
    """Run the §4 example once; returns a dict of errors and timings."""
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
    out = dict(k=k, l=l, p=p, densitized=densitized, faces=int(F.shape[0]), dofs=int(Kh.space.n_dofs),
               h=float(np.sqrt(2) * 2.0 ** -l), L2=Kh.l2_error(exact), Hm1=Kh.h_minus1_error(exact),
               t_lift=t1 - t0)
    out["t_total"] = time.perf_counter() - t0
    return out


def _eoc(es):
    es = np.asarray(es, dtype=float)
    return [None] + list(np.log2(es[:-1] / es[1:]))


def run(levels=(1, 2, 3, 4, 5, 6), ks=(1, 2, 3), controls=True, densitized=True,
        control_levels=None, progress=False):
    """Run the study. Returns a dict ``{"runs": [...], "levels": ...}``; each run is a
    list of per-level dicts (see :func:`solve_example`) with ``eoc_L2``/``eoc_Hm1``."""
    levels = list(levels)
    control_levels = list(control_levels or [l for l in levels if l <= 5])
    jobs = [(f"k={k}, p={k}", k, k, False, levels) for k in ks]
    if densitized:
        jobs += [(f"k={k}, p={k}, densitized", k, k, True, levels) for k in ks]
    if controls:
        jobs += [(f"k={k}, p={k + 1}", k, k + 1, False, control_levels) for k in ks if k <= 2]
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
        for key in ("L2", "Hm1"):
            for r, e in zip(rows, _eoc([r[key] for r in rows])):
                r["eoc_" + key] = e
        runs[name] = rows
    if bar is not None:
        bar.close()
    return {"runs": runs, "levels": levels}


def _f(x, fmt="{:.4e}"):
    return "—" if x is None else fmt.format(x)


def markdown(result):
    lines = ["# Regge metric layer: §4 example of Gopalakrishnan et al. 2024", "",
             "Quarter domain (0,1)², mixed Dirichlet/Neumann, perturbed structured meshes (seed 0). "
             "EOC = log2(e_{l-1}/e_l). Reference = design note `regge.md` (independent "
             "implementation, same meshes); paper rates: L2 k+1, H⁻¹ k+2 for p = k.", ""]
    for name, rows in result["runs"].items():
        k, p = rows[0]["k"], rows[0]["p"]
        main = (p == k and not rows[0]["densitized"])
        lines += [f"## {name}" + (f"  (paper rates: L2 {PAPER_RATES[k][0]}, H⁻¹ {PAPER_RATES[k][1]})"
                                  if main and k in PAPER_RATES else ""), ""]
        if main:
            lines += ["| l | #T | ‖K_h−K̄‖_L2 | EOC | reference | ‖K_h−K̄‖_H⁻¹ | EOC | reference | time [s] |",
                      "|---|---|---|---|---|---|---|---|---|"]
        else:
            lines += ["| l | #T | L2 error | EOC | H⁻¹ error | EOC | time [s] |", "|---|---|---|---|---|---|---|"]
        for r in rows:
            ref = REFERENCE.get((k, r["l"])) if main else None
            if main:
                lines.append(f"| {r['l']} | {r['faces']} | {_f(r['L2'])} | {_f(r['eoc_L2'], '{:.2f}')} | "
                             f"{_f(ref and ref[0])} | {_f(r['Hm1'])} | {_f(r['eoc_Hm1'], '{:.2f}')} | "
                             f"{_f(ref and ref[1])} | {r['t_total']:.2f} |")
            else:
                lines.append(f"| {r['l']} | {r['faces']} | {_f(r['L2'])} | {_f(r['eoc_L2'], '{:.2f}')} | "
                             f"{_f(r['Hm1'])} | {_f(r['eoc_Hm1'], '{:.2f}')} | {r['t_total']:.2f} |")
        if name in REFERENCE_CONTROLS:
            lines += ["", f"Reference (regge.md): {REFERENCE_CONTROLS[name]}."]
        lines.append("")
    return "\n".join(lines)


def plot(result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, key, title in zip(axes, ("L2", "Hm1"), ("‖K_h − K̄‖_L2", "‖K_h − K̄‖_H⁻¹")):
        hs_all = set()
        for name, rows in result["runs"].items():
            if rows[0]["densitized"]:
                continue
            h = np.array([r["h"] for r in rows])
            e = np.array([r[key] for r in rows])
            hs_all.update(h.tolist())
            main = rows[0]["p"] == rows[0]["k"]
            line, = ax.loglog(h, e, "-" if main else "--", marker="o", ms=4, label=name)
            k = rows[0]["k"]
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
        ax.set_xlabel("h = √2·2^-l  (dotted: paper rate)")
        ax.set_title(title)
        ax.grid(True, which="major", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("Lifted Gauss curvature of Regge metrics (Gopalakrishnan et al. 2024, §4)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


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
