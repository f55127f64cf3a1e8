"""Curved triangles: Walker's HHJ shape operator on geometry of degree m = 1, 2, 3.

    igl-hhj demo curved                          # torus, interactive (or python demos/curved.py)
    igl-hhj demo curved --screenshot out.png     # headless
    igl-hhj demo curved --surface genus3 --subdivisions 3 --screenshot out.png

One flat non-uniform mesh of Walker's torus (§6.3; 1904 triangles) or genus-3
surface (§6.4) is made curved of order m = 1, 2, 3 by Walker's modified
interpolant of the closest-point map (igl_hhj.curved.LagrangeSurface.from_projection),
and igl_hhj.curved.shape_operator (HHJ of degree r = m - 1) is solved on each.
Polyscope has no curved elements: every curved triangle is drawn as
``subdivisions²`` flat ones (igl_hhj.curved.display).

What you see: three copies side by side, left to right m = 1, 2, 3, coloured by
log10 of the mean-curvature error |H_h - H| (viridis, ONE range for all three:
dark purple = 10^lo, yellow = 10^hi; the range is printed).  Same mesh, same
number of triangles: m = 1 is mostly yellow (errors ~10^-1), m = 2 blue-green
with yellow rings on the top and bottom of the tube, m = 3 blue-green to purple
(errors ~10^-2 to 10^-4), the purple specks around the inner part of the tube.

Printed: per m the number of HHJ unknowns, the L2 errors of S_h and κ^a = tr S_h
on Γ^m (Walker §6's norms) and the solve time.
"""
from __future__ import annotations

import time

import numpy as np

from . import _common


def main(argv=None, prog=None):
    p = _common.parser(__doc__, prog=prog, size=(1500, 560))
    p.add_argument("--surface", choices=("torus", "genus3"), default="torus")
    p.add_argument("--subdivisions", type=int, default=4, help="flat triangles per curved edge (display)")
    args = p.parse_args(argv)
    if args.subdivisions < 1:
        _common.fail("--subdivisions must be at least 1")
    from igl_hhj.benchmarks.walker_tables import surface_levels
    from igl_hhj.curved import LagrangeSurface, shape_operator
    from igl_hhj.curved.display import display_mesh
    from igl_hhj.curved.errors import shape_operator_errors
    surface, seq = surface_levels(args.surface, 1)
    V, F = seq[0]
    rows, meshes = [], []
    for m in (1, 2, 3):
        t0 = time.perf_counter()
        surf = LagrangeSurface.from_projection(V, F, m, surface.project)
        fld = shape_operator(surf)
        dt = time.perf_counter() - t0
        e = shape_operator_errors(fld, surface)
        rows.append([f"m = {m}", str(fld.space.n_dofs), _common.fmt(e["S"]), _common.fmt(e["kappa_a"]), f"{dt:.2f} s"])
        DV, DF, vals = display_mesh(surf, fld, args.subdivisions, exact=surface)
        meshes.append((DV, DF, np.log10(np.maximum(vals["|H error|"], 1e-12))))
    _common.print_table(f"{args.surface}, {len(F)} triangles (HHJ degree r = m - 1)",
                        ["order", "#DOF", "‖S - S_h‖L2", "‖κa - κa_h‖L2", "solve"], rows)
    allv = np.concatenate([x[2] for x in meshes])
    lo, hi = np.percentile(allv, 1), np.percentile(allv, 99.5)
    print(f"\ncolour: log10 |H_h - H| from {lo:.2f} (dark) to {hi:.2f} (yellow)")
    viewer = _common.start_viewer(args)
    width = np.ptp(meshes[0][0][:, 0]) * 1.15
    regs = [_common.register_field(viewer, DV, DF, "log10 |H error|", v, (lo, hi), name=f"m{m}",
                                   offset=(m - 1) * width * np.array([1.0, 0, 0]))
            for m, (DV, DF, v) in zip((1, 2, 3), meshes)]
    _common.finish(viewer, args, regs)

