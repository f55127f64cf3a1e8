"""Running a batch: :func:`run_batch` in this process, on an embedded Dask cluster or on
an existing one."""
from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from .compute import check_curvature_options
from .jobs import Options, _row
from .plan import GROUP_BYTES, group_jobs, plan_jobs
from .resume import (_made_with, _previous_rows, _read_options_file, _skipped_row, _up_to_date,
                     _write_options_file, describe_options, options_key, sweep_temporaries)
from .sandbox import _local, run_group
from .summary import _Progress, write_summary


IN_PROCESS_MAX_FILES = 4
"""Without a scheduler, at most this many files run in-process (no cluster start-up)."""
MAX_WORKERS = 256
"""Largest ``workers`` of the embedded cluster (each is a process)."""


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


NO_WORKER_SECONDS = 120.0
"""How long the tasks may wait with no worker in the cluster before their meshes become error
rows.  A worker whose event loop stops answering (a parser stuck in C code holding the GIL) is
dropped by the scheduler after ``distributed.scheduler.worker-ttl`` (300 s); its nanny then shuts
down for good instead of restarting it (dask/distributed#8537), and with ``--workers 1`` nothing
is left to run the remaining tasks: ``as_completed`` waited forever (the hangs of 110 s and
300 s and more)."""
WATCH_SECONDS = 5.0
"""How often the client checks that the cluster still has workers while no task finishes."""


def _on_dask(client, groups, options, on_row, retry_singles=True):
    from distributed import wait
    futures = {}

    def submit(group, attempt):
        fut = client.submit(run_group, group, options, pure=False, retries=0,
                            key=f"igl-hhj-batch-{attempt}-{os.path.basename(group[0].path)}-"
                                f"{time.perf_counter_ns()}")
        futures[fut] = (group, attempt)
        return fut

    def finished(fut):
        group, attempt = futures.pop(fut)
        try:
            rows = fut.result()
        except Exception as exc:             # the task failed without producing rows
            if len(group) > 1 and retry_singles:
                for job in group:              # isolate the mesh that kills its worker
                    submit([job], attempt + 1)
                return
            what = ("the worker process computing it died every time it was tried (a crash "
                    "or out of memory; Dask's distributed.scheduler.allowed-failures retries)"
                    if type(exc).__name__ == "KilledWorker" else
                    f"{type(exc).__name__}: {' '.join(str(exc).split())}")
            rows = [_row(job, "error", error=f"{job.path}: {what}") for job in group]
        for row in rows:
            on_row(row)

    for g in groups:
        submit(g, 0)
    no_worker_since = None
    try:
        while futures:
            try:
                done, _ = wait(list(futures), timeout=WATCH_SECONDS, return_when="FIRST_COMPLETED")
            except TimeoutError:
                done = ()
            for fut in done:
                finished(fut)
            if done or client.scheduler_info().get("workers"):
                no_worker_since = None
                continue
            no_worker_since = no_worker_since or time.monotonic()
            if time.monotonic() - no_worker_since > NO_WORKER_SECONDS:
                client.cancel(list(futures))
                for group, _ in list(futures.values()):
                    for job in group:
                        on_row(_row(job, "error", error=f"{job.path}: no worker process left to compute "
                                                        f"it for {NO_WORKER_SECONDS:g} s (they died or "
                                                        f"stopped answering; rerun to retry)"))
                futures.clear()
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
        from ..errors import install_hint
        raise ImportError("igl-hhj batch needs dask.distributed for more than "
                          f"{IN_PROCESS_MAX_FILES} files or a --scheduler: "
                          f"{install_hint('distributed')} (or --workers 0: in-process)") from None


def _written_since(path, t_ns):
    """Whether ``path`` exists and was written after ``t_ns`` (``time.time_ns()``)."""
    try:
        return os.stat(path).st_mtime_ns > t_ns
    except OSError:
        return False


def run_batch(inputs, outdir, *, scheduler=None, workers=None, method="hhj", per="vertex",
              radius=None, fmt="npz", resume=True, timeout=None, memory_limit=None, retries=2,
              group_bytes=GROUP_BYTES, progress=True, stream=None, client=None, feature_angle=None,
              strict=False):
    """Curvature of every mesh in ``inputs``; one output per mesh and a summary.

    Parameters
    ----------
    inputs : list of str or os.PathLike
        Files, folders (searched recursively for :data:`igl_hhj.mesh_io.READ_EXTENSIONS`)
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
    strict : bool
        Refuse (an error row) a mesh that :func:`igl_hhj.principal_curvature` would repair;
        default: repair it the same way, the repair named in the row's warnings
        (:func:`igl_hhj.batch.compute.compute_curvature_repairing`).
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
                      None if feature_angle is None else float(feature_angle), bool(strict))
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
        if interrupted:          # outputs the workers finished after the interrupt reached us
            for job in todo:
                if job.path not in rows and _written_since(job.output, now):
                    row = _skipped_row(job, {})            # its statistics re-read from the .npz
                    row.update(status="ok", warnings="finished by a worker after Ctrl-C (no timings)")
                    rows[job.path] = row                   # into the summary (the bar is closed)
                    made[rel[job.path]]["done"] = True
        if todo:
            _write_options_file(outdir, made)
        done = [rows[j.path] for j in jobs if j.path in rows]
        files = write_summary(done, outdir)
    return BatchResult(done, outdir, files, time.perf_counter() - t0, mode, interrupted, len(jobs),
                       recomputed)
