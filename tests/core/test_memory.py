"""Memory of the default drop-in (issue 25 item 5): a deterministic proxy of the peak.

The peak of ``principal_curvature(V, F)`` is the HHJ solve: the mesh's cached arrays and
the assembled system are alive while the compiled PCG holds its work vectors.  The proxy
is the bytes of the distinct arrays alive at the solve (arrays sharing memory with the
input do not count: the drop-in's mesh views ``V`` and ``F``) plus the PCG's work set,
per face; the resident peak measured by ``python -m igl_hhj.benchmarks.speed`` tracks it
(0.425 KB/face on the jittered icosphere(7), 327,680 faces; 0.511 with int64 topology maps).
"""
from functools import cached_property

import numpy as np
import pytest
import scipy.sparse as sp

import igl_hhj
from igl_hhj import kernels, solvers
from igl_hhj.mesh import TriangleMesh, as_mesh
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially

# KB/face above the input at the solve on this mesh: 0.412; 0.418 with the int64 ELL row
# pointer (6 B/face), 0.504 with int64 topology maps too (int32 edges / face_edges /
# edge_faces, int8 local indices, signs and counts: 88.5 B/face less), 0.562 before the
# views of V, F (36 B/face), the int32 Morton permutations (12 B/face) and the release of
# the face cross products (24 B/face).  The target, a resident peak of 0.45
# KB/face, is reached on icosphere(7) and its jittered version (docs/speed.md).
SOLVE_BUDGET_KB_PER_FACE = 0.42
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


def _wide_topology(self):
    """The topology maps as they were before issue 25 item 5: int64, float64 signs."""
    maps = kernels.topology(self.F, self.n_vertices)
    return tuple(a.astype(np.float64 if k == 5 else np.int64) for k, a in enumerate(maps))


def test_memory_budget_fails_with_int64_topology_maps(monkeypatch):
    # the budget can fail: with the maps widened back to int64 (float64 signs) the
    # proxy grows by their 88.5 B/face and exceeds it
    V, F = _ellipsoid(6)
    narrow = _solve_kb_per_face(monkeypatch, V, F)
    wide = cached_property(_wide_topology)
    wide.__set_name__(TriangleMesh, "_topology")
    monkeypatch.setattr(TriangleMesh, "_topology", wide)
    widened = _solve_kb_per_face(monkeypatch, V, F)
    nE = 3 * len(F) // 2                       # closed mesh
    assert (widened - narrow) * 1024 * len(F) == pytest.approx(
        len(F) * 3 * (8 - 4) + len(F) * 3 * (8 - 1) + nE * 2 * (8 - 4) * 2 + nE * 2 * (8 - 1) + nE * (8 - 1))
    assert widened > SOLVE_BUDGET_KB_PER_FACE >= narrow


def test_topology_maps_are_narrow_and_reach_the_kernels_uncopied():
    m = TriangleMesh(*_ellipsoid(2))
    assert m.edges.dtype == m.face_edges.dtype == m.edge_faces.dtype == np.int32
    assert m.edge_local_index.dtype == m.face_edge_sign.dtype == m.edge_face_count.dtype == np.int8
    # the wrappers' coercions are no-ops on the stored maps (no per-call int64 copies)
    for a in (m.edges, m.face_edges, m.edge_faces):
        assert kernels._i32(a) is a
    for a in (m.edge_local_index,):
        assert kernels._i8(a) is a


def test_memory_proxy_counts_a_copy_of_the_input(monkeypatch):
    # the proxy can fail: with V and F copied (as a public TriangleMesh does) it grows by
    # their 36 B/face
    V, F = _ellipsoid(4)
    views = _solve_kb_per_face(monkeypatch, V, F)
    monkeypatch.setattr("igl_hhj.pipeline.as_mesh", lambda V, F, copy=True: as_mesh(V, F))
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
