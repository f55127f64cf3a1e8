"""``igl-hhj view RESULT``: a saved result in the viewer or as a screenshot."""
from __future__ import annotations

from ._common import (EXIT_UNREADABLE, UserError, _camera, _check_writable, _first_line, _quietly, _say, _viewer,
                      _with_hint)


def _view(args):
    """Re-open a saved result (:func:`igl_hhj.viewer.register_result`): the window, or
    ``--screenshot`` headless."""
    from ..mesh_io import MeshFileError, read_curvature
    say = _say(args)
    if not 0 <= args.robust < 50:
        raise UserError(f"--robust must be a percentile in [0, 50), got {args.robust}")
    if args.screenshot is not None:
        _check_writable(args.screenshot, (".png",))
        if min(args.size) < 16:
            raise UserError(f"--size must be at least 16 16 pixels, got {args.size[0]} {args.size[1]}")
    try:
        cf = read_curvature(args.result)               # read once here for the errors and the summary
    except MeshFileError as exc:
        raise UserError(str(exc), EXIT_UNREADABLE) from None
    est = cf.estimate
    stored = ["k1", "k2", "H", "K"] + (["d1", "d2"] if est.d1 is not None else []) + (["S"] if cf.S is not None else [])
    say(f"{args.result}: {len(cf.V)} vertices, {len(cf.F)} faces; {', '.join(stored)} per {est.location}"
        + (f" (method {cf.method})" if cf.method else ""))
    viewer = _viewer()
    shown = dict(enabled=args.quantity, robust=args.robust if args.robust > 0 else None,
                 view=args.camera, show_directions=args.directions)
    if args.screenshot is None:
        try:
            viewer.register_result(args.result, **shown)
            viewer.show()
        except viewer.ViewerUnavailable as exc:
            raise UserError(f"cannot open the viewer window: {_first_line(exc)} "
                            f"(without a display use --screenshot PNG)") from None
        return 0
    try:
        _quietly(viewer.register_result, args.result, screenshot=str(args.screenshot),
                 size=tuple(args.size), **shown)
    except viewer.ViewerUnavailable as exc:
        raise UserError(f"no screenshot: {_with_hint(exc)}") from None
    say(f"  wrote {args.screenshot}")
    return 0


def add_parser(sub):
    """The ``view`` sub-command."""
    from ..mesh_io import RESULT_EXTENSIONS
    v = sub.add_parser("view", help="re-open a saved result (curvature -o) in the viewer or as a screenshot",
                       description="Show the curvature stored in RESULT (written by 'igl-hhj curvature "
                                   f"-o': {' '.join(RESULT_EXTENSIONS)}) in the polyscope viewer: k1, k2, "
                                   "H, K per vertex or per face and the principal directions d1, d2 "
                                   "when stored; --screenshot renders headless instead.")
    v.add_argument("result", metavar="RESULT")
    v.add_argument("--screenshot", metavar="PNG", help="render headless to PNG instead of opening a window")
    v.add_argument("--quantity", choices=["k1", "k2", "H", "K"], default=None,
                   help="quantity shown first (default: the one the file was written to show: "
                        "the .ply quality, the VTK active scalars; else H)")
    v.add_argument("--directions", action="store_true", help="show the principal directions too")
    v.add_argument("--camera", type=_camera, default="auto", metavar="DIR",
                   help="as for 'igl-hhj curvature' (default auto)")
    v.add_argument("--size", type=int, nargs=2, default=(1024, 768), metavar=("W", "H"),
                   help="--screenshot size in pixels (default 1024 768)")
    v.add_argument("--robust", type=float, default=1.0, metavar="P",
                   help="colour range from the P-th to the (100-P)-th percentile (default 1; 0: full range)")
    v.add_argument("-q", "--quiet", action="store_true", help="print nothing but warnings and errors")
    v.set_defaults(func=_view)
