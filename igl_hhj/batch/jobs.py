"""One mesh of a batch: the job, the options, and :func:`process_mesh`, which reads,
computes and writes it and turns every outcome into its summary row."""
from __future__ import annotations

import math
import os
import threading
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import MeshFileError
from ..results import QUANTITIES
from .compute import MeshRefusedError, compute_curvature, compute_curvature_repairing


PERCENTILES = (1, 50, 99)
SUMMARY_COLUMNS = (["path", "output", "status", "vertices", "faces", "seconds", "cpu_seconds",
                    "peak_memory", "error", "warnings", "polygons"]
                   + [f"{q}_p{p:02d}" for q in QUANTITIES for p in PERCENTILES] + ["nan_values"])
"""Columns of ``summary.csv``: ``seconds`` wall-clock and ``cpu_seconds`` CPU time (all
threads of the process computing the mesh) from reading to writing; ``peak_memory`` in
bytes (the process's peak resident set during the mesh, Linux only, empty when unknown
or when the worker runs several threads); ``warnings`` what the mesh's reading and
computation warned about (libigl's reader messages, :class:`igl_hhj.mesh.MeshWarning`,
numpy), one-line messages joined by `` | `` (empty: none), recorded where the mesh was
computed, so Dask workers' warnings are not lost; ``polygons`` the file's polygons split
into triangles ("12 quads split into 24 triangles ...", as ``igl-hhj curvature`` and ``info``
say it: a note, not a warning; empty: triangles only); ``k1_p01 ... K_p99`` the 1st/50th/99th
percentiles over the vertices or faces; ``nan_values`` the number of elements without a
value."""
TMP_MARK = ".igl-hhj-tmp"


def _atomic_write(path, fmt, V, F, est, method, S):
    """Write to ``.<name>.<pid>.<thread>.igl-hhj-tmp.<fmt>`` in the same folder, then rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.{threading.get_ident()}{TMP_MARK}.{fmt}")
    try:
        from ..mesh_io import write_curvature
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
    strict: bool = False

    @property
    def sandboxed(self):
        """Run each mesh in a sandbox child process (needed to enforce the limits)."""
        return self.timeout is not None or self.memory_limit is not None


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
    from ..mesh_io import read_mesh_file
    said = []
    try:
        mf = read_mesh_file(job.path)
        V, F, said = mf.V, mf.F, list(mf.messages)
        if mf.split.n_split:              # a note of its own, not a warning (as curvature / info)
            extra["polygons"] = mf.split.describe()
        extra.update(vertices=len(V), faces=len(F))
        try:          # what the drop-in repairs is repaired (one warning), unless strict
            est, S, _, _ = compute_curvature_repairing(V, F, strict=options.strict, method=options.method,
                                                       per=options.per, radius=options.radius,
                                                       keep_shape_operator=options.fmt == "npz",
                                                       feature_angle=options.feature_angle)
        except MeshRefusedError as exc:
            raise MeshFileError(f"{job.path}: igl_hhj cannot use this mesh: {exc}"
                                + (" (--strict)" if exc.defect else "")) from None
        _atomic_write(job.output, options.fmt, V, F, est, options.method, S)
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
