"""Paper 001 (Stein, Grinspun, Jacobson, Wardetzky), §6: mixed P1 biharmonic experiments.

Run as ``python -m igl_hhj.benchmarks.biharmonic_convergence [--levels 5] [--perf]
[--perf-max-vertices 600000] [--out benchmark-results]``.

Convergence part (§6.1, §6.2, §5.3): for the clamped hemisphere (Fig. 2), the
clamped spherical cap θ ≤ π/4 (Fig. 3), the Schwarz lantern (Fig. 4: m ~ n, and
the degenerate regimes m ~ n² and n ~ m²; m ~ n² with both readings of "perturbed
on the order of (mean edge length)²": a random vector of the cube ``ℓ̄² [-1, 1]³`` or
``± ℓ̄²`` along the normal), the closed sphere (Thm 5.4), and Navier boundary
conditions (lantern ``u = cos φ sin πz``; hemisphere with inhomogeneous data), the
L2 and H1 errors of u1 and of u2 against h on non-uniform mesh sequences, with EOCs printed beside the paper's proven / observed rates;
a log-log PNG and a CSV of all numbers.

Performance part (``--perf``): setup + solve time against #V on clamped
hemisphere meshes up to ``--perf-max-vertices``, in the same run for
(a) ``biharmonic_solve`` with the consistent mass (the paper's method),
(b) ``biharmonic_solve`` with the barycentric lumped mass,
(c) a plain direct sparse solve of the lumped ``K M⁻¹ K`` system
    (``scipy.sparse.linalg.spsolve``, SuperLU with its default ordering),
(e) one sparse Cholesky factorisation (CHOLMOD via cholespy) of that lumped
    ``K M⁻¹ K`` system alone, the yardstick of the full-mass method (target:
    within 2×; the ratio is printed),
(d) ``igl.harmonic(V, F, b, g, k=2)`` against ``biharmonic_solve(..., f=0,
    mass="voronoi", g=g)`` (the same discrete problem; max difference reported).
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import time

import numpy as np

from . import progress as progress_bar
from ..biharmonic import BiharmonicSolver, biharmonic_solve, mass_matrix, stiffness_matrix
from ..convergence import eoc
from ..mesh import TriangleMesh
from ..solvers import _cholmod
from ..surfaces.biharmonic_problems import (
    Hemisphere,
    LanternProblem,
    SphereHarmonicsProblem,
    SphericalCapProblem,
    biharmonic_errors,
    cap_mesh,
    lantern_sequence,
)

# ---------------------------------------------------------------- paper data
# Paper 001: proven rates (Thm 5.3, Cor 5.1, Thm 5.2 for surfaces with boundary;
# Thm 5.4 without boundary) and what §6 reports as observed (Fig. 2-4 are
# plots without tables; these are the statements of the text).
PAPER = {
    "hemisphere": {"u1_L2": "1 (Thm 5.3)", "u1_H1": "3/4 (Cor 5.1)", "u2_L2": "1/2 (Thm 5.2)",
                   "observed": "Fig. 2: convergence 'with rates at least as good as predicted'; "
                               "'no convergence in the H1 norm of u2' (column ‖∇(u2-I_h u2)‖L2)"},
    "cap": {"u1_L2": "-", "u1_H1": "-", "u2_L2": "-",
            "observed": "Fig. 3: 'we still empirically observe convergence' ((C2) relaxed)"},
    "lantern m~n": {"u1_L2": "-", "u1_H1": "-", "u2_L2": "-",
                    "observed": "Fig. 4: converges, 'we even observe a rate of h^2'"},
    "lantern m~n^2": {"u1_L2": "-", "u1_H1": "-", "u2_L2": "-",
                      "observed": "Fig. 4: 'ceases to converge' (surface area does not converge); "
                                  "perturbation c ℓ̄² ξ, ξ uniform in [-1, 1]³"},
    "lantern m~n^2, normal": {"u1_L2": "-", "u1_H1": "-", "u2_L2": "-",
                              "observed": "Fig. 4: 'ceases to converge'; the same meshes perturbed "
                                          "along the normal by ± ℓ̄² (the other reading of the wording)"},
    "lantern n~m^2": {"u1_L2": "-", "u1_H1": "-", "u2_L2": "-",
                      "observed": "(not in the paper; the classic Schwarz regime: area diverges)"},
    "closed sphere": {"u1_L2": "2 (Thm 5.4)", "u1_H1": "1 (Thm 5.4)", "u2_L2": "2 (Thm 5.4)",
                      "observed": "(§5.3, no experiment)"},
    "lantern m~n, navier": {"u1_L2": "-", "u1_H1": "-", "u2_L2": "-",
                            "observed": "(not in the paper: Navier u = Δu = 0, u = cos φ sin πz)"},
    "hemisphere, navier data": {"u1_L2": "-", "u1_H1": "-", "u2_L2": "-",
                                "observed": "(not in the paper: inhomogeneous Navier data g = u, w = -Δu)"},
}

EXACT_AREA = {"hemisphere": 2 * np.pi, "cap": 2 * np.pi * (1 - np.cos(np.pi / 4)),
              "lantern m~n": 2 * np.pi, "lantern m~n^2": 2 * np.pi, "lantern m~n^2, normal": 2 * np.pi,
              "lantern n~m^2": 2 * np.pi, "closed sphere": 4 * np.pi, "lantern m~n, navier": 2 * np.pi,
              "hemisphere, navier data": 2 * np.pi}

KEYS = [("u1_L2", "‖u1-u‖L2"), ("u1_H1", "‖∇(u1-I_h u)‖L2"), ("u1_H1_grad", "‖∇(u1-u)‖L2"),
        ("u2_L2", "‖u2+Δu‖L2"), ("u2_H1", "‖∇(u2-I_h u2)‖L2")]


def _cases(levels, seed):
    """(name, problem, solve kwargs, list of (V, F))."""
    L = max(levels, 2)
    H = Hemisphere()
    C = SphericalCapProblem(np.pi / 4)
    S = SphereHarmonicsProblem()
    Lp = LanternProblem()
    Ln = LanternProblem("navier")
    Hn = SphereHarmonicsProblem(bc="clamped")     # hemisphere meshes; Navier data passed below
    lant = lambda regime, n, mode="cube": [(V, F) for V, F, _, _ in  # noqa: E731
                                           lantern_sequence(regime, n, perturbation=1.0, seed=seed, mode=mode)]
    return [
        ("hemisphere", H, {}, lambda: H.meshes(L, seed=seed)),
        ("cap", C, {}, lambda: C.meshes(L, seed=seed)),
        ("lantern m~n", Lp, {}, lambda: lant("m~n", L)),
        ("lantern m~n^2", Lp, {}, lambda: lant("m~n^2", min(L, 5))),
        ("lantern m~n^2, normal", Lp, {}, lambda: lant("m~n^2", min(L, 5), "normal")),
        ("lantern n~m^2", Lp, {}, lambda: lant("n~m^2", min(L, 4))),
        ("closed sphere", S, {"bc": "closed", "project_mean": True}, lambda: S.meshes(L, seed=seed)),
        ("lantern m~n, navier", Ln, {"bc": "navier"}, lambda: lant("m~n", L)),
        ("hemisphere, navier data", Hn, {"bc": "navier", "g": Hn.u, "w": Hn.u2},
         lambda: Hn.meshes(L, seed=seed)),
    ]


def convergence_study(problem, meshes, **solve_kw):
    """Solve on every mesh; list of error dicts (:func:`biharmonic_errors`) plus
    ``time`` (setup + solve, s) and ``area`` (mesh area)."""
    rows = []
    for V, F in meshes:
        t = time.perf_counter()
        u1, u2 = biharmonic_solve(V, F, problem.f, **solve_kw)
        dt = time.perf_counter() - t
        r = biharmonic_errors(V, F, u1, u2, problem)
        r["time"] = dt
        r["area"] = float(TriangleMesh(V, F).face_areas.sum())
        rows.append(r)
    return rows


def _fmt_table(name, rows):
    hs = [r["h"] for r in rows]
    lines = [f"### {name}", "",
             "| #V | h | area | " + " | ".join(f"{lab} | EOC" for _, lab in KEYS) + " |",
             "|---|---|---|" + "---|---|" * len(KEYS)]
    rates = {k: np.concatenate([[np.nan], eoc([r[k] for r in rows], hs)]) for k, _ in KEYS}
    for i, r in enumerate(rows):
        cells = [f"{r['n_vertices']}", f"{r['h']:.4f}", f"{r['area']:.4f}"]
        for k, _ in KEYS:
            e = rates[k][i]
            cells += [f"{r[k]:.3e}", "" if np.isnan(e) else f"{e:.2f}"]
        lines.append("| " + " | ".join(cells) + " |")
    p = PAPER[name]
    lines += ["", f"exact area: {EXACT_AREA[name]:.4f}; "
                  f"Stein et al. 2022 proven rates: u1 L2 {p['u1_L2']}, u1 H1 {p['u1_H1']}, u2 L2 {p['u2_L2']}; "
                  f"observed: {p['observed']}"]
    return "\n".join(lines)


def _plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    names = list(results)
    fig, axes = plt.subplots(2, (len(names) + 1) // 2, figsize=(4.2 * ((len(names) + 1) // 2), 7.5))
    from ..convergence import plot_convergence
    for ax, name in zip(axes.ravel(), names):
        rows = results[name]
        h = np.array([r["h"] for r in rows])
        plot_convergence(h, [[r[k] for r in rows] for k, _ in KEYS], [lab for _, lab in KEYS], ax=ax,
                         rates=(1, 2), title=name, legend=False, styles=[{"ms": 3}] * len(KEYS))
        ax.invert_xaxis()
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    for ax in axes.ravel()[len(names):]:
        ax.axis("off")
    axes.ravel()[0].legend(fontsize=7)
    fig.suptitle("Mixed P1 biharmonic (Stein et al., §6): errors vs h", fontsize=11)
    fig.tight_layout()
    fig.set_dpi(85)
    fig.canvas.draw()
    image = np.asarray(fig.canvas.buffer_rgba())
    plt.close(fig)
    from ..viewer.render import save_png
    if not save_png(path, image):                        # Pillow missing: matplotlib's RGB PNG
        import matplotlib.image
        matplotlib.image.imsave(path, image)


# ---------------------------------------------------------------- performance
def _timed(fn):
    t = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t


def performance_study(max_vertices=600_000, rings=7, seed=0, progress=True, log=print):
    """Setup+solve times on clamped hemisphere meshes (``cap_mesh(π/2, levels, rings)``)."""
    import igl
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    H = Hemisphere()
    Ph = SphereHarmonicsProblem(bc="clamped")
    rows = []
    levels = []
    lev = 0
    while True:
        nV_est = (1 + 3 * rings * (rings + 1)) * 4 ** lev        # ~ vertices after lev refinements
        if nV_est > 1.6 * max_vertices and levels:
            break
        levels.append(lev)
        lev += 1
    for lev in progress_bar(levels, "perf", "mesh", progress):
        V, F = cap_mesh(np.pi / 2, lev, rings=rings, seed=seed)
        r = {"n_vertices": len(V), "n_faces": len(F)}
        f = H.f(V)
        S, r["full_setup"] = _timed(lambda: BiharmonicSolver(V, F, mass="full"))
        (u1f, _), r["full_solve"] = _timed(lambda: S.solve(f))
        r["full_method"] = S.method
        r["full_pcg_iterations"] = S.last_iterations
        del S
        Sl, r["lumped_setup"] = _timed(lambda: BiharmonicSolver(V, F, mass="lumped"))
        (u1l, _), r["lumped_solve"] = _timed(lambda: Sl.solve(f))
        del Sl

        # (c) baseline: assemble lumped K M^-1 K and spsolve it directly
        def baseline():
            mesh = TriangleMesh(V, F)
            K = stiffness_matrix(mesh)
            Mf = mass_matrix(mesh, "full")
            ml = np.asarray(Mf.sum(axis=1)).ravel()
            I = np.flatnonzero(~mesh.boundary_vertices)
            B = K[I]
            Q = (B @ sp.diags(1.0 / ml) @ B.T).tocsc()
            u = np.zeros(len(V))
            u[I] = spla.spsolve(Q, (Mf @ f)[I])
            return u
        u1b, r["baseline_lumped_spsolve"] = _timed(baseline)
        r["baseline_vs_lumped_maxdiff"] = float(np.abs(u1b - u1l).max())
        del u1b

        # (e) yardstick: one CHOLMOD factorisation of the lumped K M^-1 K (assembly excluded)
        def lumped_schur():
            mesh = TriangleMesh(V, F)
            K = stiffness_matrix(mesh)
            ml = np.asarray(mass_matrix(mesh, "full").sum(axis=1)).ravel()
            B = K[np.flatnonzero(~mesh.boundary_vertices)]
            Q = sp.csr_matrix(B @ sp.diags(1.0 / ml) @ B.T)
            Q.sum_duplicates()
            return Q
        Q = lumped_schur()
        _, r["cholmod_lumped_factor"] = _timed(lambda: _cholmod(Q))   # factor freed at once
        del Q
        r["full_over_cholmod"] = (r["full_setup"] + r["full_solve"]) / r["cholmod_lumped_factor"]
        # (d) igl.harmonic(k=2) vs ours (voronoi mass, f = 0, u = g on the boundary)
        b = np.asarray(igl.boundary_loop(F), dtype=np.int64)
        g = Ph.u(V)
        W, r["igl_harmonic_k2"] = _timed(lambda: igl.harmonic(V, F, b, g[b][:, None], 2)[:, 0])
        (u1v, _), r["ours_voronoi_g"] = _timed(lambda: biharmonic_solve(V, F, 0.0, mass="voronoi", g=g))
        r["harmonic_vs_ours_maxdiff"] = float(np.abs(W - u1v).max())
        r["full_vs_lumped_maxdiff"] = float(np.abs(u1f - u1l).max())
        rows.append(r)
        log(f"perf #V={len(V)}: full {r['full_setup'] + r['full_solve']:.2f}s "
            f"({r['full_method']}, it={r['full_pcg_iterations']}), lumped "
            f"{r['lumped_setup'] + r['lumped_solve']:.2f}s, one CHOLMOD factorisation of K M^-1 K "
            f"{r['cholmod_lumped_factor']:.2f}s (full/that {r['full_over_cholmod']:.2f}), spsolve K M^-1 K "
            f"{r['baseline_lumped_spsolve']:.2f}s, igl.harmonic(k=2) {r['igl_harmonic_k2']:.2f}s "
            f"vs ours(voronoi) {r['ours_voronoi_g']:.2f}s (max diff {r['harmonic_vs_ours_maxdiff']:.1e})")
    return rows


def _fmt_perf(rows):
    lines = ["| #V | full mass: setup + solve (s) | method (PCG it.) | lumped: setup + solve (s) | "
             "one CHOLMOD factorisation of lumped K M⁻¹ K (s) | full / that | "
             "spsolve lumped K M⁻¹ K (s) | igl.harmonic k=2 (s) | ours voronoi, same problem (s) | "
             "max |ours − igl| |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        it = r["full_pcg_iterations"]
        lines.append(
            f"| {r['n_vertices']} | {r['full_setup']:.2f} + {r['full_solve']:.2f} | {r['full_method']}"
            f"{'' if it is None else f' ({it})'} | {r['lumped_setup']:.2f} + {r['lumped_solve']:.2f} | "
            f"{r['cholmod_lumped_factor']:.2f} | {r['full_over_cholmod']:.2f} | "
            f"{r['baseline_lumped_spsolve']:.2f} | {r['igl_harmonic_k2']:.2f} | {r['ours_voronoi_g']:.2f} | "
            f"{r['harmonic_vs_ours_maxdiff']:.1e} |")
    return "\n".join(lines)


def _plot_perf(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = [r["n_vertices"] for r in rows]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.loglog(n, [r["full_setup"] + r["full_solve"] for r in rows], "o-", label="ours, full mass (paper)")
    ax.loglog(n, [r["lumped_setup"] + r["lumped_solve"] for r in rows], "s-", label="ours, lumped mass")
    ax.loglog(n, [r["cholmod_lumped_factor"] for r in rows], "x:", label="one CHOLMOD factorisation of K M⁻¹ K")
    ax.loglog(n, [r["baseline_lumped_spsolve"] for r in rows], "^--", label="spsolve(K M⁻¹ K), lumped")
    ax.loglog(n, [r["igl_harmonic_k2"] for r in rows], "v--", label="igl.harmonic(k=2), f=0")
    ax.loglog(n, [r["ours_voronoi_g"] for r in rows], "d-", label="ours, voronoi, f=0 (same problem)")
    ax.set_xlabel("#V")
    ax.set_ylabel("setup + solve time (s)")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    ax.set_title("clamped hemisphere, 2 cores shared")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------- driver
def run(levels=5, seed=0, out="benchmark-results", perf=False, perf_max_vertices=600_000,
        perf_rings=7, plot=True, cases=None, progress=True, verbose=True):
    """Run the §6 convergence study (and optionally the performance study).

    Parameters
    ----------
    levels : int
        Mesh levels per case (h halves per level; lantern m~n² is capped at 5,
        n~m² at 4 levels).
    cases : list of str, optional
        Subset of the case names in :data:`PAPER`.
    perf : bool
        Also run :func:`performance_study` up to ``perf_max_vertices``.

    Returns
    -------
    dict with ``convergence`` ({case: rows}), ``eoc`` ({case: {key: [...]}}),
    ``perf`` (rows or None) and ``files`` (written paths).
    """
    log = print if verbose else (lambda *a, **k: None)
    os.makedirs(out, exist_ok=True)
    todo = [c for c in _cases(levels, seed) if cases is None or c[0] in cases]
    results, rates, tables = {}, {}, []
    for name, problem, kw, meshes in progress_bar(todo, "cases", "case", progress):
        rows = convergence_study(problem, meshes(), **kw)
        results[name] = rows
        hs = [r["h"] for r in rows]
        rates[name] = {k: eoc([r[k] for r in rows], hs).tolist() for k, _ in KEYS}
        tables.append(_fmt_table(name, rows))
        log(tables[-1] + "\n")
    files = []
    md = os.path.join(out, "biharmonic_convergence.md")
    with open(md, "w") as fh:
        fh.write("\n\n".join(tables) + "\n")
    files.append(md)
    csv_path = os.path.join(out, "biharmonic_convergence.csv")
    with open(csv_path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "n_vertices", "h", "area"] + [k for k, _ in KEYS] + ["time"])
        for name, rows in results.items():
            for r in rows:
                w.writerow([name, r["n_vertices"], r["h"], r["area"]] + [r[k] for k, _ in KEYS] + [r["time"]])
    files.append(csv_path)
    if plot and results:
        png = os.path.join(out, "biharmonic_convergence.png")
        _plot(results, png)
        files.append(png)
    perf_rows = None
    if perf:
        perf_rows = performance_study(perf_max_vertices, perf_rings, seed, progress, log)
        table = _fmt_perf(perf_rows)
        log(table)
        p = os.path.join(out, "biharmonic_performance.md")
        with open(p, "w") as fh:
            fh.write(table + "\n")
        files.append(p)
        with open(os.path.join(out, "biharmonic_performance.json"), "w") as fh:
            json.dump(perf_rows, fh, indent=1)
        if plot:
            png = os.path.join(out, "biharmonic_performance.png")
            _plot_perf(perf_rows, png)
            files.append(png)
    return {"convergence": results, "eoc": rates, "perf": perf_rows, "files": files}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--levels", type=int, default=5, help="refinement levels per case (default 5)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the mesh jitter (default 0)")
    ap.add_argument("--out", default="benchmark-results",
                    help="folder for the tables and plots (default ./benchmark-results/)")
    ap.add_argument("--perf", action="store_true", help="also run the timing study")
    ap.add_argument("--perf-only", action="store_true", help="only the timing study")
    ap.add_argument("--perf-max-vertices", type=int, default=600_000,
                    help="largest mesh of the timing study, in vertices (default 600000)")
    ap.add_argument("--perf-rings", type=int, default=7, help="rings of the coarse hemisphere mesh of the timing study (default 7)")
    ap.add_argument("--no-plot", action="store_true", help="no matplotlib plots")
    a = ap.parse_args(argv)
    run(levels=a.levels, seed=a.seed, out=a.out, perf=a.perf or a.perf_only,
        perf_max_vertices=a.perf_max_vertices, perf_rings=a.perf_rings, plot=not a.no_plot,
        cases=[] if a.perf_only else None)


if __name__ == "__main__":
    main()
