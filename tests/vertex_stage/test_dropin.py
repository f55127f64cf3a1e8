"""`igl_hhj.principal_curvature` is a drop-in for `igl.principal_curvature` (libigl 2.6)."""
import importlib.metadata

import igl
import numpy as np
import pytest
from conftest import sequence

import igl_hhj
from igl_hhj.convergence import vertex_errors

CALL_FORMS = [
    ((), {}),
    ((5,), {}),
    ((3, True), {}),
    ((), {"radius": 4}),
    ((), {"useKring": False}),
    ((), {"radius": 6, "useKring": True}),
    ((2,), {"useKring": False}),
]


@pytest.fixture(scope="module")
def ellipsoid_mesh():
    surface, seq = sequence("ellipsoid", 4)
    return surface, seq[-1]


def test_installed_libigl_is_supported_series():
    major, minor = (int(x) for x in importlib.metadata.version("libigl").split(".")[:2])
    assert (major, minor) == (2, 6)


@pytest.mark.parametrize("args,kwargs", CALL_FORMS)
def test_same_call_forms_and_return_structure(ellipsoid_mesh, args, kwargs):
    _, (V, F) = ellipsoid_mesh
    ref = igl.principal_curvature(V, F, *args, **kwargs)
    out = igl_hhj.principal_curvature(V, F, *args, **kwargs)
    assert type(out) is type(ref) and len(out) == len(ref) == 5
    for a, b in zip(out[:4], ref[:4]):
        assert a.shape == b.shape and a.dtype == b.dtype == np.float64
        assert a.flags.c_contiguous
    assert isinstance(out[4], list) and out[4] == []
    PD1, PD2, PV1, PV2, _ = out
    assert np.all(PV1 >= PV2)
    np.testing.assert_allclose(np.linalg.norm(PD1, axis=1), 1.0)
    np.testing.assert_allclose(np.linalg.norm(PD2, axis=1), 1.0)
    np.testing.assert_allclose(np.einsum("ij,ij->i", PD1, PD2), 0.0, atol=1e-12)


def test_keyword_names_match_libigl():
    doc = igl.principal_curvature.__doc__.splitlines()[0]
    for name in ("V:", "F:", "radius:", "useKring:"):
        assert name in doc
    import inspect
    params = list(inspect.signature(igl_hhj.principal_curvature).parameters)
    assert params[:4] == ["V", "F", "radius", "useKring"]


def test_int32_float32_inputs(ellipsoid_mesh):
    _, (V, F) = ellipsoid_mesh
    a = igl_hhj.principal_curvature(V.astype(np.float32), F.astype(np.int32))
    b = igl_hhj.principal_curvature(V.astype(np.float32).astype(np.float64), F)
    np.testing.assert_allclose(a[2], b[2])


def test_values_agree_with_libigl_and_sign(ellipsoid_mesh):
    """Both estimate the same curvatures: their difference is of the order of
    their discretisation errors against the exact ellipsoid."""
    surface, (V, F) = ellipsoid_mesh
    PD1, PD2, PV1, PV2, _ = igl_hhj.principal_curvature(V, F)
    QD1, QD2, QV1, QV2, _ = igl.principal_curvature(V, F)
    e_hhj = vertex_errors(V, F, PV1, PV2, surface)
    e_igl = vertex_errors(V, F, QV1, QV2, surface)
    w = np.ones(len(V))
    diff = np.sqrt(np.mean(w * ((PV1 - QV1) ** 2 + (PV2 - QV2) ** 2)))
    scale = np.sqrt(np.mean(QV1 ** 2 + QV2 ** 2))
    assert diff < 0.1 * scale
    assert e_hhj["k1"] < e_igl["k1"] and e_hhj["k2"] < 2 * e_igl["k2"]
    assert np.all(PV2 > 0) and np.all(QV2 > 0)      # convex: positive with outward normals
    # the max directions agree (up to sign) where the surface is far from umbilic
    k1, k2 = surface.principal_curvatures(V)
    far = (k1 - k2) > 0.5
    cos = np.abs(np.einsum("ij,ij->i", PD1[far], QD1[far]))
    assert np.median(cos) > 0.99


def test_unreferenced_vertices_are_bad_vertices(ellipsoid_mesh):
    _, (V, F) = ellipsoid_mesh
    V2 = np.vstack([V, [[10.0, 10.0, 10.0]]])
    PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(V2, F)
    assert bad == [len(V)]
    assert np.isnan(PV1[-1]) and np.isnan(PD1[-1]).all()
    assert np.isfinite(PV1[:-1]).all()


def test_bad_arguments():
    V, F = igl.icosahedron()
    with pytest.raises(TypeError, match="radius must be an int"):
        igl_hhj.principal_curvature(V, F, 2.5)
    with pytest.raises(ValueError, match="radius must be positive"):
        igl_hhj.principal_curvature(V, F, 0)
    with pytest.raises(TypeError, match="useKring must be a bool"):
        igl_hhj.principal_curvature(V, F, 5, "yes")
    with pytest.raises(ValueError, match="out-of-range"):
        igl_hhj.principal_curvature(V, F + 1)


def test_tetrahedron_and_tiny_meshes_do_not_crash():
    """libigl#1024: a tetrahedron segfaults libigl's estimator; ours answers."""
    V = np.array([[1.0, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(V, F)
    assert np.isfinite(PV1).all() and np.all(PV1 > 0) and bad == []
    one = igl_hhj.principal_curvature(V[:3], F[:1])     # a single triangle: flat
    np.testing.assert_allclose(one[2], 0.0, atol=1e-12)
