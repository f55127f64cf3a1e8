"""The compiled core's runtime: loading it, its thread policy, the heap of a large call.

This is the only module that imports the extension ``igl_hhj._hhj_core`` (as
:data:`core`); :mod:`igl_hhj.kernels` wraps its functions.  Everything that decides how
many threads igl_hhj uses is here or described here:

1. **OpenMP's idle threads sleep** (``OMP_WAIT_POLICY=PASSIVE``), set when this module is
   imported, before the extension loads libgomp (which reads the variable then), unless
   the environment sets a policy already.  Measured on a shared 2-core machine at load 8:
   with the default spinning, two threads made the drop-in 1.8x slower than one; with
   passive waiting they were equal.
2. **Threads per kernel call** (:func:`apply_thread_policy`, before every call in
   :mod:`igl_hhj.kernels`): ``OMP_NUM_THREADS`` or :func:`set_num_threads`, and one thread
   while the machine is busy (1-minute load average ≥ the number of cores,
   :data:`ADAPT_TO_LOAD`): extra threads then only queue behind other processes.
3. **In the compiled core** (``ThreadBudget`` in ``_core/core.hpp``): a kernel started
   while another igl_hhj kernel runs (several Python threads, the GIL released) gets one
   thread, so N Python threads never start N × #cores OpenMP threads, and small problems
   run on one thread.
4. **Independent kernel calls at once** (:func:`run_tasks`: the sides of a mesh cut along
   its creases): up to :func:`task_workers` Python threads, each call single-threaded by 3.

Reductions use a fixed chunking, so results are bit-identical for any thread count (and
any of these policies).

The heap of a large call (:func:`large_call_heap`, :func:`with_large_call_heap`) is the
other process-wide setting of the core: see :data:`LARGE_CALL_HEAP`.

State: the thread count asked for (:func:`set_num_threads`), the last load-average
reading (kept :data:`LOAD_TTL` seconds) and, once :func:`run_tasks` first runs tasks, one
thread pool.
"""
from __future__ import annotations

import functools
import os
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, ParamSpec, TypeVar

import numpy as np

# 1. before the extension (and libgomp with it) is loaded
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

try:
    from . import _hhj_core
except ImportError as exc:  # pragma: no cover - exercised only on a broken install
    raise ImportError(
        "igl_hhj's compiled core (igl_hhj._hhj_core) is missing or failed to load "
        f"({exc}). It is built when igl_hhj is installed: reinstall on a machine with a "
        "C++17 compiler and cmake, e.g. `pip install --force-reinstall --no-cache-dir .` "
        "from the igl_hhj source tree (scikit-build-core and nanobind come from PyPI)."
    ) from exc
core: Any = _hhj_core      # the extension has no stubs: its functions are typed by igl_hhj.kernels

__all__ = [
    "core", "max_threads", "set_num_threads", "apply_thread_policy", "task_workers", "run_tasks",
    "ADAPT_TO_LOAD", "TASKS_MIN_WORK", "LOAD_TTL",
    "large_call_heap", "with_large_call_heap", "LARGE_CALL_HEAP",
]

# --------------------------------------------------------------------------- 2. threads per call
_USER_THREADS = core.max_threads()     # OMP_NUM_THREADS or the core count; set_num_threads
ADAPT_TO_LOAD = True
"""Run single-threaded while the machine is busy (1-minute load average ≥ the number of
cores).  Results do not depend on the thread count (fixed-chunk reductions)."""

_CPU_COUNT = os.cpu_count() or 1
LOAD_TTL = 0.25
"""The load average changes on a scale of seconds: it is read at most this often (a
drop-in call on a tiny mesh makes ~10 kernel calls; reading it each time cost 8 % of a
12-face call)."""
_load_cache = [-1.0, False]          # [monotonic time of the last reading, busy]


def max_threads():
    """Number of OpenMP threads a kernel may use (1 without OpenMP)."""
    return core.max_threads()


def set_num_threads(n):
    """Set the OpenMP thread count of igl_hhj's kernels (``omp_set_num_threads``)."""
    global _USER_THREADS
    _USER_THREADS = max(1, int(n))
    core.set_num_threads(_USER_THREADS)


def _machine_busy():
    now = time.monotonic()
    if now - _load_cache[0] > LOAD_TTL:
        try:
            busy = os.getloadavg()[0] >= _CPU_COUNT
        except OSError:  # pragma: no cover - no load average on this platform
            busy = False
        _load_cache[0], _load_cache[1] = now, busy
    return _load_cache[1]


def task_workers() -> int:
    """The thread policy: the threads of the next kernel call (:func:`apply_thread_policy`)
    and how many independent kernel calls may run at once (:func:`run_tasks`):
    ``OMP_NUM_THREADS`` or :func:`set_num_threads`, one while the machine is busy."""
    n = _USER_THREADS
    if ADAPT_TO_LOAD and n > 1 and _machine_busy():
        n = 1
    return n


def apply_thread_policy():
    """Apply the thread policy for the next kernel call (calling thread only)."""
    core.set_num_threads(task_workers())


# --------------------------------------------------------------------------- 4. calls at once
_TASK_POOL: list[Any] = []
TASKS_MIN_WORK = 4000
"""A task pool pays only from this much work in all (vertices): below it the calls take
less than the threads' hand-over costs (~50 µs a task)."""

_R = TypeVar("_R")
_P = ParamSpec("_P")


def run_tasks(fn: Callable[[Any], _R], items, sizes) -> list[_R]:
    """``[fn(x) for x in items]``, concurrently on up to :func:`task_workers` threads.

    ``fn`` must release the GIL for its work (the compiled kernels do) and its calls must
    not depend on each other's results.  ``sizes`` (one number per item, its work) orders
    the start: largest first, so the longest call does not start last (LPT scheduling).
    Each kernel call inside runs single-threaded, and a kernel's bits do not depend on its
    thread count, so the results are those of the serial loop, bit for bit.  Serial when
    one worker is allowed, for one item, or below :data:`TASKS_MIN_WORK` in all.  An
    exception is raised as from the serial loop (the first item's that raised, in order).
    """
    items = list(items)
    workers = min(task_workers(), len(items))
    if workers <= 1 or float(np.sum(sizes)) < TASKS_MIN_WORK:
        return [fn(x) for x in items]
    if not _TASK_POOL:
        from concurrent.futures import ThreadPoolExecutor   # lazily: most calls never need it
        _TASK_POOL.append(ThreadPoolExecutor(max_workers=max(1, _CPU_COUNT - 1), thread_name_prefix="igl_hhj"))
    pool = _TASK_POOL[0]
    order = np.argsort(-np.asarray(sizes, dtype=np.float64), kind="stable")
    # `workers` chains of calls: no more kernels at once than the policy allows
    queue = list(order[::-1])
    lock = threading.Lock()
    out: list[Any] = [None] * len(items)

    def chain():
        while True:
            with lock:
                if not queue:
                    return
                i = int(queue.pop())
            try:
                out[i] = (True, fn(items[i]))
            except BaseException as exc:  # re-raised below, in item order
                out[i] = (False, exc)

    futures = [pool.submit(chain) for _ in range(workers - 1)]
    chain()                                       # the caller runs one chain itself
    for future in futures:
        future.result()
    for ok, value in out:
        if not ok:
            raise value
    return [value for _, value in out]


# --------------------------------------------------------------------------- the heap of a large call
LARGE_CALL_HEAP = True
"""Heap policy of a large call (glibc; see ``igl_hhj/_core/heap.cpp``).  glibc raises its
mmap threshold by itself only up to 32 MiB, so above about 930k faces each (#E, 3) float64
work array is a fresh mapping whose pages all fault on first touch (icosphere(8): 400k
minor faults per drop-in call).  Inside :func:`large_call_heap` the call's arrays come
from the heap and are reused between stages; on exit glibc's 32 MiB ceiling is restored
and the freed heap is returned (malloc_trim), so no memory is kept between calls.
Measured on icosphere(8): 400k -> 181k faults, drop-in 2.58 -> 2.27 s; no effect below
32 MiB.  False: never touch the allocator.  A policy set through
``MALLOC_MMAP_THRESHOLD_``, ``MALLOC_TRIM_THRESHOLD_`` or
``GLIBC_TUNABLES=glibc.malloc.*`` is always left alone."""
_GLIBC_MMAP_CEILING = 32 << 20
# the scope's threshold, in units of the call's (#E, 3) float64 array: its edge and vertex
# work arrays come from the heap, the few larger ones ((#E, 5) matrix rows) stay mappings.
# Measured on icosphere(8) (threshold 1.5x: 71 MB): 2.13 s, peak 0.57 KB/face, as without
# the scope; 128 MB and above: 2.03 s but 0.60 KB/face (freed large blocks linger in the
# heap); 32 MB: 2.45 s
_HEAP_SCOPE_FACTOR = 1.5


def _user_malloc_policy():
    env = os.environ
    return ("MALLOC_MMAP_THRESHOLD_" in env or "MALLOC_TRIM_THRESHOLD_" in env
            or "glibc.malloc." in env.get("GLIBC_TUNABLES", ""))


@contextmanager
def large_call_heap(n_faces: float) -> Iterator[bool]:
    """Open the large-call heap scope for a call on a mesh of ``n_faces`` faces.

    Yields True when the scope is active: the mesh's (#E, 3) float64 work arrays
    (#E ≈ 1.5 #F) exceed glibc's 32 MiB dynamic mmap ceiling, :data:`LARGE_CALL_HEAP`
    is on and no user malloc policy is set in the environment.  Nests, thread-safe."""
    big = 1.5 * float(n_faces) * 3 * 8
    if not LARGE_CALL_HEAP or big <= _GLIBC_MMAP_CEILING or _user_malloc_policy():
        yield False
        return
    active = core.heap_scope_enter(int(_HEAP_SCOPE_FACTOR * big))
    try:
        yield active
    finally:
        core.heap_scope_exit()


def _n_faces_hint(V, F):
    """Number of faces of the call ``f(V, F, ...)`` without validating (0 if unknown)."""
    if F is None:
        return int(getattr(V, "n_faces", 0) or 0)
    shape = getattr(F, "shape", None)
    try:
        return int(shape[0]) if shape else len(F)
    except (TypeError, IndexError, ValueError):
        return 0


def with_large_call_heap(fn: Callable[_P, _R]) -> Callable[_P, _R]:
    """Decorator for public functions called as ``fn(V, F, ...)``: runs them inside
    :func:`large_call_heap`.

    The signature is kept for static checkers (``Callable[P, R] -> Callable[P, R]``:
    mypy and IDEs see the decorated function's own parameters and return type) and at
    run time (``functools.wraps``; ``inspect`` follows ``__wrapped__``)."""
    @functools.wraps(fn)
    def wrapper(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        V = args[0] if args else kwargs.get("V")
        F = args[1] if len(args) > 1 else kwargs.get("F")
        with large_call_heap(_n_faces_hint(V, F)):
            return fn(*args, **kwargs)
    return wrapper
