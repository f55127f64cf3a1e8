"""Reading what libigl lacks (issue 26, item 4): glTF/GLB, 3MF (trimesh), VTP/VTU/VTK
(pyvista, meshio), polygon PLY; polygons split by one rule in every format (the fan
from each polygon's first corner, libigl's OBJ/OFF rule) and reported by ``info``.
Every file is generated in tmp_path."""
from __future__ import annotations

import sys

import numpy as np
import pytest
from conftest import require_test_extra

from igl_hhj import baselines, cli, mesh_io, polygon_io
from igl_hhj.mesh_report import mesh_report


def _quad_torus(nu=9, nv=7, R=1.0, r=0.4):
    """A torus of nu × nv non-planar quads on a non-uniform parameter grid (corners in
    order around each quad, outward normals)."""
    rng = np.random.default_rng(3)
    u = 2 * np.pi * (np.arange(nu) + 0.3 * rng.random(nu)) / nu
    v = 2 * np.pi * (np.arange(nv) + 0.3 * rng.random(nv)) / nv
    U, W = np.meshgrid(u, v, indexing="ij")
    V = np.column_stack([((R + r * np.cos(W)) * np.cos(U)).ravel(), ((R + r * np.cos(W)) * np.sin(U)).ravel(),
                         (r * np.sin(W)).ravel()])
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    idx = lambda a, b: (a % nu) * nv + (b % nv)                       # noqa: E731
    Q = np.column_stack([idx(i, j).ravel(), idx(i + 1, j).ravel(), idx(i + 1, j + 1).ravel(),
                         idx(i, j + 1).ravel()])
    return V, Q


def _mixed():
    """Quads, triangles and one pentagon (a second component), in an interleaved order."""
    V, Q = _quad_torus()
    polys = []
    for n, q in enumerate(Q.tolist()):
        polys += [q[:3], [q[0], q[2], q[3]]] if n % 3 == 0 else [q]
    t = 2 * np.pi * np.arange(5) / 5
    V = np.vstack([V, np.column_stack([np.cos(t), np.sin(t), np.full(5, 3.0)])])
    polys.insert(4, list(range(len(V) - 5, len(V))))
    return V, polys


def _fan(polys):
    return np.array([[p[0], p[j], p[j + 1]] for p in polys for j in range(1, len(p) - 1)])


def _write_obj(path, V, polys):
    with open(path, "w") as fh:
        np.savetxt(fh, V, fmt="v %.17g %.17g %.17g")
        fh.writelines("f " + " ".join(str(i + 1) for i in p) + "\n" for p in polys)


def _write_off(path, V, polys):
    with open(path, "w") as fh:
        fh.write(f"OFF\n{len(V)} {len(polys)} 0\n")
        np.savetxt(fh, V, fmt="%.17g")
        fh.writelines(f"{len(p)} " + " ".join(map(str, p)) + "\n" for p in polys)


def _ply_header(V, n_faces, fmt):
    return (f"ply\nformat {fmt} 1.0\nelement vertex {len(V)}\nproperty double x\nproperty double y\n"
            f"property double z\nelement face {n_faces}\nproperty list uchar int vertex_indices\nend_header\n")


def _write_ply_ascii(path, V, polys):
    with open(path, "w") as fh:
        fh.write(_ply_header(V, len(polys), "ascii"))
        np.savetxt(fh, V, fmt="%.17g")
        fh.writelines(f"{len(p)} " + " ".join(map(str, p)) + "\n" for p in polys)


def _write_ply_binary(path, V, Q):
    k = Q.shape[1]
    face = np.empty(len(Q), dtype=[("n", "u1"), ("i", "<i4", (k,))])
    face["n"], face["i"] = k, Q
    with open(path, "wb") as fh:
        fh.write(_ply_header(V, len(Q), "binary_little_endian").encode())
        fh.write(np.ascontiguousarray(V, dtype="<f8").tobytes())
        fh.write(face.tobytes())


def _vtk_polys(polys):
    return np.concatenate([[len(p), *p] for p in polys]).astype(np.int64)


def test_split_polygons_is_libigls_fan():
    V, polys = _mixed()
    I = np.concatenate(polys)
    C = np.concatenate([[0], np.cumsum([len(p) for p in polys])])
    F, J, split = polygon_io.split_polygons(I, C)
    np.testing.assert_array_equal(F, _fan(polys))
    np.testing.assert_array_equal(J, np.repeat(np.arange(len(polys)), [len(p) - 2 for p in polys]))
    n_quads = sum(len(p) == 4 for p in polys)
    assert split.corners == {3: sum(len(p) == 3 for p in polys), 4: n_quads, 5: 1}
    assert split.n_triangles == len(F)
    assert split.describe().startswith(f"{n_quads} quads, 1 pentagon split into {2 * n_quads + 3} triangles")
    with pytest.raises(ValueError, match="polygon 1 has 2 corners"):
        polygon_io.split_polygons([0, 1, 2, 0, 1], [0, 3, 5])
    with pytest.raises(ValueError, match="C must run from 0"):
        polygon_io.split_polygons([0, 1, 2], [0, 4])


def _polygon_files(tmp_path, V, polys):
    """The same polygon mesh in every format that can hold it."""
    files = {}
    for ext, writer in ((".obj", _write_obj), (".off", _write_off), (".ply", _write_ply_ascii)):
        files[ext] = tmp_path / f"m{ext}"
        writer(files[ext], V, polys)
    pv = require_test_extra("pyvista")
    grid = pv.PolyData(V, _vtk_polys(polys))
    for ext in (".vtp", ".vtk"):
        files[ext] = tmp_path / f"m{ext}"
        grid.save(files[ext])
    files[".vtu"] = tmp_path / "m.vtu"
    grid.cast_to_unstructured_grid().save(files[".vtu"])
    return files


def test_one_split_rule_for_every_format(tmp_path):
    """OBJ / OFF through libigl, ascii PLY / VTP / VTU / VTK through pyvista: the same
    triangles, in file order, and the same split counts."""
    V, polys = _mixed()
    want = _fan(polys)
    for ext, path in _polygon_files(tmp_path, V, polys).items():
        mf = mesh_io.read_mesh_file(path)
        np.testing.assert_array_equal(mf.F, want, err_msg=ext)
        np.testing.assert_allclose(mf.V, V, rtol=0, atol=1e-15 if ext != ".vtk" else 1e-6, err_msg=ext)
        assert mf.split.corners == polygon_io.polygon_split([len(p) for p in polys]).corners, ext
        assert (mf.reader == "libigl") == (ext in (".obj", ".off")), ext


def test_quad_files_are_reported_by_info(tmp_path, capsys):
    V, Q = _quad_torus()
    n = len(Q)
    files = _polygon_files(tmp_path, V, Q.tolist())
    files[".plyb"] = tmp_path / "binary.ply"
    _write_ply_binary(files[".plyb"], V, Q)
    for ext, path in files.items():
        mf = mesh_io.read_mesh_file(path)
        np.testing.assert_array_equal(mf.F, _fan(Q.tolist()), err_msg=ext)
        rep = mesh_report(mf.V, mf.F, split=mf.split)
        assert rep.n_quads_split == n and rep.n_faces == 2 * n and rep.polygons == {4: n}, ext
        assert rep.accepted and rep.genus == 1, ext
        assert cli.main(["info", str(path)]) == 0
        out = capsys.readouterr().out
        assert f"polygons          {n} quads split into {2 * n} triangles (fan from each polygon's " \
               f"first corner" in out, ext
        _, _, messages = mesh_io.read_mesh(path)
        assert any(f"{n} quads split into {2 * n} triangles" in m for m in messages), ext
    assert cli.main(["curvature", str(files[".vtp"])]) == 0
    assert f"{n} quads split into {2 * n} triangles" in capsys.readouterr().out
    tri = tmp_path / "tri.obj"
    _write_obj(tri, V, _fan(Q.tolist()).tolist())
    assert cli.main(["info", str(tri)]) == 0
    assert "polygons" not in capsys.readouterr().out                 # nothing split, no line
    assert mesh_io.read_mesh_file(tri).split.n_split == 0


def test_binary_ply_of_mixed_polygons_is_refused(tmp_path):
    V, Q = _quad_torus()
    path = tmp_path / "mixed.ply"
    _write_ply_binary(path, V, Q)
    data = bytearray(path.read_bytes())
    start = data.index(b"end_header\n") + len(b"end_header\n") + V.nbytes
    data[start] = 3                                           # first record claims a triangle
    path.write_bytes(bytes(data))
    with pytest.raises(mesh_io.MeshFileError, match="face 0 declares 3 corners where the file size says 4"):
        mesh_io.read_mesh(path)
    path.write_bytes(bytes(data[:-5]))
    with pytest.raises(mesh_io.MeshFileError, match="binary PLYs of mixed polygons are not supported"):
        mesh_io.read_mesh(path)


@pytest.fixture(scope="module")
def result_files(tmp_path_factory):
    """Our own .vtp / .vtu / .vtk outputs, per vertex and per face."""
    from igl_hhj.surfaces.exact import Sphere
    from igl_hhj.surfaces.meshing import icosphere, jitter_tangentially
    d = tmp_path_factory.mktemp("results")
    V, F = icosphere(2)
    V = jitter_tangentially(V, F, Sphere(), 0.2, seed=1)
    out = {}
    for per, est in (("vertex", baselines.hhj_vertex(V, F)), ("face", baselines.hhj_face(V, F))):
        for ext in (".vtp", ".vtu", ".vtk"):
            p = d / f"{per}{ext}"
            mesh_io.write_curvature(p, V, F, est, method="hhj", quantity="K")
            out[per, ext] = p, est
    return V, F, out


@pytest.mark.parametrize("reader", ["pyvista", "meshio"])
def test_our_vtk_files_round_trip(result_files, reader):
    """Geometry exactly, and every stored value (point data per vertex, cell data per face)."""
    if reader == "pyvista":
        require_test_extra("pyvista")
    else:
        require_test_extra("meshio")
    V, F, out = result_files
    for (per, ext), (path, est) in out.items():
        if reader == "meshio" and ext == ".vtp":
            continue                                          # meshio has no .vtp reader
        pm = polygon_io.read_polygon_mesh(path, readers=(reader,))
        assert pm.reader.startswith(reader)
        mf = mesh_io.read_mesh_file(path) if reader == "pyvista" else None
        np.testing.assert_array_equal(pm.V, V, err_msg=f"{per}{ext}")
        np.testing.assert_array_equal(pm.I.reshape(-1, 3), F, err_msg=f"{per}{ext}")
        data = pm.point_data if per == "vertex" else pm.cell_data
        for q in ("k1", "k2", "H", "K"):
            np.testing.assert_array_equal(data[q], getattr(est, q), err_msg=f"{per}{ext} {q}")
        np.testing.assert_array_equal(data["d1"], est.d1, err_msg=f"{per}{ext}")
        if mf is not None:
            np.testing.assert_array_equal(mf.F, F)
            assert mf.split.n_split == 0 and mf.notes() == []
            np.testing.assert_array_equal((mf.point_data if per == "vertex" else mf.cell_data)["H"], est.H)


def test_gltf_glb_and_3mf(tmp_path, capsys):
    trimesh = require_test_extra("trimesh")
    from igl_hhj.surfaces import icosphere
    V, F = icosphere(2)
    # every face with its own corners, as glTF exporters write seams: welded back
    split = trimesh.Trimesh(V[F].reshape(-1, 3), np.arange(3 * len(F)).reshape(-1, 3), process=False)
    for ext in (".glb", ".gltf"):
        path = tmp_path / f"s{ext}"
        trimesh.Trimesh(V, F, process=False).export(path)
        mf = mesh_io.read_mesh_file(path)
        assert mf.reader.startswith("trimesh")
        np.testing.assert_array_equal(mf.F, F)
        np.testing.assert_allclose(mf.V, V, rtol=0, atol=1e-7)          # glTF stores float32
        seams = tmp_path / f"seams{ext}"
        split.export(seams)
        V2, F2, messages = mesh_io.read_mesh(seams)
        assert len(V2) == len(V) and f"merged coincident glTF vertices: {3 * len(F)} -> {len(V)}" in messages
        np.testing.assert_array_equal(V2[F2], mf.V[F])                    # same triangles
        assert cli.main(["info", str(seams)]) == 0
        assert "genus             0" in capsys.readouterr().out
    require_test_extra("lxml")                       # trimesh's 3MF reader and writer need lxml
    path = tmp_path / "s.3mf"
    trimesh.Trimesh(V, F, process=False).export(path)
    mf = mesh_io.read_mesh_file(path)
    np.testing.assert_array_equal(mf.V[mf.F], V[F].astype(mf.V.dtype))


def test_missing_reader_names_the_install_command(tmp_path, monkeypatch, capsys):
    V, Q = _quad_torus()
    path = tmp_path / "q.ply"
    _write_ply_ascii(path, V, Q.tolist())
    (tmp_path / "s.glb").write_bytes(b"glTF")
    (tmp_path / "s.vtu").write_text("<VTKFile/>")
    for name in ("pyvista", "trimesh", "meshio"):
        monkeypatch.setitem(sys.modules, name, None)                   # import name -> ImportError
    cases = [(tmp_path / "s.glb", "trimesh"), (tmp_path / "s.vtu", "pyvista")]
    for p, package in cases:
        with pytest.raises(ModuleNotFoundError, match=rf"{p.suffix} files needs {package}: pip install "
                                                      rf"{package} \(in a checkout of igl-hhj: pip install "
                                                      rf"\"\.\[io\]\"\)") as info:
            mesh_io.read_mesh(p)
        assert info.value.name == package
        assert cli.main(["info", str(p)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(f"igl-hhj: error: {p}: reading {p.suffix} files needs "
                                                       f"{package}: pip install {package}") and '".[io]"' in err
    # polygon PLYs need none of them (numpy reader, float64 exactly)
    mf = mesh_io.read_mesh_file(path)
    np.testing.assert_array_equal(mf.V, V)
    np.testing.assert_array_equal(mf.F, _fan(Q.tolist()))


def test_unknown_extension_lists_every_reader(tmp_path):
    p = tmp_path / "x.fbx"
    p.write_text("x")
    with pytest.raises(mesh_io.MeshFileError, match=r"libigl reads .obj.*also .gltf, .glb, .3mf, .vtp, .vtu, .vtk"):
        mesh_io.read_mesh(p)


def test_foreign_files_without_polygons_are_clear_errors(tmp_path):
    pv = require_test_extra("pyvista")
    lines = pv.PolyData(np.eye(3), lines=np.array([2, 0, 1, 2, 1, 2]))
    lines.save(tmp_path / "lines.vtp")
    with pytest.raises(mesh_io.MeshFileError, match="no polygons in this .vtp file.*ignored cells that are "
                                                    "not polygons: 2 line"):
        mesh_io.read_mesh(tmp_path / "lines.vtp")
    (tmp_path / "bad.vtp").write_text("<VTKFile")
    with pytest.raises(mesh_io.MeshFileError, match="bad.vtp: (could not read it|no polygons)"):
        mesh_io.read_mesh(tmp_path / "bad.vtp")


def _walker_torus_quads(n):
    """Walker's torus as 2n × n quads of a non-uniform parameter grid (every corner exactly
    on the surface; the same warp on every level)."""
    from igl_hhj.surfaces.exact import WalkerTorus
    a = 2 * np.pi * np.arange(2 * n) / (2 * n)
    b = 2 * np.pi * np.arange(n) / n
    T, P = np.meshgrid(b + 0.35 * np.sin(b), a + 0.25 * np.sin(a), indexing="ij")
    V = WalkerTorus().parametrize(T.ravel(), P.ravel())
    i, j = np.meshgrid(np.arange(n), np.arange(2 * n), indexing="ij")
    idx = lambda p, q: (p % n) * (2 * n) + (q % (2 * n))               # noqa: E731
    Q = np.column_stack([idx(i, j).ravel(), idx(i, j + 1).ravel(), idx(i + 1, j + 1).ravel(),
                         idx(i + 1, j).ravel()])
    return V, Q


@pytest.mark.parametrize("ext", [".ply", ".vtp"])
def test_curvature_of_quad_files_converges(tmp_path, ext):
    """Quad meshes read from files (binary PLY: numpy; VTP: pyvista) and split by the fan
    rule give HHJ vertex curvatures that converge to Walker's torus at the drop-in's rate
    (EOC >= 0.9 on the finest pair, as tests/hhj/test_curvature.py asks of triangle meshes)."""
    import igl_hhj
    from igl_hhj.convergence import eoc, vertex_errors
    from igl_hhj.surfaces.exact import WalkerTorus
    errs = []
    for n in (8, 16, 32, 64):
        V, Q = _walker_torus_quads(n)
        path = tmp_path / f"torus{n}{ext}"
        if ext == ".ply":
            _write_ply_binary(path, V, Q)
        else:
            pv = require_test_extra("pyvista")
            pv.PolyData(V, np.column_stack([np.full(len(Q), 4), Q]).ravel()).save(path)
        mf = mesh_io.read_mesh_file(path)
        assert mf.split.corners == {4: len(Q)}
        np.testing.assert_array_equal(mf.F, _fan(Q.tolist()))
        _, _, PV1, PV2, bad = igl_hhj.principal_curvature(mf.V, mf.F)
        assert bad == []
        errs.append(vertex_errors(mf.V, mf.F, PV1, PV2, WalkerTorus()))
    hs = [e["h"] for e in errs]
    for key in ("k1", "k2", "H", "K", "k_inf"):
        r = eoc([e[key] for e in errs], hs)
        assert r[-1] >= 0.9, f"{ext} vertex {key}: EOCs {np.round(r, 3)}"
    assert errs[-1]["k_inf"] < errs[0]["k_inf"] / 8
