"""Mixed P1 biharmonic solver (Stein et al.) on a manufactured problem: solution, error, rates.

    igl-hhj demo biharmonic                          # clamped hemisphere, interactive
    igl-hhj demo biharmonic --bc navier --screenshot out.png
    igl-hhj demo biharmonic --bc closed --levels 2 --screenshot out.png   # fast

igl_hhj.biharmonic_solve solves Δ²u = f with u1 ≈ u and u2 ≈ -Δu per vertex,
on the exact test problems of igl_hhj/surfaces/biharmonic_problems.py (paper
001, §5.3 and §6), on non-uniform mesh sequences:

* ``--bc clamped``: the hemisphere of Stein et al. 2022 Fig. 2, u = (π/2 - θ)² θ⁵
  (θ = colatitude), u = ∂u/∂n = 0 on the equator; jittered Delaunay disk mapped
  onto the sphere, refined with projection;
* ``--bc navier``: the Schwarz lantern (cylinder r = 1, 0 ≤ z ≤ 1, m ~ n rings,
  vertices perturbed by (mean edge length)²), u = cos φ sin(πz), u = Δu = 0
  on both rims;
* ``--bc closed``: the unit sphere, u = a sum of harmonic polynomials of
  degrees 1-4 (zero mean), jittered icosphere refined with projection.

What you see: two copies of the finest mesh, seen obliquely.  Left: the
computed u1, viridis when u does not change sign (hemisphere: dark at the rim
and the pole, a bright band in between where (π/2 - θ)² θ⁵ peaks) and coolwarm
symmetric about 0 when it does (lantern: red and blue halves around the axis,
white at the rims; sphere: red and blue lobes).  Right: the error u1 - I_h u
(coolwarm, symmetric about 0, white = exact): its own much smaller range is
printed.  Interactively, u (exact), u2 ≈ -Δu and f can be switched on; u1
and the exact u share one range.

Printed: per level the L2 errors ‖u1 - I_h u‖ and ‖u2 - I_h(-Δu)‖ (consistent
P1 mass) and their EOCs beside the rates Stein et al. 2022 proves or reports.
Measured here (4 levels): u1 converges at O(h²) in all three cases (EOC
2.0 on the hemisphere and the sphere, 1.8-2.4 on the lantern), better than the
O(h) the paper proves for the clamped hemisphere; the u2 EOC on the hemisphere
falls from 1.8 to 0.9 over the levels (the paper proves 1/2), on the lantern
and the sphere it is about 2.
"""
from __future__ import annotations

import numpy as np

from . import _common

PAPER_KEY = {"clamped": "hemisphere", "navier": "lantern m~n", "closed": "closed sphere"}


def problem(bc):
    """(problem, extra solve kwargs, display rotation) for ``bc``."""
    from igl_hhj.surfaces.biharmonic_problems import Hemisphere, LanternProblem, SphereHarmonicsProblem
    if bc == "clamped":
        return Hemisphere(), {}, _common.rotation(0.0, -60.0)
    if bc == "navier":
        return LanternProblem("navier"), {}, _common.rotation(20.0, -75.0)
    return SphereHarmonicsProblem(bc="closed"), {"project_mean": True}, _common.rotation(30.0, -60.0)


def measure(prob, kwargs, n_levels):
    from igl_hhj import biharmonic_solve
    from igl_hhj.surfaces.biharmonic_problems import biharmonic_errors
    rows = []
    for V, F in prob.meshes(n_levels):
        u1, u2 = biharmonic_solve(V, F, prob.f, bc=prob.bc, **kwargs)
        e = biharmonic_errors(V, F, u1, u2, prob)
        rows.append({"V": np.asarray(V, float), "F": np.asarray(F), "u1": u1, "u2": u2, "faces": len(F), **e})
    return rows


def table(rows, prob, bc):
    from igl_hhj.benchmarks.biharmonic_convergence import PAPER
    _common.print_eoc_table(f"{prob.name}, bc={bc}: L2 errors of the mixed P1 solution", rows,
                            [("‖u1 - u‖", [r["u1_L2"] for r in rows]),
                             ("‖u2 + Δu‖", [r["u2_L2"] for r in rows])])
    paper = PAPER[PAPER_KEY[bc]]
    note = " (the paper's lantern is clamped; this Navier lantern is ours)" if bc == "navier" else ""
    print(f"Stein et al. 2022{note}: rates u1 L2 {paper['u1_L2']}, u2 L2 {paper['u2_L2']}; {paper['observed']}")


def show(rows, prob, R, args):
    viewer = _common.start_viewer(args)
    last = rows[-1]
    V = last["V"] @ R.T
    V = V - V.mean(axis=0)
    u = prob.u(last["V"])                           # exact u at the (unrotated) vertices
    f = prob.f(last["V"])
    ext = V.max(axis=0) - V.min(axis=0)
    where = f"{prob.name}, bc={args.bc}, {last['faces']:,} faces"
    left = viewer.register_biharmonic(V, last["F"], last["u1"], last["u2"], exact=u, f=f, name="u1",
                                      enabled="u1", title=f"computed u1 — {where}")
    right = viewer.register_biharmonic(V, last["F"], last["u1"], last["u2"], exact=u, f=f, name="error u1 - u",
                                       enabled="error", offset=(1.15 * ext[0], 0.0, 0.0),
                                       title=f"error u1 - u — {where}")
    lo, hi = left.ranges["u1"]
    elo, ehi = right.ranges["error"]
    print(f"colour ranges: u1 and u [{lo:.3g}, {hi:.3g}]; error u1 - u [{elo:.3g}, {ehi:.3g}]")
    _common.finish(viewer, args, [left, right])


def main(argv=None, prog=None):
    p = _common.parser(__doc__, prog=prog, levels=4, size=(1600, 800))
    p.add_argument("--bc", default="clamped", choices=["clamped", "navier", "closed"],
                   help="boundary condition, i.e. which test problem (default clamped)")
    args = p.parse_args(argv)
    n = _common.check_levels(args.levels, 2, 6)
    prob, kwargs, R = problem(args.bc)
    rows = measure(prob, kwargs, n)
    table(rows, prob, args.bc)
    show(rows, prob, R, args)


if __name__ == "__main__":
    main()
