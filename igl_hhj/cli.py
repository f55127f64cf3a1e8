"""The ``igl-hhj`` command line (also ``python -m igl_hhj.cli``).

Commands
--------
``igl-hhj demo``
    HHJ vs libigl curvature errors on a jittered ellipsoid sequence, then a
    screenshot of the finest mesh (headless; skipped with a warning when EGL
    is missing).
``igl-hhj curvature MESH``
    principal curvatures and directions, mean and Gauss curvature of a mesh
    file, written to ``.npz``, ``.csv``, ``.ply``, ``.vtp``, ``.vtu``, ``.vtk`` or
    ``.obj``; optional polyscope view or screenshot.
``igl-hhj view RESULT``
    re-open a saved result (``curvature -o`` ``.npz``, ``.ply``, ``.vtp``, ``.vtu``,
    ``.vtk``) with its stored quantities in the viewer, or ``--screenshot PNG``.
``igl-hhj info MESH``
    what the mesh is made of, whether igl_hhj accepts it, and which repairs the
    drop-in ``principal_curvature`` would make to a refused one.
``igl-hhj batch INPUT... -o OUTDIR``
    ``curvature -o`` for many meshes on an embedded or existing Dask cluster
    (:mod:`igl_hhj.batch`); exit 1 when some meshes failed (rows in
    ``OUTDIR/summary.csv``).

Exit codes
----------
0 success; 1 ``info``: the file was read but igl_hhj rejects the mesh;
2 user error (a mesh igl_hhj rejects in ``curvature``, bad options, unwritable
output, viewer unavailable for ``--view`` / ``--screenshot``); 3 unreadable mesh
file (missing, unreadable, malformed, truncated); 4 the solver failed on an
accepted mesh; 5 out of memory; 70 internal error (a bug: please report it);
130 interrupted (Ctrl-C).  Every failure prints exactly one line
``igl-hhj: error: ...`` on stderr (warnings: ``igl-hhj: warning: ...``); no
traceback unless ``--debug`` is given.
"""
from __future__ import annotations

import os
import signal
import sys


def _interrupted_at_startup(signum, frame):      # Ctrl-C while the imports below run
    sys.stderr.write("igl-hhj: interrupted\n")
    os._exit(130)


# not in batch workers: multiprocessing re-runs this module there as __mp_main__ (with the
# parent's argv) and they inherit SIGINT ignored; each used to print "interrupted" too
if (__name__ == "__main__" or os.path.basename(sys.argv[0] if sys.argv else "") in ("igl-hhj", "cli.py")) \
        and __name__ != "__mp_main__" and signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
    try:
        signal.signal(signal.SIGINT, _interrupted_at_startup)
    except (ValueError, OSError):                # not the main thread
        pass

import argparse  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from .mesh_io import CapturedOutput  # noqa: E402

EXIT_REJECTED, EXIT_USAGE, EXIT_UNREADABLE, EXIT_SOLVER, EXIT_MEMORY = 1, 2, 3, 4, 5
EXIT_INTERNAL, EXIT_INTERRUPTED = 70, 130

EGL_HINT = ("headless rendering needs EGL; on Debian/Ubuntu: "
            "apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri")
LARGE_MESH_FACES = 100_000
"""Meshes with more faces get stage-by-stage progress lines on stderr."""


class UserError(Exception):
    """A problem with the user's input: printed as one line, exit code ``code``."""

    def __init__(self, message, code=2):
        super().__init__(message)
        self.code = code


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (argparse prints usage + error = two lines)."""

    def error(self, message):
        raise UserError(f"{message} (see '{self.prog} --help')")


class _Stages:
    """``[i/n] label ... t s`` lines on stderr, only when enabled (large meshes)."""

    def __init__(self, total, enabled):
        self.total, self.enabled, self.i = total, enabled, 0

    def done(self, label, seconds):
        """Report a stage that has already finished."""
        self.i += 1
        if self.enabled:
            print(f"[{self.i}/{self.total}] {label} ... {seconds:.1f} s", file=sys.stderr, flush=True)

    def run(self, label, fn, *args, **kwargs):
        self.i += 1
        if self.enabled:
            print(f"[{self.i}/{self.total}] {label} ...", end=" ", file=sys.stderr, flush=True)
        t = time.perf_counter()
        out = fn(*args, **kwargs)
        if self.enabled:
            print(f"{time.perf_counter() - t:.1f} s", file=sys.stderr, flush=True)
        return out


def _read(path):
    """Guarded read (:func:`igl_hhj.mesh_io.read_mesh_file`); the reader's warnings become
    one warning line.  Polygons split into triangles are not a warning: the callers say so."""
    from .mesh_io import MeshFileError, read_mesh_file
    try:
        mf = read_mesh_file(path)
    except MeshFileError as exc:
        raise UserError(str(exc), EXIT_UNREADABLE) from None
    messages = mf.messages
    if messages:
        more = f" (+{len(messages) - 2} more)" if len(messages) > 2 else ""
        print(f"igl-hhj: warning: {path}: " + "; ".join(messages[:2]) + more, file=sys.stderr)
    return mf


def _check_writable(path, extensions=None):
    from .mesh_io import MeshFileError, check_output_path, probe_writable
    try:
        if extensions is None:
            check_output_path(path)
        else:
            if Path(path).suffix.lower() not in extensions:
                raise MeshFileError(f"{path}: unknown image extension {Path(path).suffix!r} "
                                    f"(use {', '.join(extensions)})")
            probe_writable(path)
    except MeshFileError as exc:
        raise UserError(str(exc)) from None


def _say(args):
    """``print`` for the summary lines, or a no-op with ``-q``."""
    return (lambda *a, **k: None) if getattr(args, "quiet", False) else print


def _viewer():
    from . import viewer
    return viewer


def _quietly(fn, *args, **kwargs):
    """Call ``fn`` with file descriptors 1/2 captured (polyscope's EGL start-up chatter).

    Python warnings raised meanwhile are held back and shown once the descriptors
    are restored (they used to be written into the capture and lost).
    """
    caught: list = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            with CapturedOutput():
                return fn(*args, **kwargs)
    finally:
        for w in caught:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)


# --------------------------------------------------------------------------- demo
def _demo(args):
    import igl

    from . import principal_curvature
    from .convergence import eoc, vertex_errors
    from .surfaces import Ellipsoid, ellipsoid_coarse, mesh_sequence

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


def _with_hint(exc):
    """The viewer's message, with the EGL package hint unless it already has one."""
    msg = _first_line(exc)
    return msg if "libegl1" in msg else f"{msg}; {EGL_HINT}"


def _first_line(exc):
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


# --------------------------------------------------------------------------- curvature
def _curvature(args):
    from .batch import check_curvature_options, compute_curvature, default_radius
    from .mesh import TriangleMesh

    say = _say(args)
    if args.tile_faces is not None:            # out of core, tile by tile (igl_hhj.tiled)
        from .tiled.command import run
        return run(args, say)

    per = args.per
    try:
        check_curvature_options(args.method, per, args.radius, args.feature_angle)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    if not 0 <= args.robust < 50:
        raise UserError(f"--robust must be a percentile in [0, 50), got {args.robust}")
    if args.out is not None:
        if not str(args.out).strip():
            raise UserError("-o/--out: empty output path")
        if os.path.realpath(args.out) == os.path.realpath(args.mesh):
            raise UserError(f"-o {args.out}: is the input mesh itself; refusing to overwrite it "
                            f"(choose another output file)")
        _check_writable(args.out)
    if args.screenshot is not None:
        _check_writable(args.screenshot, (".png",))
        if min(args.size) < 16:
            raise UserError(f"--size must be at least 16 16 pixels, got {args.size[0]} {args.size[1]}")

    t = time.perf_counter()
    mf = _read(args.mesh)
    V, F = mf.V, mf.F
    try:
        mesh = TriangleMesh(V, F)
    except (ValueError, TypeError) as exc:
        raise UserError(f"{args.mesh}: igl_hhj cannot use this mesh: {exc} "
                        f"(run 'igl-hhj info {args.mesh}' for a diagnosis)") from None
    t_read = time.perf_counter() - t
    large = mesh.n_faces > LARGE_MESH_FACES and not args.quiet
    keep_S = args.out is not None and Path(args.out).suffix.lower() == ".npz"
    n_stages = (2 + (keep_S and args.method == "hhj") + (args.out is not None)
                + (args.screenshot is not None))
    stages = _Stages(n_stages, large)
    stages.done(f"reading and validating {mesh.n_faces} faces", t_read)

    radius = args.radius if args.radius is not None else default_radius(args.method, per)

    t = time.perf_counter()
    est, S = compute_curvature(mesh.V, mesh.F, method=args.method, per=per,
                               radius=args.radius,
                               keep_shape_operator=keep_S, run=stages.run,
                               feature_angle=args.feature_angle)
    dt = time.perf_counter() - t

    say(f"{args.mesh}: {mesh.n_vertices} vertices, {mesh.n_faces} faces, "
          f"{int(mesh.boundary_edges.sum())} boundary edges")
    if mf.split.n_split:
        say(f"  {mf.split.describe()}")
    say(f"  method {args.method} per {per}: {dt:.2f} s")
    if args.method == "hhj":
        say(f"  smoothing scale (--radius): {radius}" + (" (none: Walker's S_h per face)" if radius == 0 else ""))
        if mesh.has_boundary:
            say("  boundary: clamped with estimated normals (quadric fits; igl_hhj.boundary_estimation)")
        if args.feature_angle is not None:
            from .features import crease_edges, crease_network
            net = crease_network(mesh, crease_edges(mesh, args.feature_angle))
            say(f"  creases (--feature-angle {args.feature_angle:g}): {len(net.edge_index)} edges in "
                f"{net.n_chains} chains, {len(net.corners)} corners; cut along them, each side clamped "
                f"with its own estimated normals; Σ θ_e|e| = {net.total_angle_length:.4g}")
    elif args.method == "igl":
        say(f"  radius: {radius} rings")
    for name, x in [("k1", est.k1), ("k2", est.k2), ("H", est.H), ("K", est.K)]:
        q = np.nanpercentile(x, [1, 50, 99]) if np.isfinite(x).any() else [np.nan] * 3
        say(f"  {name:>3}: 1% {q[0]: .4g}   median {q[1]: .4g}   99% {q[2]: .4g}")
    n_nan = int(np.isnan(est.k1).sum())
    if n_nan:
        say(f"  {n_nan} {'vertice' if per == 'vertex' else 'face'}s have no value (NaN): "
            f"{_nan_reasons(mesh, est, args.method)}")

    if args.out is not None:
        _write(stages, args, mesh, est, S)

    if args.screenshot is not None or args.view:
        viewer = _viewer()
        name = Path(args.mesh).stem
        robust = args.robust if args.robust > 0 else None
        shown = dict(estimate=est, name=name, robust=robust, enabled=args.quantity, view=args.camera)
        def creases():           # --feature-angle: the crease network on the surface, coloured by θ_e
            if args.feature_angle is None or args.method != "hhj":
                return []
            return [viewer.register_creases(mesh.V, mesh.F, feature_angle=args.feature_angle,
                                            name=f"{name} creases", view=args.camera)]

        if args.view:            # first: the interactive window cannot open after an EGL render
            try:
                viewer.register_curvature(mesh.V, mesh.F, **shown)
                creases()
                viewer.show()
            except viewer.ViewerUnavailable as exc:
                raise UserError(f"cannot open the viewer window: {_first_line(exc)} "
                                f"(without a display use --screenshot PNG)") from None
        if args.screenshot is not None:
            try:
                if args.feature_angle is None:
                    stages.run("screenshot", _quietly, viewer.register_curvature, mesh.V, mesh.F,
                               screenshot=str(args.screenshot), size=tuple(args.size), **shown)
                else:
                    def shot():
                        viewer.init("openGL3_egl")
                        regs = [viewer.register_curvature(mesh.V, mesh.F, **shown)] + creases()
                        viewer.screenshot(str(args.screenshot), regs, size=tuple(args.size))
                    stages.run("screenshot", _quietly, shot)
            except viewer.ViewerUnavailable as exc:
                raise UserError(f"no screenshot: {_with_hint(exc)}") from None
            say(f"  wrote {args.screenshot}")
    return 0


def _nan_reasons(mesh, est, method):
    """Why rows are NaN, with counts (the causes ``bad_vertices`` documents)."""
    nan = np.isnan(est.k1)
    if est.location != "vertex":
        return "the solver returned no value there"
    unref = nan & ~mesh.referenced_vertices
    folded = nan & mesh.folded_vertices
    rest = nan & ~unref & ~folded
    parts = []
    if unref.any():
        parts.append(f"{int(unref.sum())} unreferenced")
    if folded.any():
        parts.append(f"{int(folded.sum())} without a tangent plane (the faces around them cancel: "
                     f"a two-sided or folded sheet, first vertex {int(np.flatnonzero(folded)[0])})")
    if rest.any():
        why = "flagged by libigl (< 6 neighbours)" if method == "igl" else "non-finite estimate"
        parts.append(f"{int(rest.sum())} {why}")
    return ", ".join(parts)


def _write(stages, args, mesh, est, S):
    from .mesh_io import write_curvature
    try:
        stages.run(f"writing {args.out}", write_curvature, args.out, mesh.V, mesh.F, est,
                   method=args.method, S=S, quantity=args.quantity)
    except OSError as exc:
        raise UserError(f"{args.out}: cannot write: {exc.strerror or exc}") from None
    _say(args)(f"  wrote {args.out}")


# --------------------------------------------------------------------------- batch
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
    from . import batch
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
                                 feature_angle=args.feature_angle,
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


# --------------------------------------------------------------------------- view
def _view(args):
    """Re-open a saved result (:func:`igl_hhj.viewer.register_result`): the window, or
    ``--screenshot`` headless."""
    from .mesh_io import MeshFileError, read_curvature
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


# --------------------------------------------------------------------------- info
def _info(args):
    from .mesh_report import mesh_report
    mf = _read(args.mesh)
    report = mesh_report(mf.V, mf.F, split=mf.split)
    print(f"{args.mesh}")
    for line in report.lines():
        print(f"  {line}")
    return 0 if report.accepted else 1


# --------------------------------------------------------------------------- main
def _camera(text):
    """``--camera`` value: a name of :data:`igl_hhj.viewer.VIEWS` or ``X,Y,Z``."""
    names = ("auto", "+x", "-x", "+y", "-y", "+z", "-z")
    if text in names:
        return text
    try:
        d = [float(x) for x in text.split(",")]
    except ValueError:
        d = []
    if len(d) != 3 or not np.all(np.isfinite(d)) or not np.any(d):
        raise argparse.ArgumentTypeError(f"expected one of {', '.join(names)} or a nonzero direction X,Y,Z, "
                                         f"got {text!r}")
    return tuple(d)


def _version():
    from importlib import metadata

    from . import __version__
    try:
        libigl = metadata.version("libigl")
    except metadata.PackageNotFoundError:  # pragma: no cover - libigl is a dependency
        libigl = "not installed"
    return f"igl-hhj {__version__} (libigl {libigl})"


def _named_demo(argv):
    """``igl-hhj demo NAME [options]``: run demo NAME of :mod:`igl_hhj.demos` with its own
    options; None when ``argv`` is not such a call."""
    from .demos import DEMOS, run
    if argv is None:
        argv = sys.argv[1:]
    if len(argv) >= 2 and argv[0] == "demo" and argv[1] in DEMOS:
        return run(argv[1], argv[2:], prog=f"igl-hhj demo {argv[1]}")
    return None


def batch_formats():
    from .batch import FORMATS
    return FORMATS


def batch_group_bytes():
    from .batch import GROUP_BYTES
    return GROUP_BYTES


def build_parser():
    parser = _Parser(prog="igl-hhj",
                     description="igl_hhj: convergent finite-element (HHJ) curvature of triangle meshes.",
                     epilog="exit codes: 0 ok, 1 info: mesh rejected, 2 user error, 3 unreadable "
                            "mesh file, 4 solver failure, 5 out of memory, 70 internal error, "
                            "130 interrupted")
    parser.add_argument("--debug", action="store_true",
                        help="show the Python traceback of a failure (anywhere on the command line)")
    parser.add_argument("--version", action="version", version=_version(),
                        help="print the versions of igl-hhj and libigl and exit")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    from .demos import DEMOS
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

    c = sub.add_parser("curvature", help="curvature of a mesh file (libigl's formats, glTF, 3MF, VTK)",
                       description="Principal curvatures k1 >= k2, directions d1, d2, mean H and "
                                   "Gauss K curvature of a triangle mesh (.obj .off .ply .stl .wrl "
                                   ".mesh .msh with libigl; .gltf .glb .3mf with trimesh, .vtp .vtu "
                                   ".vtk with pyvista or meshio). Polygons are split into triangles "
                                   "(fan from each polygon's first corner). Sign: +1/R on a sphere "
                                   "with outward normals.")
    c.add_argument("mesh", metavar="MESH")
    c.add_argument("--method", choices=["hhj", "igl", "heine"], default="hhj",
                   help="hhj: Walker's HHJ shape operator (default); igl: igl.principal_curvature "
                        "(quadric fit); heine: Heine's P1 Weingarten map (does not converge)")
    c.add_argument("--per", choices=["face", "vertex"], default="vertex",
                   help="vertex (default, comparable with libigl) or face (HHJ's native "
                        "piecewise-constant values; hhj only)")
    c.add_argument("--radius", type=int, default=None, metavar="R",
                   help="scale: for hhj the smoothing length in rings / mean edge lengths "
                        "(default 5 per vertex as igl.principal_curvature, 0 per face: Walker's S_h); "
                        "for igl the k-ring size (default 5)")
    c.add_argument("--feature-angle", type=float, default=None, metavar="DEG",
                   help="hhj: sharp features; edges whose normals turn by more than DEG degrees "
                        "(e.g. 40) are creases: the surface is cut along them and each side gets "
                        "its own values (default: off, as libigl)")
    c.add_argument("-o", "--out", metavar="OUT",
                   help="output file, by extension: OUT.npz (k1, k2, H, K, d1, d2, V, F, and the "
                        "shape operator S for hhj), OUT.csv (one row per vertex or face), OUT.ply "
                        "(the values as vertex or face properties, --quantity as MeshLab's quality), "
                        "OUT.vtp / OUT.vtu / OUT.vtk (point or cell data for ParaView/pyvista, "
                        "--quantity the active scalars), "
                        "OUT.obj (vertices coloured by --quantity)")
    c.add_argument("--view", action="store_true", help="open the polyscope viewer")
    c.add_argument("--screenshot", metavar="PNG", help="render the curvature headless to PNG")
    c.add_argument("--quantity", choices=["k1", "k2", "H", "K"], default="H",
                   help="what --view/--screenshot and .obj colours and the .ply 'quality' property show: "
                        "k1, k2 (principal curvatures), H (mean, default), K (Gauss)")
    c.add_argument("--camera", type=_camera, default="auto", metavar="DIR",
                   help="side the --view/--screenshot camera looks from: auto (largest projected "
                        "area, default), +x, -x, +y, -y, +z, -z, or a direction X,Y,Z")
    c.add_argument("--size", type=int, nargs=2, default=(1024, 768), metavar=("W", "H"),
                   help="--screenshot size in pixels (default 1024 768)")
    c.add_argument("--robust", type=float, default=1.0, metavar="P",
                   help="colour range of --view/--screenshot from the P-th to the (100-P)-th "
                        "percentile (default 1; 0: full range)")
    c.add_argument("-q", "--quiet", action="store_true",
                   help=f"print nothing but warnings and errors: no summary on stdout, no progress "
                        f"lines (stderr, meshes > {LARGE_MESH_FACES} faces)")
    c.add_argument("--tile-faces", type=int, default=None, metavar="N",
                   help="meshes larger than memory: compute in tiles of about N faces (grown by "
                        "the overlap the computation needs) on Dask; -o OUT is then a folder of "
                        ".npy arrays (igl_hhj/docs/tiled.md)")
    c.add_argument("--scheduler", metavar="ADDRESS",
                   help="with --tile-faces: a Dask scheduler (default: embedded cluster)")
    c.add_argument("--workers", type=int, metavar="N",
                   help="with --tile-faces: worker processes of the embedded cluster (default: cores; 0: in-process)")
    c.add_argument("--resume", action=argparse.BooleanOptionalAction, default=True,
                   help="with --tile-faces: continue an interrupted run into OUT (default on)")
    c.set_defaults(func=_curvature)

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

    from .mesh_io import RESULT_EXTENSIONS
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

    i = sub.add_parser("info", help="mesh statistics and whether igl_hhj accepts the mesh",
                       description="Vertices, faces, edges, components, boundary loops, Euler "
                                   "characteristic, genus, manifoldness, orientation, degenerate and "
                                   "duplicate faces, the repairs the drop-in principal_curvature would "
                                   "make, and igl_hhj's verdict. Exit 0 accepted, "
                                   "1 rejected, 2 unreadable.")
    i.add_argument("mesh", metavar="MESH")
    i.set_defaults(func=_info)
    return parser


def _one_line(text):
    """Collapse a message to one line (C++/numpy messages may span several)."""
    return " ".join(str(text).split()) or "(no message)"


_WARNED: set[str] = set()


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """Warnings as ``igl-hhj: warning: ...`` lines, each message once per run."""
    text = _one_line(message)
    if text not in _WARNED:
        _WARNED.add(text)
        print(f"igl-hhj: warning: {text}", file=sys.stderr, flush=True)


def _failure(exc):
    """(exit code, one-line message) for an exception that ended a command."""
    from .errors import SolverError
    if isinstance(exc, UserError):
        return exc.code, _one_line(exc)
    if isinstance(exc, MemoryError) or (isinstance(exc, ImportError) and any(
            m in str(exc) for m in ("failed to map segment", "annot allocate memory"))):
        return EXIT_MEMORY, ("out of memory" + (f" ({_one_line(exc)})" if str(exc) else "")
                             + ": the computation needs more memory than this process may use; "
                               "try a smaller mesh or raise the memory limit")
    from .errors import install_hint, missing_optional
    package = missing_optional(exc)
    if package is not None:
        if "pip install" in str(exc):                 # the message already says what needs it (mesh_io)
            return EXIT_USAGE, _one_line(exc)
        return EXIT_USAGE, f"this needs the optional '{package}' package: {install_hint(package)}"
    if isinstance(exc, (SolverError, np.linalg.LinAlgError)):
        return EXIT_SOLVER, (f"the solver failed: {_one_line(exc)} (check the mesh with "
                             f"'igl-hhj info'; rerun with --debug for the traceback)")
    if isinstance(exc, RuntimeError):
        return EXIT_SOLVER, (f"computation failed: {_one_line(exc)} (rerun with --debug for "
                             f"the traceback)")
    if isinstance(exc, OSError):
        return EXIT_USAGE, _one_line(f"{exc.filename + ': ' if exc.filename else ''}"
                                     f"{exc.strerror or exc}")
    return EXIT_INTERNAL, (f"internal error: {type(exc).__name__}: {_one_line(exc)} (please "
                           f"report it; rerun with --debug for the traceback)")


_SIGINT_SEEN = [False]


def _on_sigint(signum, frame):
    _SIGINT_SEEN[0] = True
    raise KeyboardInterrupt


def _import_deferring_sigint(name):
    """Import a C++ extension with Ctrl-C deferred to the end of the import: a
    KeyboardInterrupt inside pybind11 module initialisation aborts the process
    (``terminate called after throwing pybind11::error_already_set``)."""
    import importlib
    pending = []

    def defer(signum, frame):
        pending.append(signum)
        _SIGINT_SEEN[0] = True

    try:
        previous = signal.signal(signal.SIGINT, defer)
    except (ValueError, OSError):
        previous = None
    try:
        importlib.import_module(name)
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    if pending:
        raise KeyboardInterrupt


def main(argv=None):
    """Run the command line; returns the exit code (``sys.exit(main())``).

    Every exception ends as one ``igl-hhj: error: ...`` line and an exit code
    (module docstring); ``--debug`` anywhere on the command line re-raises
    failures other than user errors, with their traceback.
    """
    _SIGINT_SEEN[0] = False
    try:
        signal.signal(signal.SIGINT, _on_sigint)          # KeyboardInterrupt from here on
    except (ValueError, OSError):
        pass
    try:
        argv = list(sys.argv[1:] if argv is None else argv)
        debug = "--debug" in argv
        argv = [a for a in argv if a != "--debug"]
        _WARNED.clear()
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning
            try:
                named = _named_demo(argv)
                if named is not None:
                    return named
                args = build_parser().parse_args(argv)
                _import_deferring_sigint("igl")
                return args.func(args)
            except SystemExit as exc:                    # --help
                return exc.code if isinstance(exc.code, int) else 0
            except KeyboardInterrupt:
                raise
            except Exception as exc:
                if _SIGINT_SEEN[0]:            # e.g. pybind11 turned the interrupt into ImportError
                    raise KeyboardInterrupt from exc
                if debug and not isinstance(exc, UserError):
                    raise
                code, message = _failure(exc)
                print(f"igl-hhj: error: {message}", file=sys.stderr)
                return code
    except KeyboardInterrupt:
        print("igl-hhj: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":
    _code = main()
    if _code == EXIT_INTERRUPTED:
        # CPython remembers a KeyboardInterrupt raised inside C-level PyRun_* calls
        # (library imports) even when it was handled, and `python -m` then ends
        # with a re-raised SIGINT (-2) instead of our exit code: leave directly.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_code)
    sys.exit(_code)
