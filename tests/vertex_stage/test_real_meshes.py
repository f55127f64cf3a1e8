"""Every mesh in shared/data/meshes runs through the core API without error or NaN."""
import warnings

import igl
import numpy as np
import pytest
from conftest import real_mesh_params

import igl_hhj
from igl_hhj.mesh import MeshWarning, TriangleMesh


@pytest.mark.parametrize("path", real_mesh_params())
def test_real_mesh(path, monkeypatch):
    V, F = igl.read_triangle_mesh(str(path))
    m = TriangleMesh(V, F)
    S = igl_hhj.shape_operator(V, F)
    assert S.shape == (len(F), 3, 3) and np.isfinite(S).all()
    np.testing.assert_allclose(np.einsum("fab,fb->fa", S, m.face_normals), 0.0,
                               atol=1e-8 * np.abs(S).max())

    def no_repair(*args, **kwargs):
        raise AssertionError(f"the repair path ran on {path.name}")
    monkeypatch.setattr(igl_hhj.repair, "repair_mesh", no_repair)   # issue 24: the fast path only
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshWarning)
        PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(V, F)
    ref = m.referenced_vertices
    assert np.isfinite(PV1[ref]).all() and np.isfinite(PV2[ref]).all() and np.isfinite(PD1[ref]).all()
    assert bad == np.flatnonzero(~ref).tolist()
    # scale-aware sanity: the median |mean curvature| is of the order of 1/size
    size = np.linalg.norm(V.max(0) - V.min(0))
    H = 0.5 * (PV1[ref] + PV2[ref])
    assert 0.1 / size < np.median(np.abs(H)) < 100 / size
    # the mesh's total mean curvature has the sign of a closed outward surface
    if not m.has_boundary:
        assert np.sum(H * np.bincount(m.F.ravel(), np.repeat(m.face_areas, 3), len(V))[ref]) > 0
