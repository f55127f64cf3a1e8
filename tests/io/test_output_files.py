"""Output files other tools read (issues 14, 26): ``igl-hhj curvature -o`` written as .ply
(named properties + MeshLab's ``quality``), .vtp / .vtu / .vtk (numpy-written VTK, the
quantity as the active scalars) and .obj (vertex colours), read back with meshio,
trimesh, pyvista and pymeshlab.  meshio, trimesh and pyvista come with the test extra;
the pymeshlab checks skip when it is not installed."""
from __future__ import annotations

import sys

import igl
import numpy as np
import pytest
from conftest import require_test_extra

from igl_hhj import baselines, cli, mesh_io

QUANTS = ("k1", "k2", "H", "K")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """{(per, ext): path} of a jittered unit sphere's curvature (quality = K), and
    the estimates {per: CurvatureEstimate} they hold."""
    from igl_hhj.surfaces.exact import Sphere
    from igl_hhj.surfaces.meshing import icosphere, jitter_tangentially
    V, F = icosphere(3)
    V = jitter_tangentially(V, F, Sphere(), 0.2, seed=2)
    d = tmp_path_factory.mktemp("out")
    mesh = d / "sphere.off"
    igl.write_triangle_mesh(str(mesh), V, F)
    V, F = igl.read_triangle_mesh(str(mesh))
    out = {}
    for per in ("vertex", "face"):
        for ext in (".ply", ".vtp", ".vtu", ".vtk", ".obj"):
            out[per, ext] = d / f"{per}{ext}"
            assert cli.main(["curvature", str(mesh), "--per", per, "--quantity", "K", "-q",
                             "-o", str(out[per, ext])]) == 0
    est = {"vertex": baselines.hhj_vertex(V, F), "face": baselines.hhj_face(V, F)}
    return out, est, V, F


def _check(arrays, est, with_quality=False):
    for q in QUANTS:
        np.testing.assert_allclose(np.asarray(arrays[q]).ravel(), getattr(est, q), rtol=1e-12, atol=1e-12)
    if with_quality:
        np.testing.assert_allclose(np.asarray(arrays["quality"]).ravel(), est.K, rtol=1e-12)


@pytest.mark.parametrize("ext", [".vtu", ".vtk"])
@pytest.mark.parametrize("per", ["vertex", "face"])
def test_meshio_reads_vtk_files(files, per, ext):
    meshio = pytest.importorskip("meshio")
    out, est, V, F = files
    m = meshio.read(out[per, ext])
    np.testing.assert_allclose(m.points, V, rtol=0, atol=0)
    np.testing.assert_array_equal(m.cells_dict["triangle"], F)
    data = m.point_data if per == "vertex" else {k: v[0] for k, v in m.cell_data.items()}
    _check(data, est[per])
    assert data["d1"].shape == (len(est[per].k1), 3)
    np.testing.assert_allclose(data["d1"], est[per].d1, atol=1e-12)


def test_meshio_reads_the_vertex_ply(files):
    meshio = pytest.importorskip("meshio")
    out, est, V, _ = files
    m = meshio.read(out["vertex", ".ply"])
    np.testing.assert_array_equal(m.points, V)
    _check(m.point_data, est["vertex"], with_quality=True)


@pytest.mark.parametrize("per", ["vertex", "face"])
def test_trimesh_reads_ply_properties_and_obj_colours(files, per):
    trimesh = pytest.importorskip("trimesh")
    out, est, V, F = files
    t = trimesh.load(out[per, ".ply"], process=False)
    np.testing.assert_array_equal(t.faces, F)
    raw = t.metadata["_ply_raw"][per]["data"]
    _check({n: raw[n] for n in raw.dtype.names}, est[per], with_quality=True)
    o = trimesh.load(out[per, ".obj"], process=False)
    assert o.vertices.shape == V.shape and np.allclose(o.vertices, V)
    rgb = np.asarray(o.visual.vertex_colors)[:, :3].astype(float)
    # unit sphere, K ≈ 1 > 0 everywhere: every vertex on the red side of the diverging map
    assert rgb.shape == (len(V), 3) and np.all(rgb[:, 0] > rgb[:, 2])


@pytest.mark.parametrize("per", ["vertex", "face"])
def test_libigl_reads_the_ply(files, per):
    out, _, V, F = files
    V2, F2 = igl.read_triangle_mesh(str(out[per, ".ply"]))
    np.testing.assert_array_equal(V2, V)
    np.testing.assert_array_equal(F2, F)


@pytest.mark.parametrize("ext", [".vtp", ".vtu", ".vtk"])
@pytest.mark.parametrize("per", ["vertex", "face"])
def test_pyvista_reads_vtk_files(files, per, ext):
    """pyvista (VTK's own readers) opens the files with the --quantity (here K) as the
    active scalars, every value exact, d1 / d2 as 3-vectors; .vtp is a PolyData."""
    pv = require_test_extra("pyvista")
    out, est, V, F = files
    m = pv.read(out[per, ext])
    assert type(m).__name__ == ("PolyData" if ext == ".vtp" else "UnstructuredGrid")
    data = m.point_data if per == "vertex" else m.cell_data
    other = m.cell_data if per == "vertex" else m.point_data
    assert data.active_scalars_name == "K" and m.active_scalars_name == "K"
    assert len(other.keys()) == 0
    n = len(est[per].k1)
    _check({q: data[q] for q in QUANTS}, est[per])
    for q in QUANTS:
        assert data[q].shape == (n,)
    assert data["d1"].shape == data["d2"].shape == (n, 3) and data.active_vectors_name == "d1"
    np.testing.assert_allclose(data["d2"], est[per].d2, rtol=0, atol=0)
    np.testing.assert_allclose(m.points, V, rtol=0, atol=0)
    assert m.n_cells == len(F) and (m.is_all_triangles if ext == ".vtp" else True)
    faces = (m.faces if ext == ".vtp" else m.cells).reshape(-1, 4)
    np.testing.assert_array_equal(faces[:, 1:], F)


def test_vtk_files_default_to_H_and_carry_the_shape_operator(files, tmp_path):
    """Without --quantity the active scalars are H; write_curvature(S=...) adds the
    shape operator as a 9-component cell tensor (ParaView's tensor layout)."""
    pv = require_test_extra("pyvista")
    out, est, V, F = files
    mesh = tmp_path / "s.off"
    igl.write_triangle_mesh(str(mesh), V, F)
    assert cli.main(["curvature", str(mesh), "-q", "-o", str(tmp_path / "h.vtp")]) == 0
    assert pv.read(tmp_path / "h.vtp").point_data.active_scalars_name == "H"
    import igl_hhj
    S = igl_hhj.shape_operator(V, F)
    for ext in (".vtp", ".vtu", ".vtk"):
        mesh_io.write_curvature(tmp_path / f"s{ext}", V, F, est["vertex"], method="hhj", S=S)
        m = pv.read(tmp_path / f"s{ext}")
        assert m.cell_data["S"].shape == (len(F), 9) and m.GetCellData().GetTensors().GetName() == "S"
        np.testing.assert_array_equal(m.cell_data["S"].reshape(-1, 3, 3), S)
        assert m.point_data.active_scalars_name == "H"


@pytest.mark.parametrize("per", ["vertex", "face"])
def test_pymeshlab_reads_quality_and_colours(files, per):
    pymeshlab = pytest.importorskip("pymeshlab")
    out, est, V, _ = files
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(out[per, ".ply"]))
    m = ms.current_mesh()
    q = m.vertex_scalar_array() if per == "vertex" else m.face_scalar_array()
    np.testing.assert_allclose(q, est[per].K, rtol=1e-12)
    ms.load_new_mesh(str(out[per, ".obj"]))
    assert ms.current_mesh().has_vertex_color()


def test_vtk_files_need_no_meshio(files, tmp_path, monkeypatch):
    """.vtp / .vtu / .vtk used to need meshio (``pip install "igl-hhj[io]"``, a hint that
    fails from a checkout); they are written with numpy now."""
    pv = require_test_extra("pyvista")
    out, est, V, F = files
    monkeypatch.setitem(sys.modules, "meshio", None)            # import meshio -> ImportError
    mesh = tmp_path / "s.off"
    igl.write_triangle_mesh(str(mesh), V, F)
    for ext in (".vtp", ".vtu", ".vtk"):
        assert mesh_io.check_output_path(tmp_path / f"x{ext}") == ext
        assert cli.main(["curvature", str(mesh), "-q", "-o", str(tmp_path / f"x{ext}")]) == 0
        monkeypatch.delitem(sys.modules, "meshio")
        np.testing.assert_array_equal(pv.read(tmp_path / f"x{ext}").point_data["H"], est["vertex"].H)
        monkeypatch.setitem(sys.modules, "meshio", None)


def test_write_vtk_checks_its_arguments(tmp_path):
    from igl_hhj.vtk_files import write_vtk
    V, F = np.eye(3), np.array([[0, 1, 2]])
    with pytest.raises(ValueError, match="not a VTK extension"):
        write_vtk(tmp_path / "x.vtx", V, F)
    with pytest.raises(ValueError, match="first axis must have 3 entries"):
        write_vtk(tmp_path / "x.vtp", V, F, point_data={"u": np.zeros(4)})
    with pytest.raises(ValueError, match="one-component"):
        write_vtk(tmp_path / "x.vtp", V, F, point_data={"d": V}, scalars="d")
    with pytest.raises(ValueError, match="not one of the arrays"):
        write_vtk(tmp_path / "x.vtp", V, F, point_data={"u": V[:, 0]}, scalars="H")
    with pytest.raises(TypeError, match="must be numeric"):
        write_vtk(tmp_path / "x.vtp", V, F, cell_data={"s": np.array(["a"])})
    with pytest.raises(ValueError, match="without quotes"):
        write_vtk(tmp_path / "x.vtp", V, F, cell_data={'a"b': np.zeros(1)})


def test_quantity_colours():
    c = mesh_io.quantity_colours(np.array([-2.0, 0.0, 2.0, np.nan, 100.0]), robust=0)
    np.testing.assert_allclose(c[1], [0.865] * 3)
    assert c[0, 2] > c[0, 0] and c[2, 0] > c[2, 2]                  # blue < 0 < red
    np.testing.assert_allclose(c[3], [0.5] * 3)                    # NaN: grey
    np.testing.assert_allclose(c[4], [0.706, 0.016, 0.150])        # the largest magnitude: the red end
    with pytest.raises(ValueError, match="quantity must be one of"):
        mesh_io.write_curvature("x.ply", np.zeros((3, 3)), np.array([[0, 1, 2]]), None, method="hhj",
                                quantity="Q")
