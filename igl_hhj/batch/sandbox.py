"""The sandbox: a child process that computes one mesh at a time and is killed on
timeout or memory, and :func:`run_group`, the task Dask runs."""
from __future__ import annotations

import os
import sys
import threading
import time

from .jobs import _proc_status_bytes, _row, process_mesh


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
        code = f"from igl_hhj.batch.sandbox import _sandbox_main; _sandbox_main({r_job}, {w_row})"
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
    from .. import baselines, curvature, mesh, mesh_io  # noqa: F401
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
