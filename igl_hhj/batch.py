"""Curvature of whole mesh collections, in-process or on a Dask cluster (``igl-hhj batch``).

One output file per input mesh, with exactly the content ``igl-hhj curvature
-o`` writes for that mesh (both go through :func:`compute_curvature` and
:func:`igl_hhj.mesh_io.write_curvature`), plus ``OUTDIR/summary.csv`` (and
``summary.parquet`` when pyarrow is installed) with one row per input.

Execution
---------
* no ``scheduler``: a handful of files (≤ :data:`IN_PROCESS_MAX_FILES`, or
  ``workers=0``) run in this process; more run on an embedded
  ``distributed.LocalCluster`` of worker *processes* (one thread each), sized
  to the machine;
* ``scheduler="tcp://host:port"``: the meshes are submitted to that Dask
  cluster (``dask scheduler`` + ``dask worker``, dask-jobqueue, Kubernetes,
  ...).  Workers need only ``igl_hhj`` installed and must see the input and
  output paths (shared file system).

Dask does the scheduling, data transfer and worker supervision; this module
only plans the files, groups small meshes into one task (to amortise the
per-task overhead, see :data:`GROUP_BYTES`), and turns every outcome into a
summary row.

Failure isolation
-----------------
Every mesh ends with exactly one row whose ``status`` is ``ok``, ``error``,
``skipped`` or ``timeout``:

* unreadable, corrupt, empty, non-manifold, ... meshes: ``error`` with the
  one-line message of :func:`igl_hhj.mesh_io.read_mesh` /
  :class:`igl_hhj.mesh.TriangleMesh`;
* a worker process that dies (segfault, killed by the OS or by Dask's memory
  monitor) has its tasks re-run by Dask; a task whose workers died more than
  ``distributed.scheduler.allowed-failures`` times (embedded cluster:
  ``retries``) is split into single meshes and re-submitted once more; a
  single mesh that still kills its worker is an ``error`` row;
* ``timeout`` / ``memory_limit``: each mesh runs in a *sandbox* child process
  (one persistent child per worker thread, restarted after a kill) that is
  killed when the mesh takes longer than ``timeout`` seconds (status
  ``timeout``) or its resident memory exceeds ``memory_limit`` bytes
  (``error``, "exceeds the memory limit").

Outputs are written to a temporary file next to the target and renamed
(``os.replace``), so an output either is complete or does not exist;
temporaries left by killed workers (``*.igl-hhj-tmp.*``) are removed at the
end of every run, including an interrupted one.

Resume
------
With ``resume=True`` (default) an input whose output exists and is newer than
the input is not recomputed (status ``skipped``; its statistics are copied
from the previous ``summary.csv`` when it has them) -- provided it was computed
with the same ``method``, ``per`` and ``radius``: ``OUTDIR/.igl-hhj-options.json``
records the options of every output (see :data:`OPTIONS_FILE`); an output
computed with other options, or of unknown options, is recomputed and
:attr:`BatchResult.recomputed` says so.
"""
from __future__ import annotations

import csv
import glob
import math
import os
import sys
import threading
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .mesh_io import MESH_EXTENSIONS, MeshFileError

__all__ = ["compute_curvature", "check_curvature_options", "Job", "plan_jobs", "process_mesh",
           "run_batch", "BatchResult", "SUMMARY_COLUMNS", "FORMATS", "IN_PROCESS_MAX_FILES",
           "GROUP_BYTES"]

FORMATS = ("npz", "ply", "vtp", "vtu")
"""Output formats of ``igl-hhj batch`` (as ``igl-hhj curvature -o``)."""

IN_PROCESS_MAX_FILES = 4
"""Without a scheduler, at most this many files run in-process (no cluster start-up)."""

GROUP_BYTES = 400_000
"""Consecutive input files are grouped into one Dask task until their sizes add up to
this many bytes (about 8k faces of ascii OFF); larger files are one task each.
``python -m igl_hhj.benchmarks.batch`` compares it with one mesh per task (igl_hhj/docs/batch.md, "Throughput")."""

GROUP_MAX = 16
"""At most this many meshes per task."""

PERCENTILES = (1, 50, 99)
QUANTITIES = ("k1", "k2", "H", "K")
SUMMARY_COLUMNS = (["path", "output", "status", "vertices", "faces", "seconds", "cpu_seconds",
                    "peak_memory", "error", "warnings"]
                   + [f"{q}_p{p:02d}" for q in QUANTITIES for p in PERCENTILES] + ["nan_values"])
"""Columns of ``summary.csv``: ``seconds`` wall-clock and ``cpu_seconds`` CPU time (all
threads of the process computing the mesh) from reading to writing; ``peak_memory`` in
bytes (the process's peak resident set during the mesh, Linux only, empty when unknown
or when the worker runs several threads); ``warnings`` what the mesh's reading and
computation warned about (libigl's reader messages, :class:`igl_hhj.mesh.MeshWarning`,
numpy), one-line messages joined by `` | `` (empty: none), recorded where the mesh was
computed, so Dask workers' warnings are not lost; ``k1_p01 ... K_p99`` the 1st/50th/99th
percentiles over the vertices or faces; ``nan_values`` the number of elements without a
value."""

TMP_MARK = ".igl-hhj-tmp"

# (method, per) -> igl_hhj.baselines estimator
ESTIMATORS = {("hhj", "vertex"): "hhj_vertex", ("hhj", "face"): "hhj_face",
              ("igl", "vertex"): "libigl_quadric", ("heine", "vertex"): "heine"}
METHOD_LABELS = {"hhj": "HHJ solve", "igl": "libigl quadric fit", "heine": "Heine P1 solve"}


# --------------------------------------------------------------------------- one mesh
MAX_RADIUS = 10**6
MAX_WORKERS = 256
"""Largest ``workers`` of the embedded cluster (each is a process)."""
"""Largest ``--radius`` (as :func:`igl_hhj.curvature.check_principal_curvature_args`)."""


def check_curvature_options(method, per, radius=None, feature_angle=None):
    """Raise ``ValueError`` for a combination ``igl-hhj curvature`` / ``batch`` cannot compute.

    ``radius``: hhj per vertex, the smoothing scale of :func:`igl_hhj.principal_curvature`
    (> 0); hhj per face, ``smoothing`` of :func:`igl_hhj.face_principal_curvature` (≥ 0);
    igl, libigl's k-ring (> 0); not for heine.  None: the defaults of
    :func:`default_radius`.  ``feature_angle``: degrees in (0, 180), hhj only (per face
    only unsmoothed, radius 0), see :mod:`igl_hhj.features`."""
    if method not in METHOD_LABELS:
        raise ValueError(f"unknown method {method!r} (use {', '.join(METHOD_LABELS)})")
    if per not in ("vertex", "face"):
        raise ValueError(f"unknown per {per!r} (use vertex or face)")
    if method != "hhj" and per == "face":
        raise ValueError(f"--method {method} computes per-vertex curvature only; "
                         f"use --per vertex (or --method hhj for per-face values)")
    if radius is not None:
        if method == "heine":
            raise ValueError("--radius applies to --method hhj and igl, not heine")
        if isinstance(radius, (bool, np.bool_)) or not isinstance(radius, (int, np.integer)):
            raise ValueError(f"--radius must be an integer, got {radius!r}")
        if radius < 0 or (radius == 0 and not (method == "hhj" and per == "face")):
            raise ValueError(f"--radius must be a positive integer (0 only with --per face), "
                             f"got {radius}")
        if radius > MAX_RADIUS:
            raise ValueError(f"--radius must be at most {MAX_RADIUS} (10**6), got {radius:.3g}")
    if feature_angle is not None:
        if method != "hhj":
            raise ValueError(f"--feature-angle applies to --method hhj, not {method}")
        if per == "face" and radius:
            raise ValueError("--feature-angle with --per face gives Walker's S_h of the cut surface "
                             "unsmoothed: use --radius 0 (or --per vertex)")
        from .features import check_feature_angle
        try:
            check_feature_angle(feature_angle)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"--{exc}".replace("feature_angle", "feature-angle", 1)) from None


def default_radius(method, per):
    """The ``radius`` used when none is given: 5 per vertex (as ``igl.principal_curvature``),
    0 per face (Walker's S_h itself), None for heine."""
    if method == "heine":
        return None
    return 0 if per == "face" else 5


def _call(label, fn, *args, **kwargs):
    return fn(*args, **kwargs)


def compute_curvature(V, F, *, method="hhj", per="vertex", radius=None, keep_shape_operator=False,
                      run=None, feature_angle=None):
    """Curvature of one mesh exactly as ``igl-hhj curvature`` and ``igl-hhj batch`` compute it.

    Parameters
    ----------
    V : (#V, 3) float64, F : (#F, 3) int
        A mesh :class:`igl_hhj.mesh.TriangleMesh` accepts.
    method : {"hhj", "igl", "heine"}
    per : {"vertex", "face"} ("face": hhj only)
    radius : int, optional
        See :func:`check_curvature_options`; None: :func:`default_radius`.
    keep_shape_operator : bool
        Also return the HHJ shape operator S_h (Walker eq. 5.12), as stored in
        the ``.npz`` output; ignored for igl/heine.
    run : callable, optional
        ``run(label, fn, *args, **kwargs)`` wraps each stage (the CLI's
        progress lines); default: call ``fn``.
    feature_angle : float, optional
        hhj only: sharp features (:mod:`igl_hhj.features`), creases above this many degrees.

    Returns
    -------
    est : igl_hhj.baselines.CurvatureEstimate
    S : (#F, 3, 3) float64 or None
    """
    from . import baselines
    check_curvature_options(method, per, radius, feature_angle)
    run = run or _call
    if radius is None:
        radius = default_radius(method, per)
    label = f"{METHOD_LABELS[method]} ({per})"
    if method == "hhj" and feature_angle is not None:
        from .curvature import shape_operator
        hhj = baselines.hhj_face if per == "face" else baselines.hhj_vertex
        S = run(f"{METHOD_LABELS[method]} (shape operator, creases)", shape_operator, V, F,
                feature_angle=feature_angle) if keep_shape_operator or per == "face" else None
        if per == "face":                 # S_h of the cut surface itself
            return run(f"curvatures ({per})", hhj, V, F, shape_operator=S), S
        return run(label, hhj, V, F, radius=radius, feature_angle=feature_angle), S
    if method == "hhj":
        hhj = baselines.hhj_face if per == "face" else baselines.hhj_vertex
        scale = {"smoothing": radius} if per == "face" else {"radius": radius}
        if keep_shape_operator:    # solve once, keep S_h for the npz, derive the curvatures from it
            from .curvature import shape_operator
            S = run(f"{METHOD_LABELS[method]} (shape operator)", shape_operator, V, F)
            return run(f"curvatures ({per})", hhj, V, F, shape_operator=S, **scale), S
        return run(label, hhj, V, F, **scale), None
    if method == "igl":
        return run(label, baselines.libigl_quadric, V, F, radius=radius), None
    return run(label, baselines.estimate, ESTIMATORS[method, per], V, F), None


def _atomic_write(path, fmt, V, F, est, method, S):
    """Write to ``.<name>.<pid>.<thread>.igl-hhj-tmp.<fmt>`` in the same folder, then rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.{threading.get_ident()}{TMP_MARK}.{fmt}")
    try:
        from .mesh_io import write_curvature
        write_curvature(tmp, V, F, est, method=method, S=S)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _percentile_stats(est):
    out = {}
    for q in QUANTITIES:
        x = np.asarray(getattr(est, q), dtype=np.float64)
        finite = np.isfinite(x)
        vals = np.percentile(x[finite], PERCENTILES) if finite.any() else [math.nan] * len(PERCENTILES)
        out.update({f"{q}_p{p:02d}": float(v) for p, v in zip(PERCENTILES, vals)})
    out["nan_values"] = int(np.isnan(est.k1).sum())
    return out


def _reset_peak_memory():
    """Reset the kernel's peak-RSS counter of this process (Linux ``clear_refs`` 5)."""
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def _proc_status_bytes(key, pid="self"):
    try:
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


@dataclass(frozen=True)
class Job:
    """One input mesh: ``path`` (as given / found) and its ``output`` file."""

    path: str
    output: str
    size: int = 0


@dataclass(frozen=True)
class Options:
    """What to compute and write for every mesh, and its sandbox limits (see :func:`run_batch`)."""

    method: str = "hhj"
    per: str = "vertex"
    radius: int | None = None
    fmt: str = "npz"
    timeout: float | None = None
    memory_limit: int | None = None
    feature_angle: float | None = None

    @property
    def sandboxed(self):
        """Run each mesh in a sandbox child process (needed to enforce the limits)."""
        return self.timeout is not None or self.memory_limit is not None


OPTIONS_FILE = ".igl-hhj-options.json"
"""``OUTDIR/OPTIONS_FILE``: ``{output relative to OUTDIR: {"options": {method, per, radius},
"done": bool, "t": ns}}``.  ``done`` False: the output was being recomputed with ``options``
from time ``t`` on (an output newer than ``t`` has them, e.g. one finished by a worker
after an interrupt; an older one still has its previous, unknown options)."""


def options_key(method, per, radius, feature_angle=None):
    """The options an output depends on (radius None → :func:`default_radius`;
    ``feature_angle`` only when given, so that older outputs keep their key)."""
    key = {"method": method, "per": per,
           "radius": default_radius(method, per) if radius is None else int(radius)}
    if feature_angle is not None:
        key["feature_angle"] = float(feature_angle)
    return key


def describe_options(key):
    if key is None:
        return "unknown options"
    text = f"--method {key['method']} --per {key['per']}"
    text += f" --radius {key['radius']}" if key.get("radius") is not None else ""
    return text + (f" --feature-angle {key['feature_angle']:g}" if key.get("feature_angle") is not None else "")


def _read_options_file(outdir):
    import json
    try:
        with open(Path(outdir) / OPTIONS_FILE) as fh:
            data = json.load(fh)
        return data if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}


def _write_options_file(outdir, entries):
    import json
    path = Path(outdir) / OPTIONS_FILE
    tmp = Path(outdir) / f".igl-hhj-options.{os.getpid()}.json.new"
    with open(tmp, "w") as fh:
        json.dump(entries, fh, indent=0, sort_keys=True)
    os.replace(tmp, path)


def _made_with(entry, output):
    """The options ``output`` was computed with according to its entry, or None."""
    if not isinstance(entry, dict) or not isinstance(entry.get("options"), dict):
        return None
    if entry.get("done"):
        return entry["options"]
    try:
        return entry["options"] if os.stat(output).st_mtime_ns > int(entry.get("t", 0)) else None
    except (OSError, TypeError, ValueError):
        return None


def _row(job, status, **kw):
    row = {c: None for c in SUMMARY_COLUMNS}
    row.update(path=job.path, output=job.output, status=status, **kw)
    return row


def process_mesh(job, options, measure_peak=True):
    """Read, validate, compute and write one mesh; never raises for a bad mesh.

    Returns the summary row (dict with :data:`SUMMARY_COLUMNS`): status ``ok``
    or ``error`` with the one-line message, and the warnings the mesh raised.
    """
    t0, c0 = time.perf_counter(), time.process_time()
    peak = measure_peak and _reset_peak_memory()
    extra = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")            # every mesh reports its own, not once per process
        status, message, said = _compute_one(job, options, extra)
    said += [str(w.message) for w in caught]
    if said:
        extra["warnings"] = " | ".join(dict.fromkeys(" ".join(m.split()) for m in said if m.strip()))
    if peak:
        extra["peak_memory"] = _proc_status_bytes("VmHWM")
    return _row(job, status, seconds=round(time.perf_counter() - t0, 4),
                cpu_seconds=round(time.process_time() - c0, 4), error=message, **extra)


def _compute_one(job, options, extra):
    """(status, error message, reader messages) of one mesh; statistics go into ``extra``."""
    from .mesh import TriangleMesh
    from .mesh_io import read_mesh
    said = []
    try:
        V, F, said = read_mesh(job.path)
        said = list(said)
        extra.update(vertices=len(V), faces=len(F))
        try:
            mesh = TriangleMesh(V, F)
        except (ValueError, TypeError) as exc:
            raise MeshFileError(f"{job.path}: igl_hhj cannot use this mesh: {exc}") from None
        est, S = compute_curvature(mesh.V, mesh.F, method=options.method, per=options.per,
                                   radius=options.radius,
                                   keep_shape_operator=options.fmt == "npz",
                                   feature_angle=options.feature_angle)
        _atomic_write(job.output, options.fmt, mesh.V, mesh.F, est, options.method, S)
        extra.update(_percentile_stats(est))
        status, message = "ok", None
    except MemoryError:
        status, message = "error", f"{job.path}: out of memory"
    except Exception as exc:           # isolate every failure of one mesh into its row
        msg = " ".join(str(exc).split()) or type(exc).__name__
        if not isinstance(exc, (MeshFileError, ValueError, TypeError, OSError)):
            msg = f"{type(exc).__name__}: {msg}"
        status, message = "error", msg if msg.startswith(job.path) else f"{job.path}: {msg}"
    return status, message, said


# --------------------------------------------------------------------------- sandbox
class _Sandbox:
    """A persistent child process computing one mesh at a time, killed on timeout / memory.

    Not a scheduler: Dask (or the in-process loop) decides what runs where; this only
    runs a mesh at arm's length so that its time and memory can be bounded.
    """

    POLL = 0.02
    START_TIMEOUT = 120.0

    def __init__(self):
        self.proc = None

    def _start(self):
        import subprocess
        from multiprocessing.connection import Connection
        r_job, w_job = os.pipe()
        r_row, w_row = os.pipe()
        code = f"from igl_hhj.batch import _sandbox_main; _sandbox_main({r_job}, {w_row})"
        env = {k: v for k, v in os.environ.items() if k != "MALLOC_TRIM_THRESHOLD_"}  # see _local_cluster
        self.proc = subprocess.Popen([sys.executable, "-c", code], pass_fds=(r_job, w_row), env=env,
                                     stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL)
        os.close(r_job)
        os.close(w_row)
        self.send, self.recv = Connection(w_job, readable=False), Connection(r_row, writable=False)
        # the clock of a mesh starts once the child has imported igl_hhj
        if not self.recv.poll(self.START_TIMEOUT) or self.recv.recv() != "ready":
            self._kill()
            raise RuntimeError(f"the sandbox process did not start within {self.START_TIMEOUT} s")

    def _kill(self):
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.send.close()
            self.recv.close()
            self.proc = None

    def close(self):
        self._kill()

    def run(self, job, options):
        if self.proc is None or self.proc.poll() is not None:
            self._kill()
            self._start()
        t0 = time.perf_counter()
        self.send.send((job, options))
        peak = 0
        while True:
            try:
                if self.recv.poll(self.POLL):
                    return self.recv.recv()
            except (EOFError, OSError):
                pass
            elapsed = time.perf_counter() - t0
            if self.proc.poll() is not None:
                code = self.proc.returncode
                self._kill()
                why = f"killed by signal {-code}" if code < 0 else f"exit code {code}"
                return _row(job, "error", seconds=round(elapsed, 4), peak_memory=peak or None,
                            error=f"{job.path}: the process computing it died ({why})")
            rss = _proc_status_bytes("VmRSS", self.proc.pid) or 0
            peak = max(peak, rss)
            if options.memory_limit is not None and rss > options.memory_limit:
                self._kill()
                return _row(job, "error", seconds=round(elapsed, 4), peak_memory=rss,
                            error=f"{job.path}: exceeds the memory limit ({rss} > "
                                  f"{options.memory_limit} bytes resident)")
            if options.timeout is not None and elapsed > options.timeout:
                self._kill()
                return _row(job, "timeout", seconds=round(elapsed, 4), peak_memory=peak or None,
                            error=f"{job.path}: took longer than {options.timeout:g} s")


def _sandbox_main(r_fd, w_fd):
    """Entry point of a sandbox child: compute the jobs it is sent until the pipe closes."""
    from multiprocessing.connection import Connection
    recv, send = Connection(r_fd, writable=False), Connection(w_fd, readable=False)
    import igl  # noqa: F401
    from . import baselines, curvature, mesh, mesh_io  # noqa: F401
    send.send("ready")
    while True:
        try:
            job, options = recv.recv()
        except (EOFError, OSError):
            return
        send.send(process_mesh(job, options))


_local = threading.local()


def _sandbox():
    box = getattr(_local, "sandbox", None)
    if box is None:
        box = _local.sandbox = _Sandbox()
        import atexit
        atexit.register(box.close)
    return box


def _single_threaded_worker():
    """True unless we run inside a Dask worker with several threads (peak RSS is per process)."""
    try:
        from distributed import get_worker
        return get_worker().state.nthreads == 1
    except (ImportError, ValueError, AttributeError):
        return True


def run_group(jobs, options):
    """The Dask task: compute a group of meshes one after the other, return their rows."""
    single = _single_threaded_worker()
    rows = []
    for job in jobs:
        row = _sandbox().run(job, options) if options.sandboxed else process_mesh(job, options, single)
        rows.append(row)
    return rows


# --------------------------------------------------------------------------- planning
def _is_mesh(p):
    return p.is_file() and p.suffix.lower() in MESH_EXTENSIONS


def collect_inputs(inputs):
    """Expand files, folders (recursively, mesh extensions only) and glob patterns.

    Returns a list of ``(path, root)``: ``root`` is the folder the output path is made
    relative to (the folder given, or the file's own folder).  A path that does not exist
    and is not a pattern is kept (it becomes an ``error`` row).  Raises ``ValueError``
    for a pattern or folder without mesh files.
    """
    found = []
    for item in inputs:
        item = str(item)
        p = Path(item)
        if p.is_dir():
            files = sorted(q for q in p.rglob("*") if _is_mesh(q) and TMP_MARK not in q.name)
            if not files:
                raise ValueError(f"{item}: no mesh files ({', '.join(MESH_EXTENSIONS)}) in this folder")
            found += [(q, p) for q in files]
        elif p.exists() or not glob.has_magic(item):
            found.append((p, p.parent))
        else:
            matches = sorted(Path(m) for m in glob.glob(item, recursive=True))
            files = [m for m in matches if _is_mesh(m)]
            for m in matches:
                if m.is_dir():
                    files += sorted(q for q in m.rglob("*") if _is_mesh(q))
            if not files:
                raise ValueError(f"{item}: no mesh files match this pattern")
            found += [(q, q.parent) for q in files]
    seen, unique = set(), []
    for q, root in found:
        key = os.path.abspath(q)
        if key not in seen:
            seen.add(key)
            unique.append((q, root))
    return unique


def plan_jobs(inputs, outdir, fmt="npz"):
    """One :class:`Job` per input mesh: ``OUTDIR/<path relative to the inputs' common
    folder, extension replaced by .fmt>`` (``a/b.off`` → ``OUTDIR/a/b.npz``; two inputs
    that differ only in extension keep it: ``a/b.off.npz``)."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown format {fmt!r} (use {', '.join(FORMATS)})")
    out_abs = os.path.realpath(outdir) + os.sep            # realpath: also through symlinks
    found = [(q, r) for q, r in collect_inputs(inputs)       # outputs are never inputs
             if not os.path.realpath(q).startswith(out_abs)]
    if not found:
        return []
    roots = [os.path.abspath(r) for _, r in found]
    common = Path(os.path.commonpath(roots))
    rels = [Path(os.path.abspath(q)).relative_to(common) for q, _ in found]
    targets = [r.with_suffix("." + fmt) for r in rels]
    count = {}
    for t in targets:
        count[t] = count.get(t, 0) + 1
    jobs = []
    outdir = Path(outdir)
    for (q, _), rel, t in zip(found, rels, targets):
        if count[t] > 1:
            t = rel.with_name(rel.name + "." + fmt)
        try:
            size = q.stat().st_size
        except OSError:
            size = 0
        jobs.append(Job(str(q), str(outdir / t), size))
    return jobs


def group_jobs(jobs, group_bytes=GROUP_BYTES, group_max=GROUP_MAX):
    """Consecutive jobs in groups of total input size ≤ ``group_bytes`` (≤ ``group_max``)."""
    groups, cur, cur_bytes = [], [], 0
    for job in jobs:
        if cur and (cur_bytes + job.size > group_bytes or len(cur) >= group_max):
            groups.append(cur)
            cur, cur_bytes = [], 0
        cur.append(job)
        cur_bytes += job.size
    if cur:
        groups.append(cur)
    return groups


def _previous_rows(summary):
    try:
        with open(summary, newline="") as fh:
            return {r["path"]: r for r in csv.DictReader(fh)}
    except (OSError, csv.Error, KeyError):
        return {}


def _up_to_date(job):
    try:
        return os.stat(job.output).st_mtime_ns > os.stat(job.path).st_mtime_ns
    except OSError:
        return False


def _skipped_row(job, previous):
    """Status ``skipped``, statistics from the previous summary or else from the ``.npz``."""
    old = previous.get(job.path)
    row = _row(job, "skipped")
    if old is not None and old.get("status") in ("ok", "skipped") and old.get("faces"):
        for c in SUMMARY_COLUMNS[3:]:
            if c not in ("seconds", "cpu_seconds", "peak_memory", "error", "warnings") \
                    and old.get(c) not in (None, ""):
                row[c] = old[c]
    elif job.output.endswith(".npz"):    # finished by a worker after the interrupt reached us
        try:
            from .baselines import CurvatureEstimate
            with np.load(job.output) as z:
                est = CurvatureEstimate(str(z["per"]), z["k1"], z["k2"], z["H"], z["K"],
                                        None, None, np.zeros(0, np.int64))
                row.update(vertices=len(z["V"]), faces=len(z["F"]), **_percentile_stats(est))
        except (OSError, KeyError, ValueError):
            pass
    return row


def sweep_temporaries(outdir):
    """Remove ``*.igl-hhj-tmp.*`` files (left by killed workers) under ``outdir``."""
    n = 0
    for tmp in Path(outdir).rglob(f"*{TMP_MARK}.*"):
        try:
            tmp.unlink()
            n += 1
        except OSError:
            pass
    return n


# --------------------------------------------------------------------------- summary, progress
def _fmt(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if math.isnan(v) else repr(v)
    return str(v)


def write_summary(rows, outdir):
    """``OUTDIR/summary.csv`` (atomically) and ``summary.parquet`` if pyarrow is installed.

    Returns the list of files written.
    """
    outdir = Path(outdir)
    path = outdir / "summary.csv"
    tmp = outdir / f".summary.{os.getpid()}{TMP_MARK}.csv"
    with open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(SUMMARY_COLUMNS)
        for r in rows:
            w.writerow([_fmt(r.get(c)) for c in SUMMARY_COLUMNS])
    os.replace(tmp, path)
    written = [path]
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return written
    cols = {}
    for c in SUMMARY_COLUMNS:
        vals = [r.get(c) for r in rows]
        vals = [None if v in ("", None) else v for v in vals]
        if c in ("vertices", "faces", "peak_memory", "nan_values"):
            cols[c] = pa.array([None if v is None else int(v) for v in vals], pa.int64())
        elif c in ("path", "output", "status", "error", "warnings"):
            cols[c] = pa.array([None if v is None else str(v) for v in vals], pa.string())
        else:
            cols[c] = pa.array([None if v is None else float(v) for v in vals], pa.float64())
    ptmp = outdir / f".summary.{os.getpid()}{TMP_MARK}.parquet"
    pq.write_table(pa.table(cols), ptmp)
    os.replace(ptmp, outdir / "summary.parquet")
    return written + [outdir / "summary.parquet"]


class _Progress:
    """tqdm bar (meshes done / failed, rate, ETA) on a terminal, one plain line per mesh otherwise."""

    def __init__(self, total, enabled=True, stream=None):
        self.stream = stream or sys.stderr
        self.total, self.done, self.failed = total, 0, 0
        self.bar = None
        self.enabled = enabled
        if enabled and getattr(self.stream, "isatty", lambda: False)():
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=total, unit="mesh", file=self.stream, dynamic_ncols=True)
            except ImportError:
                pass

    def update(self, row):
        self.done += 1
        self.failed += row["status"] in ("error", "timeout")
        if row.get("warnings") and row["status"] != "skipped":   # also with -q: warnings are news
            self._write(f"igl-hhj: warning: {row['path']}: {row['warnings']}")
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.set_postfix(failed=self.failed, refresh=False)
            self.bar.update(1)
            return
        faces = f"{row['faces']} faces" if row.get("faces") not in (None, "") else ""
        secs = f"{float(row['seconds']):.2f} s" if row.get("seconds") not in (None, "") else ""
        line = f"[{self.done}/{self.total}] {row['status']:<7} {row['path']}  {faces}  {secs}".rstrip()
        if row.get("error"):
            line += f"  ({row['error']})"
        print(line, file=self.stream, flush=True)

    def _write(self, line):
        if self.bar is not None:
            self.bar.write(line, file=self.stream)
        else:
            print(line, file=self.stream, flush=True)

    def close(self):
        if self.bar is not None:
            self.bar.close()


# --------------------------------------------------------------------------- execution
@dataclass
class BatchResult:
    """Outcome of :func:`run_batch`: one row per input (input order) and what was written."""

    rows: list
    outdir: Path
    summary_files: list = field(default_factory=list)
    seconds: float = 0.0
    mode: str = ""
    interrupted: bool = False
    total: int = 0
    recomputed: dict = field(default_factory=dict)
    """{description of the options an up-to-date output had: count} of the outputs
    recomputed because they were computed with other (or unknown) options."""

    def counts(self):
        c = {s: 0 for s in ("ok", "error", "skipped", "timeout")}
        for r in self.rows:
            c[r["status"]] = c.get(r["status"], 0) + 1
        return c


def _quiet_loggers(names):
    """Raise the named loggers above CRITICAL; returns {logger: previous level}."""
    import logging
    saved = {}
    for name in names:
        logger = logging.getLogger(name)
        saved[logger] = logger.level
        logger.setLevel(logging.CRITICAL + 1)
    return saved


def _in_process(groups, options, on_row):
    for group in groups:
        for job in group:                 # one by one: progress and Ctrl-C per mesh
            on_row(run_group([job], options)[0])


def _on_dask(client, groups, options, on_row, retry_singles=True):
    from distributed import as_completed
    futures = {}

    def submit(group, attempt):
        fut = client.submit(run_group, group, options, pure=False, retries=0,
                            key=f"igl-hhj-batch-{attempt}-{os.path.basename(group[0].path)}-"
                                f"{time.perf_counter_ns()}")
        futures[fut] = (group, attempt)
        return fut

    ac = as_completed([submit(g, 0) for g in groups])
    try:
        for fut in ac:
            group, attempt = futures.pop(fut)
            try:
                rows = fut.result()
            except Exception as exc:             # the task failed without producing rows
                if len(group) > 1 and retry_singles:
                    for job in group:              # isolate the mesh that kills its worker
                        ac.add(submit([job], attempt + 1))
                    continue
                what = ("the worker process computing it died every time it was tried (a crash "
                        "or out of memory; Dask's distributed.scheduler.allowed-failures retries)"
                        if type(exc).__name__ == "KilledWorker" else
                        f"{type(exc).__name__}: {' '.join(str(exc).split())}")
                rows = [_row(job, "error", error=f"{job.path}: {what}") for job in group]
            for row in rows:
                on_row(row)
    finally:
        if futures:
            client.cancel(list(futures))


def _local_cluster(n_workers, retries):
    """Embedded cluster of ``n_workers`` single-threaded worker processes on 127.0.0.1.

    The workers are started with SIGINT ignored (inherited through exec): Ctrl-C in a
    terminal signals the whole process group, and only this process should handle it
    (cancel, clean up, write the summary) instead of every worker printing a traceback.
    """
    import signal

    import dask
    from distributed import LocalCluster
    main = threading.current_thread() is threading.main_thread()
    old = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        return _start_local_cluster(LocalCluster, dask, n_workers, retries)
    finally:
        if main:
            signal.signal(signal.SIGINT, old)


def _start_local_cluster(LocalCluster, dask, n_workers, retries):
    # worker-saturation 1.0: a worker holds only the task it runs, so a worker that dies takes
    # no queued bystander task's retry budget with it.  MALLOC_TRIM_THRESHOLD_ unset: Dask's
    # default (65536) turns off glibc's dynamic mmap threshold, every large numpy temporary
    # then costs fresh pages, and the HHJ solves ran far slower in the workers than in a plain
    # loop (python -m igl_hhj.benchmarks.batch).  Dashboard / HTTP routes on a free loopback
    # port (the default :8787 warns when another cluster holds it).
    with dask.config.set({"distributed.scheduler.allowed-failures": retries,
                          "distributed.scheduler.worker-saturation": 1.0,
                          "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
        return LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                            dashboard_address="127.0.0.1:0", host="127.0.0.1", memory_limit=0,
                            silence_logs=50)


def _machine_cores():
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _import_distributed():
    try:
        import distributed  # noqa: F401
    except ImportError:
        from .errors import install_hint
        raise ImportError("igl-hhj batch needs dask.distributed for more than "
                          f"{IN_PROCESS_MAX_FILES} files or a --scheduler: "
                          f"{install_hint('distributed')} (or --workers 0: in-process)") from None


def run_batch(inputs, outdir, *, scheduler=None, workers=None, method="hhj", per="vertex",
              radius=None, fmt="npz", resume=True, timeout=None, memory_limit=None, retries=2,
              group_bytes=GROUP_BYTES, progress=True, stream=None, client=None, feature_angle=None):
    """Curvature of every mesh in ``inputs``; one output per mesh and a summary.

    Parameters
    ----------
    inputs : list of str or os.PathLike
        Files, folders (searched recursively for :data:`igl_hhj.mesh_io.MESH_EXTENSIONS`)
        or glob patterns (``**`` allowed).
    outdir : str or os.PathLike
        Created if needed; see :func:`plan_jobs` for the output names.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:port``).
    workers : int, optional
        Worker processes of the embedded cluster (default: the machine's cores, at most one
        per task); 0: run in this process.  Ignored with ``scheduler``.
    method, per, radius, feature_angle
        As ``igl-hhj curvature`` (:func:`compute_curvature`).
    fmt : {"npz", "ply", "vtp", "vtu"}
    resume : bool
        Skip inputs whose output is newer than the input (status ``skipped``).
    timeout : float, optional
        Seconds per mesh; longer → status ``timeout``.
    memory_limit : int, optional
        Resident bytes per mesh; more → ``error``.
    retries : int
        Embedded cluster: how often a task may lose its worker before it is given up
        (Dask's ``allowed-failures``).
    group_bytes : int
        Small inputs are grouped into one task up to this total file size (0: one mesh per task).
    progress : bool
        Progress bar (terminal) or one line per mesh (otherwise) on ``stream`` (stderr).
    client : distributed.Client, optional
        Use this client instead of creating one.

    Returns
    -------
    BatchResult
        ``interrupted`` is True after ``KeyboardInterrupt`` (the summary then lists the
        meshes finished so far; rerun to continue).
    """
    check_curvature_options(method, per, radius, feature_angle)
    if timeout is not None and not timeout > 0:
        raise ValueError(f"timeout must be positive, got {timeout}")
    if memory_limit is not None and not memory_limit > 0:
        raise ValueError(f"memory limit must be positive, got {memory_limit}")
    if workers is not None and workers < 0:
        raise ValueError(f"workers must be ≥ 0, got {workers}")
    if workers is not None and workers > MAX_WORKERS:
        raise ValueError(f"workers must be at most {MAX_WORKERS} (one process each), got {workers}")
    t0 = time.perf_counter()
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    jobs = plan_jobs(inputs, outdir, fmt)
    if not jobs:
        raise ValueError("no input meshes")
    options = Options(method, per, None if radius is None else int(radius), fmt, timeout, memory_limit,
                      None if feature_angle is None else float(feature_angle))
    previous = _previous_rows(outdir / "summary.csv")
    key = options_key(method, per, radius, feature_angle)
    made = _read_options_file(outdir)
    rel = {job.path: os.path.relpath(job.output, outdir) for job in jobs}
    rows = {}
    todo = []
    recomputed = {}
    for job in jobs:
        if resume and _up_to_date(job):
            was = _made_with(made.get(rel[job.path]), job.output)
            if was == key:
                rows[job.path] = _skipped_row(job, previous)
                continue
            what = describe_options(was)
            recomputed[what] = recomputed.get(what, 0) + 1
        todo.append(job)
    now = time.time_ns()
    for job in todo:
        made[rel[job.path]] = {"options": key, "done": False, "t": now}
    if todo:
        _write_options_file(outdir, made)
    bar = _Progress(len(jobs), progress, stream)
    for job in jobs:
        if job.path in rows:
            bar.update(rows[job.path])

    def on_row(row):
        rows[row["path"]] = row
        if row["status"] == "ok" and row["path"] in rel:
            made[rel[row["path"]]]["done"] = True
        bar.update(row)

    in_process = client is None and scheduler is None and (
        workers == 0 or (workers is None and len(todo) <= IN_PROCESS_MAX_FILES))
    groups = group_jobs(todo, group_bytes)
    mode = "in-process"
    interrupted = False
    cluster = own_client = None
    try:
        if todo and in_process:
            _in_process(groups, options, on_row)
        elif todo:
            _import_distributed()
            from distributed import Client
            if client is None:
                if scheduler is not None:
                    try:
                        # waits distributed.comm.timeouts.connect (default 30 s)
                        own_client = client = Client(scheduler)
                    except (OSError, TimeoutError, ValueError) as exc:
                        raise ValueError(f"cannot connect to the Dask scheduler at {scheduler}: "
                                         f"{' '.join(str(exc).split())[:200]}") from None
                    mode = f"scheduler {scheduler}"
                else:
                    n = workers or min(_machine_cores(), len(groups))
                    cluster = _local_cluster(n, retries)
                    own_client = client = Client(cluster)
                    mode = f"local cluster, {n} worker process{'es' if n > 1 else ''}"
            else:
                mode = "given client"
            _on_dask(client, groups, options, on_row)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        bar.close()
        # after Ctrl-C the comms die under Dask's background tasks, which log their
        # tracebacks (CommClosedError) while the client closes: not the user's news
        quiet = _quiet_loggers(("distributed", "tornado", "asyncio")) if interrupted else {}
        for obj in (own_client, cluster):
            if obj is not None:
                try:
                    obj.close()
                except Exception:         # already torn down by the interrupt
                    pass
        for logger, level in quiet.items():
            logger.setLevel(level)
        box = getattr(_local, "sandbox", None)
        if box is not None:
            box.close()
        sweep_temporaries(outdir)
        if todo:
            _write_options_file(outdir, made)
        done = [rows[j.path] for j in jobs if j.path in rows]
        files = write_summary(done, outdir)
    return BatchResult(done, outdir, files, time.perf_counter() - t0, mode, interrupted, len(jobs),
                       recomputed)
