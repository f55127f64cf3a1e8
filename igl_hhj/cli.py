"""Command-line interface: ``igl-hhj demo`` and ``igl-hhj curvature MESH``."""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np


def _demo(args):
    import igl

    from . import principal_curvature
    from .convergence import eoc, vertex_errors
    from .surfaces import Ellipsoid, ellipsoid_coarse, mesh_sequence

    surface = Ellipsoid()
    V0, F0 = ellipsoid_coarse(surface, subdivisions=2, amount=0.3, seed=args.seed)
    print("igl_hhj demo: ellipsoid x² + (2y)² + (2z/3)² = 1, jittered coarse mesh refined "
          "uniformly with projection (non-uniform sequence).")
    print("Per-vertex principal curvatures against the exact ones (L2 errors, lumped mass).\n")
    header = (f"{'faces':>7} {'h':>7} | {'HHJ err H':>10} {'err K':>9} {'time':>7} | "
              f"{'libigl err H':>12} {'err K':>9} {'time':>7}")
    print(header)
    print("-" * len(header))
    rows = []
    for V, F in mesh_sequence(V0, F0, surface, args.levels):
        t = time.perf_counter()
        _, _, PV1, PV2, _ = principal_curvature(V, F)
        t_hhj = time.perf_counter() - t
        t = time.perf_counter()
        _, _, QV1, QV2, _ = igl.principal_curvature(V, F)
        t_igl = time.perf_counter() - t
        e = vertex_errors(V, F, PV1, PV2, surface)
        g = vertex_errors(V, F, QV1, QV2, surface)
        rows.append((e, g))
        print(f"{len(F):>7} {e['h']:>7.4f} | {e['H']:>10.3e} {e['K']:>9.3e} {t_hhj:>6.2f}s | "
              f"{g['H']:>12.3e} {g['K']:>9.3e} {t_igl:>6.2f}s")
    hs = [r[0]["h"] for r in rows]
    if len(rows) > 1:
        print("\nEOC (last level):  HHJ  H {:.2f}  K {:.2f}   |   libigl  H {:.2f}  K {:.2f}".format(
            eoc([r[0]["H"] for r in rows], hs)[-1], eoc([r[0]["K"] for r in rows], hs)[-1],
            eoc([r[1]["H"] for r in rows], hs)[-1], eoc([r[1]["K"] for r in rows], hs)[-1]))
    return 0


def _curvature(args):
    import igl

    from . import principal_curvature, shape_operator
    from .mesh import TriangleMesh

    V, F = igl.read_triangle_mesh(args.mesh)
    t = time.perf_counter()
    mesh = TriangleMesh(V, F)
    S = shape_operator(mesh.V, mesh.F)
    PD1, PD2, PV1, PV2, bad = principal_curvature(mesh.V, mesh.F)
    dt = time.perf_counter() - t
    print(f"{args.mesh}: {mesh.n_vertices} vertices, {mesh.n_faces} faces, "
          f"{int(mesh.boundary_edges.sum())} boundary edges; {dt:.2f} s")
    for name, x in [("kappa1", PV1), ("kappa2", PV2), ("mean", 0.5 * (PV1 + PV2)), ("gauss", PV1 * PV2)]:
        q = np.nanpercentile(x, [1, 50, 99])
        print(f"  {name:>6}: 1% {q[0]: .4g}   median {q[1]: .4g}   99% {q[2]: .4g}")
    if bad:
        print(f"  {len(bad)} unreferenced vertices have no value (NaN)")
    if args.out:
        np.savez(args.out, S=S, PD1=PD1, PD2=PD2, PV1=PV1, PV2=PV2)
        print(f"  wrote {args.out}")
    return 0


def main(argv=None):
    parser = argparse.ArgumentParser(prog="igl-hhj", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    d = sub.add_parser("demo", help="HHJ vs libigl curvature on a built-in ellipsoid mesh sequence")
    d.add_argument("--levels", type=int, default=4, help="number of refinement levels (default 4)")
    d.add_argument("--seed", type=int, default=0)
    d.set_defaults(func=_demo)
    c = sub.add_parser("curvature", help="principal curvatures of a mesh file (any format libigl reads)")
    c.add_argument("mesh")
    c.add_argument("--out", help="write S, PD1, PD2, PV1, PV2 to this .npz file")
    c.set_defaults(func=_curvature)
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, TypeError, OSError) as exc:
        print(f"igl-hhj: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
