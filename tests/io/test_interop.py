"""Mesh objects of other libraries (issue 14): trimesh / pyvista / meshio meshes are
accepted wherever (V, F) is (V = the object, F omitted), give exactly the results of
their arrays, and results go back onto such objects.  trimesh and meshio come with
the test extra; the pyvista checks skip when it is absent."""
from __future__ import annotations

import numpy as np
import pytest
from conftest import require_test_extra

import igl_hhj
from igl_hhj import baselines, interop
from igl_hhj.mesh import as_mesh
from igl_hhj.surfaces.exact import Ellipsoid
from igl_hhj.surfaces.meshing import ellipsoid_coarse, jitter_tangentially, refine


@pytest.fixture(scope="module")
def mesh():
    s = Ellipsoid()
    V, F = refine(*ellipsoid_coarse(s, subdivisions=1), s, 1)
    return jitter_tangentially(V, F, s, 0.2, seed=4), F


def _objects(V, F):
    out = {}
    trimesh = pytest.importorskip("trimesh")
    out["trimesh"] = trimesh.Trimesh(V, F, process=False)
    meshio = pytest.importorskip("meshio")
    out["meshio"] = meshio.Mesh(V, [("vertex", np.arange(3)[:, None]), ("triangle", F)])
    pyvista = require_test_extra("pyvista")
    out["pyvista"] = pyvista.PolyData(V, np.column_stack([np.full(len(F), 3), F]).ravel())
    return out


def test_objects_give_the_results_of_their_arrays(mesh):
    V, F = mesh
    S = igl_hhj.shape_operator(V, F)
    PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(V, F)
    H = igl_hhj.face_mean_curvature(V, F)
    K = igl_hhj.regge.gauss_curvature(V, F)
    for kind, obj in _objects(V, F).items():
        np.testing.assert_array_equal(as_mesh(obj).F, F, err_msg=kind)     # faces never reordered
        np.testing.assert_array_equal(igl_hhj.shape_operator(obj), S, err_msg=kind)
        r = igl_hhj.principal_curvature(obj)
        np.testing.assert_array_equal(r[2], PV1, err_msg=kind)
        np.testing.assert_array_equal(r[1], PD2, err_msg=kind)
        np.testing.assert_array_equal(igl_hhj.face_mean_curvature(obj), H, err_msg=kind)
        np.testing.assert_array_equal(igl_hhj.regge.gauss_curvature(obj), K, err_msg=kind)
        np.testing.assert_array_equal(baselines.hhj_face(obj).k1, baselines.hhj_face(V, F).k1, err_msg=kind)


def test_bad_objects_are_clear_errors(mesh):
    V, F = mesh
    meshio = pytest.importorskip("meshio")
    quads = meshio.Mesh(V[:4], [("quad", [[0, 1, 2, 3]])])
    with pytest.raises(ValueError, match="quad cells.*triangulate"):
        igl_hhj.shape_operator(quads)
    tets = meshio.Mesh(V[:4], [("tetra", [[0, 1, 2, 3]])])
    with pytest.raises(ValueError, match="volume mesh"):
        igl_hhj.shape_operator(tets)
    with pytest.raises(ValueError, match="no triangle cells"):
        igl_hhj.shape_operator(meshio.Mesh(V, [("line", [[0, 1]])]))
    with pytest.raises(TypeError, match="F is required unless V is a TriangleMesh or a mesh object"):
        igl_hhj.shape_operator(V)
    # the adapter hands the arrays to the usual validation (here: an index out of range)
    trimesh = pytest.importorskip("trimesh")
    broken = trimesh.Trimesh(V.copy(), F.copy(), process=False, validate=False)
    broken.faces[0, 0] = len(V) + 5
    with pytest.raises(ValueError, match="out-of-range vertex indices"):
        igl_hhj.shape_operator(broken)


def test_pyvista_needs_triangles(mesh):
    pv = require_test_extra("pyvista")
    quad = pv.PolyData(np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]]), np.array([4, 0, 1, 2, 3]))
    with pytest.raises(ValueError, match="triangulate"):
        igl_hhj.shape_operator(quad)
    S = igl_hhj.shape_operator(quad.triangulate())
    assert S.shape == (2, 3, 3) and np.allclose(S, 0.0)          # a flat square


def test_results_back_onto_objects(mesh):
    V, F = mesh
    est_v, est_f = baselines.hhj_vertex(V, F), baselines.hhj_face(V, F)
    trimesh = pytest.importorskip("trimesh")
    tm = interop.to_trimesh(trimesh.Trimesh(V, F, process=False), est_v)
    np.testing.assert_array_equal(tm.faces, F)
    np.testing.assert_array_equal(tm.vertex_attributes["H"], est_v.H)
    tf = interop.to_trimesh(V, F, {"S": igl_hhj.shape_operator(V, F), "H": est_f.H})
    assert tf.face_attributes["S"].shape == (len(F), 3, 3)
    meshio = pytest.importorskip("meshio")
    m = interop.to_meshio(V, F, est_f)
    np.testing.assert_array_equal(m.cell_data["K"][0], est_f.K)
    assert m.cell_data["d1"][0].shape == (len(F), 3)
    back = interop.to_meshio(m, results={"u": V[:, 0]})               # a meshio.Mesh in, out again
    np.testing.assert_array_equal(back.point_data["u"], V[:, 0])
    with pytest.raises(ValueError, match="first axis must have"):
        interop.to_meshio(V, F, {"x": np.zeros(len(V) + 1)})
    with pytest.raises(TypeError, match="CurvatureEstimate or a dict"):
        interop.to_meshio(V, F, [1, 2, 3])


def test_results_onto_pyvista(mesh):
    require_test_extra("pyvista")
    V, F = mesh
    est = baselines.hhj_vertex(V, F)
    p = interop.to_pyvista(V, F, est)
    np.testing.assert_array_equal(p.point_data["k1"], est.k1)
    np.testing.assert_allclose(p.points, V)
    assert p.is_all_triangles and p.n_cells == len(F)


def test_viewer_takes_objects(mesh):
    ps = pytest.importorskip("polyscope")
    trimesh = pytest.importorskip("trimesh")
    from igl_hhj import viewer
    V, F = mesh
    viewer.init("openGL_mock")
    reg = viewer.register_comparison(trimesh.Trimesh(V, F, process=False), name="tm")
    assert set(reg.structures) == {"tm HHJ", "tm libigl"}
    ps.remove_all_structures()


def test_tensors_round_trip_through_vtu(mesh, tmp_path):
    """(#F, 3, 3) tensors used to be written into .vtu with a corrupt layout: now (#F, 9)."""
    meshio = pytest.importorskip("meshio")
    V, F = mesh
    S = igl_hhj.shape_operator(V, F)
    Sv = np.random.default_rng(0).normal(size=(len(V), 3, 3))
    m = interop.to_meshio(V, F, {"S": S, "Sv": Sv})
    assert m.cell_data["S"][0].shape == (len(F), 9) and m.point_data["Sv"].shape == (len(V), 9)
    m.write(tmp_path / "s.vtu")
    back = meshio.read(tmp_path / "s.vtu")
    np.testing.assert_allclose(back.cell_data["S"][0].reshape(-1, 3, 3), S)
    np.testing.assert_allclose(back.point_data["Sv"].reshape(-1, 3, 3), Sv)
    # VTK itself (pyvista's reader) sees valid 9-component arrays of the right length
    pv = require_test_extra("pyvista")
    grid = pv.read(tmp_path / "s.vtu")
    assert grid.cell_data["S"].shape == (len(F), 9) and grid.point_data["Sv"].shape == (len(V), 9)
    np.testing.assert_array_equal(grid.cell_data["S"].reshape(-1, 3, 3), S)


def test_to_pyvista_flattens_tensors_and_shows_H(mesh, tmp_path):
    """(n, 3, 3) results become (n, 9) arrays on points and cells (pyvista refuses 3-d
    point data); H is the active scalars unless ``scalars=`` says otherwise, and the
    .vtp pyvista writes keeps both."""
    pv = require_test_extra("pyvista")
    V, F = mesh
    S = igl_hhj.shape_operator(V, F)
    est = baselines.hhj_vertex(V, F)
    p = interop.to_pyvista(V, F, {"H": est.H, "Sv": np.repeat(S[:1], len(V), axis=0), "S": S})
    assert p.point_data["Sv"].shape == (len(V), 9) and p.cell_data["S"].shape == (len(F), 9)
    assert p.point_data.active_scalars_name == "H"
    p.save(tmp_path / "p.vtp")
    back = pv.read(tmp_path / "p.vtp")
    assert back.point_data.active_scalars_name == "H"
    np.testing.assert_array_equal(back.cell_data["S"].reshape(-1, 3, 3), S)
    assert interop.to_pyvista(V, F, est, scalars="K").point_data.active_scalars_name == "K"
    with pytest.raises(ValueError, match="scalars='Q' is not one of the results"):
        interop.to_pyvista(V, F, est, scalars="Q")


class _FakeGrid:
    """The attributes of a pyvista.UnstructuredGrid that the adapter reads."""

    def __init__(self, V, F, types=None):
        self.points = V
        self.n_points = len(V)
        self.cells = np.column_stack([np.full(len(F), 3), F]).ravel()
        self.celltypes = np.full(len(F), 5, np.uint8) if types is None else types
        self.cells_dict = {5: F}


def test_unstructured_grid_of_triangles_is_a_mesh_object(mesh):
    V, F = mesh
    grid = _FakeGrid(V, F)
    assert interop.is_mesh_object(grid)
    V2, F2 = interop.mesh_arrays(grid)
    np.testing.assert_array_equal(V2, V)
    np.testing.assert_array_equal(F2, F)
    np.testing.assert_allclose(igl_hhj.face_mean_curvature(grid), igl_hhj.face_mean_curvature(V, F))
    with pytest.raises(ValueError, match="tetra cells: only triangles"):
        interop.mesh_arrays(_FakeGrid(V, F, np.r_[np.full(len(F) - 1, 5), 10].astype(np.uint8)))


def test_real_pyvista_unstructured_grid(mesh):
    pv = require_test_extra("pyvista")
    V, F = mesh
    grid = pv.PolyData(V, np.column_stack([np.full(len(F), 3), F]).ravel()).cast_to_unstructured_grid()
    V2, F2 = interop.mesh_arrays(grid)
    np.testing.assert_allclose(V2, V)
    np.testing.assert_array_equal(F2, F)
