"""``igl-hhj batch INPUT... -o OUTDIR``: many meshes through :mod:`igl_hhj.batch`."""
from __future__ import annotations

import argparse
import sys

from ._common import UserError


def _memory_bytes(text):
    """``2000000000``, ``2e9``, ``512M``, ``4G``, ``1.5GiB`` -> bytes."""
    import re
    m = re.fullmatch(r"\s*([0-9.eE+]+)\s*([kKmMgGtT]?)(i?[bB])?\s*", text)
    try:
        value = float(m.group(1)) if m else None
    except ValueError:
        value = None
    if value is None or not value > 0:
        raise argparse.ArgumentTypeError(f"not a positive number of bytes: {text!r} (e.g. 4G)")
    base = 1024 if m.group(3) and m.group(3).lower() == "ib" else 1000
    return int(value * base ** " kmgt".index(m.group(2).lower() or " "))


def _batch(args):
    from .. import batch
    if args.workers is not None and args.workers < 0:
        raise UserError(f"--workers must be at least 0, got {args.workers}")
    if args.workers is not None and args.workers > batch.MAX_WORKERS:
        raise UserError(f"--workers must be at most {batch.MAX_WORKERS} (one process each), "
                        f"got {args.workers}")
    if not str(args.out).strip():
        raise UserError("-o/--out: empty output path")
    try:
        result = batch.run_batch(args.inputs, args.out, scheduler=args.scheduler,
                                 workers=args.workers, method=args.method, per=args.per,
                                 radius=args.radius, fmt=args.format, resume=args.resume,
                                 feature_angle=args.feature_angle, strict=args.strict,
                                 timeout=args.timeout, memory_limit=args.memory_limit,
                                 progress=not args.quiet,
                                 group_bytes=(batch.GROUP_BYTES if args.group_bytes is None
                                              else args.group_bytes))
    except (ValueError, ImportError) as exc:
        raise UserError(str(exc)) from None
    except OSError as exc:
        raise UserError(f"{args.out}: {exc.strerror or exc}") from None
    for was, n in result.recomputed.items():
        print(f"igl-hhj: recomputed {n} mesh{'es' if n > 1 else ''} whose output had {was} "
              f"(now {batch.describe_options(batch.options_key(args.method, args.per, args.radius, args.feature_angle))})",
              file=sys.stderr)
    c = result.counts()
    of = f" of {result.total}" if len(result.rows) < result.total else ""
    print(f"{len(result.rows)}{of} meshes: {c['ok']} ok, {c['error']} error, {c['timeout']} timeout, "
          f"{c['skipped']} skipped in {result.seconds:.1f} s ({result.mode}); "
          f"summary {result.summary_files[0]}")
    if result.interrupted:
        print("igl-hhj: interrupted (rerun the same command to continue)", file=sys.stderr)
        return 130
    return 0 if c["error"] + c["timeout"] == 0 else 1


def batch_formats():
    from ..batch import FORMATS
    return FORMATS


def batch_group_bytes():
    from ..batch import GROUP_BYTES
    return GROUP_BYTES


def add_parser(sub):
    """The ``batch`` sub-command."""
    b = sub.add_parser("batch", help="curvature of many mesh files, in parallel (Dask)",
                       description="igl-hhj curvature -o for every mesh in INPUT (files, folders "
                                   "searched recursively, glob patterns): OUTDIR/<relative "
                                   "path>.FORMAT and OUTDIR/summary.csv (+ summary.parquet with "
                                   "pyarrow). Embedded Dask cluster by default (in-process for a "
                                   "handful of files), or an existing one with --scheduler.",
                       epilog="exit codes: 0 all ok/skipped, 1 some meshes failed (see "
                              "summary.csv), 2 user error, 130 interrupted (rerun to resume)")
    b.add_argument("inputs", nargs="+", metavar="INPUT")
    b.add_argument("-o", "--out", required=True, metavar="OUTDIR", help="output folder")
    b.add_argument("--scheduler", metavar="ADDRESS",
                   help="Dask scheduler to use, e.g. tcp://<scheduler-host>:8786 (default: embedded cluster)")
    b.add_argument("--workers", type=int, metavar="N",
                   help="worker processes of the embedded cluster (default: number of cores; "
                        "0: in-process)")
    b.add_argument("--method", choices=["hhj", "igl", "heine"], default="hhj",
                   help="as for 'igl-hhj curvature' (default hhj)")
    b.add_argument("--per", choices=["face", "vertex"], default="vertex",
                   help="as for 'igl-hhj curvature' (default vertex)")
    b.add_argument("--radius", type=int, metavar="R",
                   help="as for 'igl-hhj curvature': hhj smoothing scale (default 5 per vertex, 0 per face), igl k-ring")
    b.add_argument("--feature-angle", type=float, default=None, metavar="DEG",
                   help="as for 'igl-hhj curvature': hhj with creases above DEG degrees (default off)")
    b.add_argument("--strict", action="store_true",
                   help="as for 'igl-hhj curvature': refuse (error row) a mesh the drop-in would repair")
    b.add_argument("--format", choices=list(batch_formats()), default="npz",
                   help="npz (default; same content as 'igl-hhj curvature -o X.npz'), ply, or "
                        "vtp / vtu (ParaView, pyvista)")
    b.add_argument("--resume", action=argparse.BooleanOptionalAction, default=True,
                   help="skip inputs whose output is newer than the input (default on)")
    b.add_argument("--timeout", type=float, metavar="S",
                   help="seconds per mesh (status timeout when exceeded)")
    b.add_argument("--memory-limit", type=_memory_bytes, metavar="BYTES",
                   help="resident memory per mesh, e.g. 4G (status error when exceeded)")
    b.add_argument("--group-bytes", type=int, default=None, metavar="N",
                   help="group small input files into one task up to N bytes in total "
                        "(default %d; 0: one mesh per task)" % batch_group_bytes())
    b.add_argument("-q", "--quiet", action="store_true", help="no progress bar / lines")
    b.set_defaults(func=_batch)
