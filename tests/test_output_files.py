"""Output files other tools read (issue 14): ``igl-hhj curvature -o`` written as .ply
(named properties + MeshLab's ``quality``), .vtu / .vtk (meshio) and .obj (vertex
colours), read back with meshio, trimesh, pyvista and pymeshlab.  meshio and
trimesh come with the test extra; the pyvista / pymeshlab checks skip when those
are not installed."""
from __future__ import annotations

import sys

import igl
import numpy as np
import pytest

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
        for ext in (".ply", ".vtu", ".vtk", ".obj"):
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


@pytest.mark.parametrize("per", ["vertex", "face"])
def test_pyvista_reads_vtk_files(files, per):
    pv = pytest.importorskip("pyvista")
    out, est, V, _ = files
    for ext in (".vtu", ".vtk"):
        m = pv.read(out[per, ext])
        data = m.point_data if per == "vertex" else m.cell_data
        _check({q: data[q] for q in QUANTS}, est[per])
        np.testing.assert_allclose(m.points, V)


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


def test_vtu_without_meshio_is_a_clear_error(files, tmp_path, monkeypatch, capsys):
    out, est, V, F = files
    monkeypatch.setitem(sys.modules, "meshio", None)            # import meshio -> ImportError
    with pytest.raises(mesh_io.MeshFileError, match="needs meshio: pip install meshio"):
        mesh_io.check_output_path(tmp_path / "x.vtu")
    mesh = tmp_path / "s.off"
    igl.write_triangle_mesh(str(mesh), V, F)
    assert cli.main(["curvature", str(mesh), "-o", str(tmp_path / "x.vtk")]) == 2
    assert "needs meshio" in capsys.readouterr().err and not (tmp_path / "x.vtk").exists()


def test_quantity_colours():
    c = mesh_io.quantity_colours(np.array([-2.0, 0.0, 2.0, np.nan, 100.0]), robust=0)
    np.testing.assert_allclose(c[1], [0.865] * 3)
    assert c[0, 2] > c[0, 0] and c[2, 0] > c[2, 2]                  # blue < 0 < red
    np.testing.assert_allclose(c[3], [0.5] * 3)                    # NaN: grey
    np.testing.assert_allclose(c[4], [0.706, 0.016, 0.150])        # the largest magnitude: the red end
    with pytest.raises(ValueError, match="quantity must be one of"):
        mesh_io.write_curvature("x.ply", np.zeros((3, 3)), np.array([[0, 1, 2]]), None, method="hhj",
                                quantity="Q")
