"""HHJ (per face) vs libigl (per vertex) principal curvatures, side by side in polyscope.

    python demos/compare_curvature.py                       # built-in jittered ellipsoid, interactive
    python demos/compare_curvature.py path/to/mesh.off      # any mesh libigl can read
    python demos/compare_curvature.py --screenshot out.png  # headless (EGL): kappa1 image
    python demos/compare_curvature.py --screenshot out.png --quantity K

Both copies of the mesh use the same colour range for each quantity
(kappa1, kappa2, H, K); the principal directions are registered as vectors.
"""
from __future__ import annotations

import argparse


def load(path=None, levels=3):
    """(V, F) of the mesh at ``path`` or, if None, a perturbed ellipsoid refined ``levels`` times."""
    if path is None:
        from igl_hhj.surfaces.exact import Ellipsoid
        from igl_hhj.surfaces.meshing import ellipsoid_coarse, jitter_tangentially, refine
        s = Ellipsoid()
        V, F = ellipsoid_coarse(s, subdivisions=1)
        V, F = refine(V, F, s, levels)
        return jitter_tangentially(V, F, s, amount=0.3, seed=1), F
    import igl
    V, F = igl.read_triangle_mesh(str(path))
    return V, F


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("mesh", nargs="?", help="mesh file (default: built-in ellipsoid)")
    p.add_argument("--screenshot", metavar="PNG", help="render headless (EGL) to this file and exit")
    p.add_argument("--quantity", default="k1", choices=["k1", "k2", "H", "K"])
    args = p.parse_args(argv)
    from igl_hhj import viewer
    V, F = load(args.mesh)
    if args.screenshot:
        lo, hi = viewer.screenshot(V, F, args.screenshot, quantity=args.quantity)
        print(f"wrote {args.screenshot} ({args.quantity}, colour range [{lo:.3g}, {hi:.3g}])")
        return
    ps = viewer.init()
    viewer.register_comparison(V, F, enabled=args.quantity)
    ps.show()


if __name__ == "__main__":
    main()
