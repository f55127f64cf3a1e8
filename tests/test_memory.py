"""Memory of the default drop-in (issue 25 item 5): a deterministic proxy of the peak.

The peak of ``principal_curvature(V, F)`` is the HHJ solve: the mesh's cached arrays and
the assembled system are alive while the compiled PCG holds its work vectors.  The proxy
is the bytes of the distinct arrays alive at the solve (arrays sharing memory with the
input do not count: the drop-in's mesh views ``V`` and ``F``) plus the PCG's work set,
per face; the resident peak measured by ``python -m igl_hhj.benchmarks.speed`` tracks it
(0.52 KB/face on the 328k jittered ellipsoid).
"""
import numpy as np
import pytest
import scipy.sparse as sp

import igl_hhj
from igl_hhj import solvers
from igl_hhj.mesh import as_mesh
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially

# KB/face above the input at the solve on this mesh: 0.504; 0.562 before the views of V, F
# (36 B/face), the int32 Morton permutations (12 B/face) and the release of the face cross
# products (24 B/face).  The target is 0.45 (not reached).
SOLVE_BUDGET_KB_PER_FACE = 0.51
# compiled block PCG on k right-hand sides (pcg.cpp): R (the caller's rhs, overwritten),
# X, z, p, q, each (#E, k) float64
PCG_WORK_ARRAYS = 5


def _arrays(obj):
    if isinstance(obj, np.ndarray):
        return [obj]
    if sp.issparse(obj):
        return [getattr(obj, a) for a in ("data", "indices", "indptr") if hasattr(obj, a)]
    if isinstance(obj, (tuple, list)):
        return [a for o in obj for a in _arrays(o)]
    if isinstance(obj, dict):
        return [a for o in obj.values() for a in _arrays(o)]
    return []


def _distinct_bytes(arrays, exclude):
    """Bytes of the arrays, each memory block once, leaving out those sharing ``exclude``'s."""
    kept = []
    for a in sorted(arrays, key=lambda a: -a.nbytes):
        if not any(np.shares_memory(a, b) for b in kept + exclude):
            kept.append(a)
    return sum(a.nbytes for a in kept)


def _ellipsoid(level):
    V, F = icosphere(level)
    return jitter_tangentially(V, F, Sphere(), 0.3, seed=1) * np.array([1, 0.8, 0.6]), F


def _solve_kb_per_face(monkeypatch, V, F):
    seen = []
    orig = solvers.HHJSystem.solve

    def spy(self, rhs, *args, **kwargs):
        live = _arrays(self.mesh.__dict__) + _arrays(self.__dict__) + [rhs]
        seen.append(_distinct_bytes(live, [V, F])
                    + (PCG_WORK_ARRAYS - 1) * rhs.shape[0] * rhs.shape[1] * 8)   # rhs counted above
        return orig(self, rhs, *args, **kwargs)

    monkeypatch.setattr(solvers.HHJSystem, "solve", spy)
    igl_hhj.principal_curvature(V, F)
    assert len(seen) == 1                      # one HHJ solve in the default drop-in
    return seen[0] / 1024 / len(F)


def test_dropin_memory_at_the_solve_within_budget(monkeypatch):
    V, F = _ellipsoid(6)                       # 81,920 faces
    kb = _solve_kb_per_face(monkeypatch, V, F)
    assert kb <= SOLVE_BUDGET_KB_PER_FACE, f"{kb:.3f} KB/face alive at the solve"


def test_memory_proxy_counts_a_copy_of_the_input(monkeypatch):
    # the proxy can fail: with V and F copied (as a public TriangleMesh does) it grows by
    # their 36 B/face
    V, F = _ellipsoid(4)
    views = _solve_kb_per_face(monkeypatch, V, F)
    monkeypatch.setattr("igl_hhj.curvature.as_mesh", lambda V, F, copy=True: as_mesh(V, F))
    copies = _solve_kb_per_face(monkeypatch, V, F)
    assert copies - views == pytest.approx((V.nbytes + F.nbytes) / 1024 / len(F))


def test_as_mesh_copy_false_views_the_input():
    V, F = icosphere(2)
    m = as_mesh(V, F, copy=False)
    assert np.shares_memory(m.V, V) and np.shares_memory(m.F, F)
    assert not m.V.flags.writeable and not m.F.flags.writeable
    assert V.flags.writeable                   # the caller's arrays keep their flags
    c = as_mesh(V, F)
    assert not np.shares_memory(c.V, V) and not np.shares_memory(c.F, F)
    # a conversion (int32 faces) is a new array either way
    m32 = as_mesh(V, F.astype(np.int32), copy=False)
    assert m32.F.dtype == np.int64 and np.array_equal(m32.F, F)


def test_dropin_with_views_matches_copied_mesh():
    V, F = _ellipsoid(3)
    a = igl_hhj.principal_curvature(V, F)
    b = igl_hhj.principal_curvature(as_mesh(V, F))   # a TriangleMesh (its own copies) passes through
    for x, y in zip(a[:4], b[:4]):
        assert np.array_equal(x, y, equal_nan=True)
