"""The runtime of the compiled core (igl_hhj.runtime): bit-identical results across runs,
thread counts and concurrent callers, the missing-extension error, the large-call heap,
and its switches, also reachable under their old names in igl_hhj.kernels."""
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import igl_hhj
from igl_hhj import kernels, runtime
from igl_hhj.curvature import _shape_operator
from igl_hhj.mesh import TriangleMesh
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially
from kernel_cases import bumpy


def test_bit_identical_across_runs_threads_and_concurrent_callers():
    V, F = bumpy(5)            # 30k edges: above the kernels' single-thread threshold
    m = TriangleMesh(V, F)
    nt = kernels.max_threads()
    adapt, kernels.ADAPT_TO_LOAD = kernels.ADAPT_TO_LOAD, False
    try:
        kernels.set_num_threads(1)
        one = _shape_operator(m, None, None, None, "cg", 1e-10)
        kernels.set_num_threads(max(2, nt))
        two = _shape_operator(m, None, None, None, "cg", 1e-10)
        again = _shape_operator(m, None, None, None, "cg", 1e-10)
    finally:
        kernels.set_num_threads(nt)
        kernels.ADAPT_TO_LOAD = adapt
    assert np.array_equal(one, two) and np.array_equal(two, again)
    out = [None] * 3

    def work(i):
        out[i] = igl_hhj.principal_curvature(V, F, solver="cg")

    threads = [threading.Thread(target=work, args=(i,)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    ref = igl_hhj.principal_curvature(V, F, solver="cg")
    for o in out:
        for a, b in zip(o[:4], ref[:4]):
            assert np.array_equal(a, b)


def test_missing_extension_is_an_import_error_naming_the_fix():
    code = ("import sys; sys.modules['igl_hhj._hhj_core'] = None\n"
            "try:\n    from igl_hhj import kernels\nexcept ImportError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "compiled core" in out.stdout and "C++17 compiler" in out.stdout


def test_large_call_heap_engages_only_above_glibc_ceiling(monkeypatch):
    monkeypatch.delenv("MALLOC_MMAP_THRESHOLD_", raising=False)
    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)
    monkeypatch.delenv("GLIBC_TUNABLES", raising=False)
    with runtime.large_call_heap(100_000) as active:      # (#E, 3) arrays of 3.6 MB
        assert active is False
        assert runtime.core.heap_scope_depth() == 0
    on_glibc = sys.platform.startswith("linux")
    with runtime.large_call_heap(1_000_000) as active:    # 36 MB > 32 MiB
        assert runtime.core.heap_scope_depth() == 1
        assert active is on_glibc
        with runtime.large_call_heap(2_000_000):           # nests
            assert runtime.core.heap_scope_depth() == 2
        assert runtime.core.heap_scope_depth() == 1
    assert runtime.core.heap_scope_depth() == 0
    monkeypatch.setattr(kernels, "LARGE_CALL_HEAP", False)
    with runtime.large_call_heap(10_000_000) as active:
        assert active is False and runtime.core.heap_scope_depth() == 0


def test_large_call_heap_leaves_a_user_malloc_policy_alone(monkeypatch):
    for var, value in (("MALLOC_MMAP_THRESHOLD_", "1000000"),
                       ("GLIBC_TUNABLES", "glibc.malloc.trim_threshold=1000000")):
        with monkeypatch.context() as mp:
            mp.setenv(var, value)
            with runtime.large_call_heap(10_000_000) as active:
                assert active is False and runtime.core.heap_scope_depth() == 0


def test_large_call_heap_closes_on_errors_and_across_threads(monkeypatch):
    monkeypatch.setattr(runtime, "_GLIBC_MMAP_CEILING", 0)   # engage on small meshes
    V, F = icosphere(2)
    with pytest.raises(ValueError):
        igl_hhj.principal_curvature(V, F[:, :2])
    assert runtime.core.heap_scope_depth() == 0
    errors = []

    def work():
        try:
            for _ in range(3):
                igl_hhj.principal_curvature(V, F)
        except Exception as exc:   # pragma: no cover - reported below
            errors.append(exc)
    threads = [threading.Thread(target=work) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert runtime.core.heap_scope_depth() == 0


def test_large_call_heap_does_not_change_results(monkeypatch):
    V, F = icosphere(3)
    V = jitter_tangentially(V, F, Sphere(), 0.3, seed=3)
    monkeypatch.setattr(kernels, "LARGE_CALL_HEAP", False)
    ref = igl_hhj.principal_curvature(V, F)
    S_ref = igl_hhj.shape_operator(V, F)
    monkeypatch.setattr(kernels, "LARGE_CALL_HEAP", True)
    monkeypatch.setattr(runtime, "_GLIBC_MMAP_CEILING", 0)
    out = igl_hhj.principal_curvature(V, F)
    for a, b in zip(ref[:4], out[:4]):
        np.testing.assert_array_equal(a, b)
    assert ref[4] == out[4]
    np.testing.assert_array_equal(S_ref, igl_hhj.shape_operator(V, F))


def test_omp_wait_policy_is_set_before_the_core_loads():
    assert os.environ["OMP_WAIT_POLICY"]          # set by the runtime unless the user had one


def test_switches_set_through_kernels_are_the_runtime_s(monkeypatch):
    for name, value in (("ADAPT_TO_LOAD", False), ("LARGE_CALL_HEAP", False), ("TASKS_MIN_WORK", 7)):
        old = getattr(runtime, name)
        monkeypatch.setattr(kernels, name, value)
        assert getattr(runtime, name) == value and getattr(kernels, name) == value
        monkeypatch.undo()
        assert getattr(runtime, name) == old and getattr(kernels, name) == old
    assert kernels.run_tasks is runtime.run_tasks and kernels.set_num_threads is runtime.set_num_threads
    assert kernels._core is runtime.core


def test_large_call_heap_switch_is_read_at_call_time(monkeypatch):
    monkeypatch.setattr(kernels, "LARGE_CALL_HEAP", False)
    with runtime.large_call_heap(10_000_000) as active:
        assert active is False
