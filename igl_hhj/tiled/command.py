"""``igl-hhj curvature MESH -o OUT --tile-faces N``: :func:`igl_hhj.tiled.curvature_file`
from the command line (the ``curvature`` command hands over when ``--tile-faces`` is given)."""
from __future__ import annotations

__all__ = ["run"]

_NOT_TILED = (("method", "hhj", "--method"), ("per", "vertex", "--per"), ("feature_angle", None, "--feature-angle"),
              ("view", False, "--view"), ("screenshot", None, "--screenshot"))


def run(args, say=print):
    """Run the tiled computation of ``args`` (the parsed ``curvature`` command); returns 0."""
    from ..cli._common import EXIT_UNREADABLE, UserError
    from ..errors import MeshFileError
    from . import curvature_file
    for name, default, flag in _NOT_TILED:
        if getattr(args, name, default) != default:
            raise UserError(f"{flag} cannot be used with --tile-faces (tiled runs compute the "
                            f"drop-in's per-vertex values, hhj)")
    if args.out is None:
        raise UserError("--tile-faces needs -o OUT, the output folder (OUT/PV1.npy, ...)")
    if args.tile_faces < 1:
        raise UserError(f"--tile-faces must be at least 1, got {args.tile_faces}")
    try:
        res = curvature_file(args.mesh, args.out, radius=5 if args.radius is None else args.radius,
                             tile_faces=args.tile_faces, scheduler=args.scheduler, workers=args.workers,
                             resume=args.resume, progress=False if args.quiet else None)
    except MeshFileError as exc:
        raise UserError(str(exc), EXIT_UNREADABLE) from None
    except (ValueError, TypeError) as exc:
        raise UserError(f"{args.mesh}: {exc}") from None
    rings = [s["rings"] for s in res.stats.values()]
    done = "continued an earlier run, " if res.resumed else ""
    say(f"{args.mesh}: {res.n_faces} faces, {res.n_vertices} vertices ({res.read}), {len(res.stats)} tiles, "
        f"overlap {min(rings)}-{max(rings)} rings, faces computed / faces {res.faces_computed / res.n_faces:.2f}")
    say(f"{done}{len(res.computed)} tiles computed in {res.seconds:.1f} s; {res.n_bad} bad vertices (NaN rows)")
    say(f"values: {res.out}/PD1.npy PD2.npy PV1.npy PV2.npy bad_vertices.npy (igl_hhj.tiled.read_result), "
        f"tiles: {res.out}/tiles.csv")
    return 0
