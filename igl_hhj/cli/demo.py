"""``igl-hhj demo [NAME]``: HHJ against libigl on a jittered ellipsoid sequence, or one of
the demos of :mod:`igl_hhj.demos`."""
from __future__ import annotations

import sys
import time

import numpy as np

from ._common import UserError, _check_writable, _quietly, _viewer, _with_hint


def _demo(args):
    import igl

    from .. import principal_curvature
    from ..convergence import eoc, vertex_errors
    from ..surfaces import Ellipsoid, ellipsoid_coarse, mesh_sequence

    if args.levels < 1:
        raise UserError(f"--levels must be at least 1, got {args.levels}")
    if args.levels > 7:
        raise UserError(f"--levels must be at most 7 (level 7 has 1.3 million faces), got {args.levels}")
    if not 0 <= args.seed < 2 ** 63:
        raise UserError(f"--seed must be a non-negative integer below 2**63, got {args.seed}")
    if min(args.size) < 16:
        raise UserError(f"--size must be at least 16 16 pixels, got {args.size[0]} {args.size[1]}")
    shot = None if args.no_screenshot else args.screenshot
    if shot is not None:
        _check_writable(shot, (".png",))
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
    if shot is not None:
        try:
            _demo_screenshot(V, F, surface, PV1, PV2, QV1, QV2, shot, tuple(args.size))
        except _viewer().ViewerUnavailable as exc:
            print(f"igl-hhj: warning: no screenshot ({_with_hint(exc)})", file=sys.stderr)
        else:
            print(f"\nwrote {shot}: |error of H| on the finest mesh, HHJ (left) and libigl (right), "
                  "one colour range")
    return 0


def _demo_screenshot(V, F, surface, PV1, PV2, QV1, QV2, path, size=(1600, 700)):
    """Pointwise |H_h − H| of HHJ and libigl side by side, one shared colour range."""
    viewer = _viewer()
    H = surface.mean_curvature(V)
    err = {"HHJ": np.abs(0.5 * (PV1 + PV2) - H), "libigl": np.abs(0.5 * (QV1 + QV2) - H)}
    top = float(np.nanpercentile(np.concatenate(list(err.values())), 99))
    Vd = V @ viewer.view_rotation("auto", V, F, landscape=True).T   # the side with the largest projected area
    shift = np.array([1.1 * np.ptp(Vd[:, 0]), 0.0, 0.0])
    regs = [_quietly(viewer.register_scalars, Vd, F, {f"|H error| per vertex [{viewer.LENGTH_UNIT}]": e}, name=f"demo {k}",
                     vminmax=(0.0, top), cmap="viridis", offset=i * shift,
                     title=f"{viewer.METHOD_TITLES[k]} — jittered ellipsoid, {len(F):,} faces")
            for i, (k, e) in enumerate(err.items())]
    _quietly(viewer.screenshot, str(path), regs, size=size)


def _named_demo(argv):
    """``igl-hhj demo NAME [options]``: run demo NAME of :mod:`igl_hhj.demos` with its own
    options; None when ``argv`` is not such a call."""
    from ..demos import DEMOS, run
    if argv is None:
        argv = sys.argv[1:]
    if len(argv) >= 2 and argv[0] == "demo" and argv[1] in DEMOS:
        return run(argv[1], argv[2:], prog=f"igl-hhj demo {argv[1]}")
    return None


def add_parser(sub):
    """The ``demo`` sub-command."""
    from ..demos import DEMOS
    d = sub.add_parser("demo", help="HHJ vs libigl curvature on a built-in ellipsoid mesh sequence; "
                                    "'demo NAME' runs one of the demos",
                       description="Without NAME: error table of HHJ and libigl curvature against the "
                                   "exact ellipsoid, then a screenshot of the finest mesh. With NAME: "
                                   "run that demo with its own options (see 'igl-hhj demo NAME --help').")
    d.add_argument("name", nargs="?", choices=DEMOS, metavar="NAME",
                   help=f"one of {', '.join(DEMOS)} (its options follow the name)")
    d.add_argument("--levels", type=int, default=4, help="number of refinement levels (default 4)")
    d.add_argument("--seed", type=int, default=0, help="seed of the coarse-mesh jitter (default 0)")
    d.add_argument("--screenshot", default="igl_hhj_demo.png", metavar="PNG",
                   help="where to write the screenshot (default ./igl_hhj_demo.png)")
    d.add_argument("--no-screenshot", action="store_true", help="only print the table")
    d.add_argument("--size", type=int, nargs=2, default=(1600, 700), metavar=("W", "H"),
                   help="screenshot size in pixels (default 1600 700)")
    d.set_defaults(func=_demo)
