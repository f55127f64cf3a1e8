"""Meshes and helpers shared by the tests of the compiled kernels against their numpy
references (tests/mesh, tests/hhj, tests/vertex_stage, tests/core)."""
import numpy as np
import pytest
from conftest import sequence

from igl_hhj import kernels
from igl_hhj.mesh import TriangleMesh
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially

RTOL = 1e-9


def rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(b).max()


def bumpy(level=3, seed=3):
    V, F = icosphere(level)
    V = jitter_tangentially(V, F, Sphere(), 0.3, seed=seed)
    return V * np.array([1.0, 0.7, 1.3]), F


def sliver_mesh(height=5e-3):
    """A bent jittered sphere with needle triangles: one vertex of several faces pulled
    towards the opposite edge's midpoint, leaving ``height`` of its distance.
    5e-3: minimum angle ~0.6° (camelhead's is 0.55°).  Any two implementations differ
    by about cond(A)·eps·10 (measured: 4e-12 at 1.1°, cond 1e5; 2e-9 at 0.12°, cond 1e8),
    so the ≤1e-9 comparison is made at real meshes' sliver level; 1e-9 (relative area
    ~1e-9, near the validation limit) is used to check that nothing raises."""
    V, F = bumpy(3, seed=5)
    V = V.copy()
    for f in (10, 200, 777):
        a, b, c = F[f]
        V[c] = 0.5 * (V[a] + V[b]) + height * (V[c] - 0.5 * (V[a] + V[b]))
    return V, F


@pytest.fixture(scope="module")
def closed():
    return TriangleMesh(*bumpy())


@pytest.fixture(scope="module")
def saddle():
    surface, seq = sequence("saddle", 3)
    V, F = seq[-1]
    return surface, TriangleMesh(V, F)


def kernel_meshes():
    V, F = bumpy()
    keep = V[F].mean(axis=1)[:, 2] < 0.5
    Fo = F[keep]
    perm = np.random.default_rng(0).permutation(len(F))
    return {"closed": (V, F), "open": (V, Fo), "permuted": (V, F[perm]), "sliver": sliver_mesh()}


def on_one_and_two_threads(fn):
    """[fn() on one thread, fn() on two] (the load adaptation off)."""
    nt = kernels.max_threads()
    adapt, kernels.ADAPT_TO_LOAD = kernels.ADAPT_TO_LOAD, False
    try:
        out = []
        for k in (1, max(2, nt)):
            kernels.set_num_threads(k)
            out.append(fn())
        return out
    finally:
        kernels.set_num_threads(nt)
        kernels.ADAPT_TO_LOAD = adapt
