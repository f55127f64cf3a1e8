"""``igl-hhj view RESULT`` and :func:`igl_hhj.viewer.register_result` (issue 26, item 6):
every result ``curvature -o`` writes with its mesh re-opens with the stored values as
the registered quantities (checked under polyscope's mock backend), the file's own
quantity shown first; ``--screenshot`` renders headless."""
from __future__ import annotations

import numpy as np
import polyscope as ps
import pytest
from conftest import png_stats, require_egl, require_test_extra

from igl_hhj import cli, mesh_io, viewer

LABELS = {"k1": "kappa1", "k2": "kappa2", "H": "mean H", "K": "Gauss K"}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """``igl-hhj curvature -o`` outputs of a jittered ellipsoid, hhj per vertex and per
    face and igl per vertex, with the values they hold (the .npz, read with numpy)."""
    from igl_hhj.surfaces import Ellipsoid, ellipsoid_coarse
    from igl_hhj.surfaces.meshing import jitter_tangentially
    d = tmp_path_factory.mktemp("view")
    s = Ellipsoid()
    V, F = ellipsoid_coarse(s, subdivisions=2)
    V = jitter_tangentially(V, F, s, 0.2, seed=5)
    mesh = d / "ell.off"
    with open(mesh, "w") as fh:
        fh.write(f"OFF\n{len(V)} {len(F)} 0\n")
        np.savetxt(fh, V, fmt="%.17g")
        np.savetxt(fh, np.column_stack([np.full(len(F), 3), F]), fmt="%d")
    out = {}
    for method, per, quantity in (("hhj", "vertex", "K"), ("hhj", "face", "k2"), ("igl", "vertex", "H")):
        ref = d / f"{method}_{per}.npz"
        assert cli.main(["curvature", str(mesh), "-q", "--method", method, "--per", per, "-o", str(ref)]) == 0
        for ext in mesh_io.RESULT_EXTENSIONS:
            path = d / f"{method}_{per}{ext}"
            if ext != ".npz":
                assert cli.main(["curvature", str(mesh), "-q", "--method", method, "--per", per,
                                 "--quantity", quantity, "-o", str(path)]) == 0
            out[method, per, ext] = path, quantity, np.load(ref)
    return out


@pytest.fixture
def mock():
    viewer.init("openGL_mock")
    yield ps
    ps.remove_all_structures()


def test_every_result_reopens_with_its_stored_quantities(mock, results):
    require_test_extra("pyvista")                     # .vtp is read with pyvista
    for (method, per, ext), (path, quantity, ref) in results.items():
        reg = viewer.register_result(path)
        where = "vertices" if per == "vertex" else "faces"
        tag = {"hhj": "HHJ", "igl": "libigl"}[method] if ext in (".npz", ".ply") else "stored"
        name = path.stem
        want = [f"{LABELS[q]} ({tag} {where})" for q in LABELS] + [f"PD{i} ({tag} {where})" for i in (1, 2)]
        assert reg.names(name) == want, (path.name, reg.names(name))
        for q in LABELS:
            info = reg.quantities[(name, f"{LABELS[q]} ({tag} {where})")]
            np.testing.assert_array_equal(info.values, ref[q], err_msg=f"{path.name} {q}")
            assert info.defined_on == where
        line = reg.quantities[(name, f"PD1 ({tag} {where})")]
        assert line.kind == "line" and line.values.shape == (len(ref["k1"]), 3)
        # the direction field is d1 scaled by the local edge length: parallel to the stored d1
        cos = np.abs(np.sum(line.values * ref["d1"], axis=1)) / np.linalg.norm(line.values, axis=1)
        np.testing.assert_allclose(cos[np.isfinite(cos)], 1.0, rtol=0, atol=1e-12, err_msg=path.name)
        shown = "H" if ext == ".npz" else quantity          # the .npz does not record a quantity
        assert [k for k, i in reg.quantities.items() if i.enabled] == [(name, f"{LABELS[shown]} ({tag} {where})")]
        assert reg.titles[name].startswith(f"{path.name}: ")
        ps.remove_all_structures()
    reg = viewer.register_result(results["hhj", "vertex", ".ply"][0], enabled="k1", name="again")
    assert [k for k, i in reg.quantities.items() if i.enabled] == [("again", "kappa1 (HHJ vertices)")]


def test_cli_view_opens_the_window(mock, results, monkeypatch, capsys):
    shown = []
    monkeypatch.setattr(viewer, "show", lambda **kw: shown.append(ps.has_surface_mesh("hhj_face")))
    path = results["hhj", "face", ".ply"][0]
    assert cli.main(["view", str(path)]) == 0
    assert shown == [True]
    out = capsys.readouterr().out
    assert out.startswith(f"{path}: ") and "k1, k2, H, K, d1, d2 per face (method hhj)" in out
    assert cli.main(["view", str(results["hhj", "face", ".npz"][0]), "-q"]) == 0
    assert capsys.readouterr().out == ""


def test_cli_view_errors(results, tmp_path, capsys):
    csv = tmp_path / "x.csv"
    csv.write_text("index,k1\n0,1\n")
    assert cli.main(["view", str(csv)]) == cli.EXIT_UNREADABLE
    assert "a .csv holds no mesh" in capsys.readouterr().err
    plain = tmp_path / "plain.off"
    plain.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    assert cli.main(["view", str(plain)]) == cli.EXIT_UNREADABLE
    assert "cannot re-open a .off file" in capsys.readouterr().err
    ply = tmp_path / "plain.ply"
    ply.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
                   "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    assert cli.main(["view", str(ply)]) == cli.EXIT_UNREADABLE
    err = capsys.readouterr().err
    assert "no curvature arrays k1, k2, H, K per face" in err and "igl-hhj curvature MESH -o OUT" in err
    assert cli.main(["view", str(tmp_path / "missing.npz")]) == cli.EXIT_UNREADABLE
    assert "no such file" in capsys.readouterr().err
    bad = tmp_path / "bad.npz"
    np.savez(bad, H=np.zeros(3))
    assert cli.main(["view", str(bad)]) == cli.EXIT_UNREADABLE
    assert "no arrays V and F" in capsys.readouterr().err
    path = results["hhj", "vertex", ".npz"][0]
    assert cli.main(["view", str(path), "--screenshot", str(tmp_path / "x.jpg")]) == cli.EXIT_USAGE
    assert "unknown image extension" in capsys.readouterr().err


def test_cli_view_screenshot(results, tmp_path, capsys):
    require_egl()
    path = results["hhj", "vertex", ".ply"][0]            # written with --quantity K: K > 0 is red
    png = tmp_path / "view.png"
    assert cli.main(["view", str(path), "--screenshot", str(png), "--size", "480", "360"]) == 0
    stats = png_stats(png)
    assert (stats["width"], stats["height"]) == (480, 360)
    assert stats["foreground"] > 0.2 and stats["red"] > 5 * stats["blue"]     # K > 0 on the ellipsoid
    ps.remove_all_structures()
