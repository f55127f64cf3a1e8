"""Mesh layer: validation (one test per rejected input class) and derived quantities."""
import igl
import numpy as np
import pytest

from igl_hhj.mesh import TriangleMesh, validate_mesh
from igl_hhj.surfaces import icosphere

V1 = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
F1 = np.array([[0, 1, 2], [1, 3, 2]])


def test_accepts_int32_float32_and_lists():
    m = TriangleMesh(V1.astype(np.float32), F1.astype(np.int32))
    assert m.V.dtype == np.float64 and m.F.dtype == np.int64
    assert m.V.flags.c_contiguous and m.F.flags.c_contiguous
    m2 = TriangleMesh(V1.tolist(), F1.tolist())
    np.testing.assert_array_equal(m2.F, F1)


def test_never_reorders_F():
    F = np.array([[2, 0, 1], [1, 3, 2]])
    V, F2 = validate_mesh(V1, F)
    np.testing.assert_array_equal(F2, F)


@pytest.mark.parametrize("V,F,exc,match", [
    (V1[:, :2], F1, ValueError, r"V must have shape \(#V, 3\)"),
    (V1, F1[:, :2], ValueError, r"F must have shape \(#F, 3\)"),
    (np.zeros((0, 3)), F1, ValueError, "V is empty"),
    (V1, np.zeros((0, 3), dtype=int), ValueError, "F is empty"),
    (np.where(np.arange(12).reshape(4, 3) == 7, np.nan, V1), F1, ValueError, "NaN or inf.*vertex 2"),
    (np.where(np.arange(12).reshape(4, 3) == 3, np.inf, V1), F1, ValueError, "NaN or inf.*vertex 1"),
    (V1, np.array([[0, 1, 2], [1, -3, 2]]), ValueError, "negative vertex indices.*face 1"),
    (V1, np.array([[0, 1, 2], [1, 4, 2]]), ValueError, "out-of-range.*face 1"),
    (V1, np.array([[0, 1, 2], [1, 1, 2]]), ValueError, "repeated vertex.*face 1"),
    (V1, F1.astype(float), TypeError, "integer vertex indices"),
    (np.array([["a", "b", "c"]] * 4), F1, TypeError, "real numbers"),
    (V1.astype(complex), F1, TypeError, "real numbers"),
])
def test_rejects_bad_input(V, F, exc, match):
    with pytest.raises(exc, match=match):
        TriangleMesh(V, F)


def test_rejects_zero_area_face():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]])
    with pytest.raises(ValueError, match=r"degenerate \(zero-area\) faces; first at face 1"):
        TriangleMesh(V, [[0, 1, 3], [0, 1, 2]])


def test_rejects_non_manifold_edge():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]])
    F = [[0, 1, 2], [1, 0, 3], [0, 1, 4]]
    with pytest.raises(ValueError, match="non-manifold edges.*vertices \\[0, 1\\] with 3 faces"):
        TriangleMesh(V, F)


def test_rejects_inconsistent_orientation():
    with pytest.raises(ValueError, match="not consistently oriented: faces \\[0, 1\\]"):
        TriangleMesh(V1, [[0, 1, 2], [1, 2, 3]])


def test_unreferenced_vertices_allowed():
    V = np.vstack([V1, [[5.0, 5, 5]]])
    m = TriangleMesh(V, F1)
    assert not m.referenced_vertices[4] and m.referenced_vertices[:4].all()
    assert np.isnan(m.vertex_normals[4]).all()


def test_edge_maps_follow_libigl_corner_convention():
    V, F = icosphere(1)
    m = TriangleMesh(V, F)
    E, uE, EMAP, *_ = igl.unique_edge_map(F)
    for c in range(3):  # edge opposite corner c joins the other two corners
        e = m.face_edges[:, c]
        a, b = F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        assert np.all(np.sort(m.edges[e], axis=1) == np.sort(np.stack([a, b], 1), axis=1))
    # every interior edge has two faces, seen with opposite signs
    assert (m.edge_face_count == 2).all()
    s = m.face_edge_sign
    f0, f1 = m.edge_faces[:, 0], m.edge_faces[:, 1]
    i0, i1 = m.edge_local_index[:, 0], m.edge_local_index[:, 1]
    assert np.all(s[f0, i0] == 1) and np.all(s[f1, i1] == -1)
    assert m.n_edges == uE.shape[0]


def test_conormals_outward_unit_tangent():
    V, F = icosphere(1)
    m = TriangleMesh(V, F)
    n = m.conormals
    np.testing.assert_allclose(np.linalg.norm(n, axis=2), 1.0)
    np.testing.assert_allclose(np.einsum("fia,fa->fi", n, m.face_normals), 0.0, atol=1e-14)
    np.testing.assert_allclose(np.einsum("fia,fia->fi", n, m.edge_tangents), 0.0, atol=1e-14)
    # outward: points away from the opposite corner
    X = V[F]
    mid = 0.5 * (X[:, [1, 2, 0]] + X[:, [2, 0, 1]])
    assert np.all(np.einsum("fia,fia->fi", n, mid - X) > 0)


def test_barycentric_gradients_reproduce_linear_functions():
    rng = np.random.default_rng(0)
    V, F = icosphere(1)
    V = V + 0.05 * rng.normal(size=V.shape)
    m = TriangleMesh(V, F)
    G = m.barycentric_gradients
    np.testing.assert_allclose(G.sum(axis=1), 0.0, atol=1e-12)
    a = rng.normal(size=3)
    w = V @ a                                  # linear function
    grad = np.einsum("fi,fia->fa", w[F], G)    # P1 gradient on each face
    P = np.eye(3) - m.face_normals[:, :, None] * m.face_normals[:, None, :]
    np.testing.assert_allclose(grad, P @ a, atol=1e-12)
    np.testing.assert_allclose(m.face_areas, 0.5 * igl.doublearea(V, F))


def test_boundary_edges_and_loops():
    V, F = icosphere(2)
    keep = V[F].mean(axis=1)[:, 2] < 0.3
    F = F[keep]
    m = TriangleMesh(V, F)
    L = igl.boundary_loop(F)
    assert set(np.flatnonzero(m.boundary_vertices)) == set(L.tolist())
    assert len(m.boundary_loops) == 1 and len(m.boundary_loops[0]) == len(L)
    assert m.boundary_edges.sum() == len(L)


def test_sum_corners_to_vertices():
    V, F = icosphere(1)
    m = TriangleMesh(np.vstack([V, [[3.0, 3, 3]]]), F)       # one unreferenced vertex
    third = np.broadcast_to(m.face_areas[:, None] / 3, (m.n_faces, 3))
    w = m.sum_corners_to_vertices(third)
    assert w.shape == (m.n_vertices,) and w[-1] == 0.0
    np.testing.assert_allclose(w.sum(), m.face_areas.sum())
    vec = m.sum_corners_to_vertices(np.ones((m.n_faces, 3, 2, 2)))
    np.testing.assert_array_equal(vec[:-1, 0, 1], np.bincount(F.ravel()))


def test_the_list_of_cached_quantities_is_complete():
    """TriangleMesh.CACHED (documented in its Notes) names every cached property."""
    from functools import cached_property
    cached = {k for k, v in vars(TriangleMesh).items() if isinstance(v, cached_property)}
    assert set(TriangleMesh.CACHED) == cached and len(TriangleMesh.CACHED) == len(cached)
    assert all(f"``{k}``" in TriangleMesh.__doc__ for k in cached)
