"""Curvature of a mesh: HHJ (left) beside libigl's principal_curvature (right), same colours.

    igl-hhj demo compare_curvature                         # generated jittered torus, interactive
    igl-hhj demo compare_curvature path/to/mesh.off        # any file igl.read_triangle_mesh reads
    igl-hhj demo compare_curvature --screenshot out.png    # headless (EGL)
    igl-hhj demo compare_curvature MESH --quantity K --per face --robust 5 --screenshot out.png

What you see: two copies of the mesh side by side, coloured by one curvature
(--quantity: k1, k2, mean H (default) or Gauss K) with a diverging map
(coolwarm) whose range is symmetric about 0 and IDENTICAL for both copies:
white = zero curvature, red = positive, blue = negative; the range runs to the
1st/99th percentile of both methods' values (--robust 1, the default; --robust
0 uses the extremes), so a few outliers do not wash the picture out.  Left:
igl_hhj (the drop-in per-vertex values by default, like with like beside libigl's;
Walker's HHJ shape operator itself, one value per face, with --per face).  Right:
igl.principal_curvature (quadric fit over a 5-ring, per vertex).  On the
default generated mesh (Walker's torus (x²+y²-0.6)² + 1.5z² = 0.25, jittered,
tilted towards the camera) H is red on the outer side and white to pale blue
towards the hole on both copies; libigl's copy shows a dark-red, wavy band
along the top of the outer side where HHJ's stays a smooth, lighter red.  In
the interactive viewer all of k1, k2, H, K and the principal directions (PD1,
PD2) of both methods can be switched on.

Printed: for a generated surface (--surface torus|ellipsoid), the relative L2 error of k1, k2, H, K
against the exact curvatures for both methods (smaller is better); for a mesh
file, the 1st/50th/99th percentiles of each quantity for both methods and the
run times.  A missing or unreadable file gives a one-line error (exit code 2).
"""
from __future__ import annotations

import time

import numpy as np

from . import _common

QUANTS = ("k1", "k2", "H", "K")


def generated(name, levels=None):
    """A jittered mesh of Walker's torus or an ellipsoid, and its exact surface."""
    from igl_hhj.surfaces.exact import Ellipsoid, WalkerTorus
    from igl_hhj.surfaces.meshing import ellipsoid_coarse, jitter_tangentially, refine, torus_coarse
    if name == "torus":
        s = WalkerTorus()
        V, F = torus_coarse(24, 12, amount=0.25, seed=0)
        levels = 2 if levels is None else levels
    else:
        s = Ellipsoid(axes=(1.5, 1.0, 0.6))
        V, F = ellipsoid_coarse(s, subdivisions=1)
        levels = 3 if levels is None else levels
    V, F = refine(V, F, s, levels)
    return jitter_tangentially(V, F, s, amount=0.3, seed=1), F, s


TILT = _common.rotation(0.0, -60.0)  # generated surfaces: seen obliquely from above


def estimates(V, F, per):
    from igl_hhj import viewer
    t0 = time.perf_counter()
    hhj = viewer.curvature_estimate(V, F, method="hhj", per=per)
    t1 = time.perf_counter()
    igl_ = viewer.curvature_estimate(V, F, method="igl", per="vertex")
    t2 = time.perf_counter()
    return hhj, igl_, t1 - t0, t2 - t1


def error_table(V, F, surface, hhj, igl_, rotation):
    """Relative L2 errors against ``surface`` of estimates computed on ``V @ rotation.T``."""
    from dataclasses import replace

    from igl_hhj.benchmarks.compare_estimators import errors
    from igl_hhj.mesh import as_mesh
    mesh = as_mesh(V, F)
    back = {lab: replace(est, d1=None if est.d1 is None else est.d1 @ rotation,
                         d2=None if est.d2 is None else est.d2 @ rotation)
            for lab, est in (("HHJ", hhj), ("libigl", igl_))}
    e = {lab: errors(mesh, est, surface) for lab, est in back.items()}
    _common.print_table(f"Relative L2 error against the exact curvature ({mesh.n_faces} faces)",
                        ["quantity", "HHJ", "libigl"], [[q, e["HHJ"][q], e["libigl"][q]] for q in QUANTS])


def percentile_table(hhj, igl_, times):
    rows = []
    for q in QUANTS:
        row = [q]
        for est in (hhj, igl_):
            row += list(np.nanpercentile(getattr(est, q), [1, 50, 99]))
        rows.append(row)
    rows.append(["time (s)", times[0], "", "", times[1], "", ""])
    _common.print_table("Percentiles of the curvatures (p1 / p50 / p99)",
                        ["quantity", "HHJ p1", "p50", "p99", "libigl p1", "p50", "p99"], rows)


def main(argv=None, prog=None):
    p = _common.parser(__doc__, prog=prog, size=(1600, 800))
    p.add_argument("mesh", nargs="?", help="mesh file (default: a generated surface, see --surface)")
    p.add_argument("--surface", default="torus", choices=["torus", "ellipsoid"],
                   help="generated surface when no mesh file is given (default: Walker's torus)")
    p.add_argument("--quantity", default="H", choices=list(QUANTS), help="quantity shown (default H)")
    p.add_argument("--per", default="vertex", choices=["vertex", "face"],
                   help="HHJ values per vertex (the drop-in, default: like with like beside libigl's "
                        "per-vertex values) or per face (Walker's native S_h)")
    p.add_argument("--robust", type=float, default=1.0, metavar="P",
                   help="colour range from the [P, 100-P] percentiles of both methods' values "
                        "(default 1; 0 = the extremes)")
    p.add_argument("--camera", default="auto", choices=["auto", "+x", "-x", "+y", "-y", "+z", "-z"],
                   help="mesh file: the side the camera looks from (default auto: largest projected area)")
    args = p.parse_args(argv)
    if args.robust is not None and not 0 <= args.robust < 50:
        _common.fail(f"--robust must be a percentile in [0, 50), got {args.robust}")
    if args.mesh is None:
        V0, F, surface = generated(args.surface)
        V = V0 @ TILT.T
    else:
        V, F = _common.read_mesh(args.mesh)
        surface = None
    print(f"mesh: {args.mesh or 'generated ' + args.surface}, {len(V)} vertices, {len(F)} faces")
    hhj, igl_, th, ti = estimates(V, F, args.per)
    if surface is not None:
        error_table(V0, F, surface, hhj, igl_, TILT)
    else:
        percentile_table(hhj, igl_, (th, ti))
    viewer = _common.start_viewer(args)
    from pathlib import Path
    name = Path(args.mesh).stem if args.mesh else f"jittered {args.surface}"
    reg = viewer.register_comparison(V, F, hhj=hhj, libigl=igl_, enabled=args.quantity, robust=args.robust,
                                     name=name, view=args.camera if args.mesh else None)
    lo, hi = reg.ranges[args.quantity]
    print(f"colour range of {args.quantity} (both copies): [{lo:.3g}, {hi:.3g}]")
    _common.finish(viewer, args, [reg])


if __name__ == "__main__":
    main()
