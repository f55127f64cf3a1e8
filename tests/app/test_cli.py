"""The ``igl-hhj`` command line: demo, curvature, info; output files; one-line user errors."""
from __future__ import annotations

import os
import subprocess
import sys

import igl
import numpy as np
import pytest
from conftest import MESH_DIR, write_off

from igl_hhj import baselines, cli
from igl_hhj.mesh import TriangleMesh

COLUMNS = ["k1", "k2", "H", "K", "d1x", "d1y", "d1z", "d2x", "d2y", "d2z"]


# --------------------------------------------------------------------------- helpers
def unit_sphere(levels=3):
    V, F = igl.icosahedron()
    for _ in range(levels):
        V, F = igl.upsample(V, F)
        V = V / np.linalg.norm(V, axis=1, keepdims=True)
    return V, F


@pytest.fixture(scope="module")
def sphere(tmp_path_factory):
    """(path, V, F) of a unit sphere (642 vertices, outward normals) written as .off."""
    V, F = unit_sphere()
    path = tmp_path_factory.mktemp("sphere") / "sphere.off"
    igl.write_triangle_mesh(str(path), V, F)
    V, F = igl.read_triangle_mesh(str(path))          # what the CLI sees (ascii round trip)
    return path, V, F


def real_mesh(name):
    path = MESH_DIR / name
    if not path.is_file():
        pytest.skip(f"{path} absent")
    return path


def one_error_line(err):
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, f"expected exactly one stderr line, got {lines!r}"
    assert lines[0].startswith("igl-hhj: error: "), lines[0]
    return lines[0]


def read_ply_properties(path):
    """Minimal binary-little-endian PLY reader: {element: structured array} (lists of 3 only)."""
    raw = path.read_bytes()
    end = raw.index(b"end_header\n") + len(b"end_header\n")
    header = raw[:end].decode("ascii").splitlines()
    assert header[:2] == ["ply", "format binary_little_endian 1.0"]
    types = {"double": "<f8", "float": "<f4", "int": "<i4", "uchar": "u1"}
    elements = []
    for line in header:
        w = line.split()
        if w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property" and w[1] == "list":
            elements[-1][2].extend([("n_" + w[4], types[w[2]]), (w[4], types[w[3]], (3,))])
        elif w[0] == "property":
            elements[-1][2].append((w[2], types[w[1]]))
    out, offset = {}, end
    for name, n, fields in elements:
        dt = np.dtype(fields)
        out[name] = np.frombuffer(raw, dtype=dt, count=n, offset=offset)
        offset += n * dt.itemsize
    assert offset == len(raw)
    return out


# --------------------------------------------------------------------------- demo
def test_demo_table(capsys):
    assert cli.main(["demo", "--levels", "2", "--no-screenshot"]) == 0
    out = capsys.readouterr().out
    assert "HHJ err H" in out and "EOC (last level)" in out and "wrote" not in out
    rows = [line for line in out.splitlines() if line.strip()[:1].isdigit()]
    assert len(rows) == 2


def test_demo_is_headless_safe(tmp_path, monkeypatch, capsys):
    """No EGL: one warning line naming the Debian packages, still exit 0 with the table."""
    from igl_hhj import viewer

    def unavailable(*args, **kwargs):
        raise viewer.ViewerUnavailable("polyscope could not initialise backend 'openGL3_egl': no EGL")
    monkeypatch.setattr(viewer, "register_scalars", unavailable)
    monkeypatch.chdir(tmp_path)
    assert cli.main(["demo", "--levels", "1"]) == 0
    cap = capsys.readouterr()
    assert "HHJ err H" in cap.out
    lines = cap.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("igl-hhj: warning:") and "libegl1" in lines[0]
    assert not (tmp_path / "igl_hhj_demo.png").exists()


def render_or_skip(argv, capsys):
    """Run a screenshot command; skip when EGL is missing outside CI."""
    code = cli.main(argv)
    cap = capsys.readouterr()
    if ("libegl1" in cap.err) and not os.environ.get("CI"):
        pytest.skip("EGL libraries missing (not in CI)")
    return code, cap


@pytest.mark.slow
def test_demo_writes_screenshot(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    code, cap = render_or_skip(["demo", "--levels", "2"], capsys)
    assert code == 0
    png = tmp_path / "igl_hhj_demo.png"
    assert png.stat().st_size > 0 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "igl_hhj_demo.png" in cap.out


def test_demo_rejects_bad_options(tmp_path, capsys):
    assert cli.main(["demo", "--levels", "0"]) == 2
    assert "--levels" in one_error_line(capsys.readouterr().err)
    assert cli.main(["demo", "--screenshot", str(tmp_path / "no" / "x.png")]) == 2
    one_error_line(capsys.readouterr().err)


# --------------------------------------------------------------------------- curvature
@pytest.mark.parametrize("per", ["vertex", "face"])
def test_curvature_outputs_agree_and_reread(sphere, tmp_path, capsys, per):
    path, V, F = sphere
    n = len(V) if per == "vertex" else len(F)
    outs = {ext: tmp_path / f"k{ext}" for ext in (".npz", ".csv", ".ply")}
    for out in outs.values():
        assert cli.main(["curvature", str(path), "--per", per, "-o", str(out)]) == 0
    assert "median" in capsys.readouterr().out

    d = np.load(outs[".npz"])
    assert set(d.files) == {"k1", "k2", "H", "K", "d1", "d2", "V", "F", "per", "method", "S"}
    assert str(d["per"]) == per and str(d["method"]) == "hhj"
    assert d["S"].shape == (len(F), 3, 3)
    assert d["k1"].shape == (n,) and d["d1"].shape == (n, 3) and d["d2"].shape == (n, 3)
    np.testing.assert_array_equal(d["V"], V)
    np.testing.assert_array_equal(d["F"], F)
    # the library's own values (the CLI is wiring, not a new estimator)
    est = baselines.hhj_vertex(V, F) if per == "vertex" else baselines.hhj_face(V, F)
    np.testing.assert_allclose(d["k1"], est.k1, rtol=1e-10)
    np.testing.assert_allclose(d["K"], est.K, rtol=1e-10)
    # unit sphere, outward normals: +1
    for q in ("k1", "k2", "H", "K"):
        assert abs(np.median(d[q]) - 1.0) < 0.01, q
    assert np.all(np.abs(np.einsum("ij,ij->i", d["d1"], d["d2"])) < 1e-8)

    csv = np.loadtxt(outs[".csv"], delimiter=",", skiprows=1)
    assert outs[".csv"].read_text().splitlines()[0] == ",".join(["index"] + COLUMNS)
    assert csv.shape == (n, 11)
    np.testing.assert_array_equal(csv[:, 0], np.arange(n))
    np.testing.assert_array_equal(csv[:, 1:], np.column_stack([d["k1"], d["k2"], d["H"], d["K"],
                                                               d["d1"], d["d2"]]))

    V2, F2 = igl.read_triangle_mesh(str(outs[".ply"]))
    np.testing.assert_array_equal(V2, V)
    np.testing.assert_array_equal(F2, F)
    ply = read_ply_properties(outs[".ply"])
    assert np.all(ply["face"]["n_vertex_indices"] == 3)
    np.testing.assert_array_equal(ply["face"]["vertex_indices"], F)
    table = ply[per]
    for j, c in enumerate(COLUMNS):
        np.testing.assert_array_equal(table[c], csv[:, 1 + j])
    np.testing.assert_array_equal(table["quality"], d["H"])             # MeshLab's quality = H (--quantity)
    other = "face" if per == "vertex" else "vertex"
    assert "k1" not in ply[other].dtype.names and "quality" not in ply[other].dtype.names


@pytest.mark.parametrize("method, fn", [("igl", baselines.libigl_quadric), ("heine", baselines.heine)])
def test_curvature_methods_are_the_baselines(sphere, tmp_path, method, fn):
    path, V, F = sphere
    out = tmp_path / "k.npz"
    assert cli.main(["curvature", str(path), "--method", method, "-o", str(out), "-q"]) == 0
    d = np.load(out)
    est = fn(V, F)
    assert "S" not in d.files and str(d["method"]) == method and str(d["per"]) == "vertex"
    np.testing.assert_allclose(d["k1"], est.k1, rtol=1e-10)
    np.testing.assert_allclose(d["H"], est.H, rtol=1e-10)
    assert np.median(d["H"]) > 0                       # outward sphere: positive


def test_curvature_radius(sphere, tmp_path, capsys):
    """--radius is the drop-in's smoothing scale (and libigl's k-ring for --method igl)."""
    path, V, F = sphere
    out = tmp_path / "k.npz"
    assert cli.main(["curvature", str(path), "--radius", "2", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "smoothing scale (--radius): 2" in text and "boundary:" not in text   # closed mesh
    np.testing.assert_allclose(np.load(out)["k1"], baselines.hhj_vertex(V, F, radius=2).k1, rtol=1e-10)
    assert not np.allclose(np.load(out)["k1"], baselines.hhj_vertex(V, F).k1, rtol=0, atol=1e-8)
    assert cli.main(["curvature", str(path), "--per", "face", "--radius", "3", "-o", str(out), "-q"]) == 0
    np.testing.assert_allclose(np.load(out)["k1"], baselines.hhj_face(V, F, smoothing=3).k1, rtol=1e-10)
    assert cli.main(["curvature", str(path), "--method", "igl", "--radius", "3", "-o", str(out), "-q"]) == 0
    np.testing.assert_allclose(np.load(out)["k1"], baselines.libigl_quadric(V, F, radius=3).k1, rtol=1e-10)
    capsys.readouterr()
    for bad in (["--radius", "0"], ["--radius", "-1"], ["--method", "heine", "--radius", "2"]):
        assert cli.main(["curvature", str(path), *bad]) == 2
        assert "--radius" in one_error_line(capsys.readouterr().err)


def test_curvature_sign_follows_orientation(tmp_path):
    V, F = unit_sphere(2)
    path = write_off(tmp_path / "inward.off", V, F[:, ::-1])
    out = tmp_path / "k.npz"
    assert cli.main(["curvature", str(path), "-o", str(out)]) == 0
    assert abs(np.median(np.load(out)["H"]) + 1.0) < 0.05


def test_unreferenced_vertex_is_nan_in_every_format(tmp_path, capsys):
    V, F = unit_sphere(2)
    path = write_off(tmp_path / "extra.off", np.vstack([V, [[5.0, 5.0, 5.0]]]), F)
    for ext in (".csv", ".ply"):
        assert cli.main(["curvature", str(path), "-o", str(tmp_path / f"k{ext}")]) == 0
    assert "1 vertices have no value (NaN): 1 unreferenced" in capsys.readouterr().out
    csv = np.loadtxt(tmp_path / "k.csv", delimiter=",", skiprows=1)
    vert = read_ply_properties(tmp_path / "k.ply")["vertex"]
    assert np.isnan(csv[-1, 1:]).all() and np.isfinite(csv[:-1]).all()
    assert np.isnan(vert["H"][-1]) and np.isfinite(vert["H"][:-1]).all()


def test_curvature_per_face_needs_hhj(sphere, capsys):
    path, _, _ = sphere
    for method in ("igl", "heine"):
        assert cli.main(["curvature", str(path), "--method", method, "--per", "face"]) == 2
        assert "per-vertex" in one_error_line(capsys.readouterr().err)


def test_progress_lines_only_for_large_meshes(sphere, tmp_path, monkeypatch, capsys):
    path, _, _ = sphere
    out = str(tmp_path / "k.csv")
    assert cli.main(["curvature", str(path), "-o", out]) == 0
    assert capsys.readouterr().err == ""
    from igl_hhj.cli import curvature as curvature_command
    monkeypatch.setattr(curvature_command, "LARGE_MESH_FACES", 100)     # what the command reads
    assert cli.main(["curvature", str(path), "-o", out]) == 0
    err = capsys.readouterr().err.splitlines()
    assert [ln[:5] for ln in err] == ["[1/3]", "[2/3]", "[3/3]"]
    assert "HHJ solve" in err[1] and err[1].endswith(" s")
    assert cli.main(["curvature", str(path), "-o", out, "--quiet"]) == 0
    assert capsys.readouterr().err == ""


def test_output_errors_come_before_computing(sphere, tmp_path, monkeypatch, capsys):
    path, _, _ = sphere

    def must_not_run(*args, **kwargs):
        raise AssertionError("computed before checking the output")
    monkeypatch.setattr(baselines, "estimate", must_not_run)
    from igl_hhj.cli import curvature as curvature_command
    monkeypatch.setattr(curvature_command, "_read", must_not_run)       # the name the command calls
    for out in ["/nonexistent/dir/x.npz", str(tmp_path / "x.txt"), str(tmp_path)]:
        assert cli.main(["curvature", str(path), "-o", out]) == 2
        one_error_line(capsys.readouterr().err)
    assert cli.main(["curvature", str(path), "--screenshot", "/nonexistent/dir/x.png"]) == 2
    one_error_line(capsys.readouterr().err)
    assert list(tmp_path.iterdir()) == []                 # the write probe leaves nothing behind


def test_failed_run_keeps_existing_output(tmp_path, capsys):
    bad = write_off(tmp_path / "nm.off", *NONMANIFOLD)
    out = tmp_path / "k.csv"
    out.write_text("previous results\n")
    assert cli.main(["curvature", str(bad), "-o", str(out), "--strict"]) == 2
    one_error_line(capsys.readouterr().err)
    assert out.read_text() == "previous results\n"


@pytest.mark.slow
def test_curvature_real_mesh_with_boundary(tmp_path, capsys):
    path = real_mesh("camelhead.off")
    out = tmp_path / "camel.csv"
    assert cli.main(["curvature", str(path), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "56 boundary edges" in text
    assert text.count("boundary: clamped with estimated normals") == 1
    V, F = igl.read_triangle_mesh(str(path))
    csv = np.loadtxt(out, delimiter=",", skiprows=1)
    assert csv.shape == (len(V), 11) and np.isfinite(csv).all()
    np.testing.assert_allclose(csv[:, 1], baselines.hhj_vertex(V, F).k1, rtol=1e-12, atol=1e-12)


def test_curvature_real_mesh_per_face_ply(tmp_path):
    path = real_mesh("fandisk.off")
    out = tmp_path / "fandisk.ply"
    assert cli.main(["curvature", str(path), "--per", "face", "-o", str(out)]) == 0
    V, F = igl.read_triangle_mesh(str(path))
    V2, F2 = igl.read_triangle_mesh(str(out))
    np.testing.assert_array_equal(F2, F)
    np.testing.assert_allclose(V2, V, rtol=0, atol=0)
    ply = read_ply_properties(out)
    assert len(ply["face"]) == len(F) and np.isfinite(ply["face"]["H"]).all()


def test_curvature_screenshot(sphere, tmp_path, capsys):
    path, _, _ = sphere
    png = tmp_path / "sphere.png"
    code, cap = render_or_skip(["curvature", str(path), "--screenshot", str(png)], capsys)
    assert code == 0 and png.stat().st_size > 0 and str(png) in cap.out


def test_screenshots_are_annotated_full_colour_pngs(sphere, tmp_path, monkeypatch, capsys):
    """Issue 26 (1): ``igl-hhj demo`` and ``curvature --screenshot`` write the annotated
    picture (title at the top, colour bar with range and unit below), as full-colour RGB
    PNGs (a 256-colour palette banded smooth fields)."""
    from PIL import Image
    monkeypatch.chdir(tmp_path)
    path, _, _ = sphere
    code, _ = render_or_skip(["curvature", str(path), "--screenshot", "c.png", "--size", "400", "300"], capsys)
    assert code == 0
    code, _ = render_or_skip(["demo", "--levels", "2", "--size", "600", "300"], capsys)
    assert code == 0
    for png in ("c.png", "igl_hhj_demo.png"):
        im = Image.open(png)
        assert im.mode == "RGB", png
        rgb = np.asarray(im.convert("RGB"), dtype=float) / 255
        text = (rgb.max(axis=2) < 0.35) & (np.ptp(rgb, axis=2) < 0.05)     # dark grey: text, not the mesh
        h = len(rgb)
        assert text[: h // 4].any(), png           # the title at the top
        assert text[-h // 8:].any(), png           # the colour bar's tick labels at the bottom
    from igl_hhj import viewer
    assert viewer.LONG_LABELS["H"].endswith(f"[{viewer.LENGTH_UNIT}]")


def test_screenshot_without_matplotlib_warns_and_keeps_a_colour_bar(sphere, tmp_path, monkeypatch, capsys):
    """The annotation warning used to be written into the captured EGL chatter and lost;
    now it is one ``igl-hhj: warning:`` line, and polyscope draws its own colour bar."""
    import warnings
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    path, _, _ = sphere
    png = tmp_path / "plain.png"
    code, cap = render_or_skip(["curvature", str(path), "--screenshot", str(png),
                                "--size", "400", "300"], capsys)
    assert code == 0 and png.stat().st_size > 0, cap.err
    assert "igl-hhj: warning: matplotlib is not installed" in cap.err and "pip install matplotlib" in cap.err
    monkeypatch.delitem(sys.modules, "matplotlib")
    from PIL import Image
    rgb = np.asarray(Image.open(png).convert("RGB"), dtype=int)
    # the unit sphere is red everywhere (H = 1 > 0): blue pixels come from polyscope's coolwarm bar
    assert ((rgb[..., 2] - rgb[..., 0]) > 60).sum() > 100
    # a warning inside any captured call is shown afterwards, not lost
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        with pytest.warns(UserWarning, match="held back"):
            assert cli._common._quietly(lambda: warnings.warn("held back") or 7) == 7


def test_curvature_view_registers_the_estimate(sphere, monkeypatch, capsys):
    from igl_hhj import viewer
    calls = []
    monkeypatch.setattr(viewer, "register_curvature", lambda V, F, **kw: calls.append((len(V), len(F), kw)))
    monkeypatch.setattr(viewer, "show", lambda: calls.append("show"))
    path, V, F = sphere
    assert cli.main(["curvature", str(path), "--per", "face", "--view"]) == 0
    (nv, nf, kw), shown = calls
    assert (nv, nf) == (len(V), len(F)) and shown == "show"
    assert kw["name"] == "sphere" and kw["estimate"].location == "face" and kw["robust"] == 1.0
    assert kw["enabled"] == "H" and kw["view"] == "auto"
    calls.clear()
    assert cli.main(["curvature", str(path), "--view", "--quantity", "K", "--camera", "1,0,-2"]) == 0
    assert calls[0][2]["enabled"] == "K" and calls[0][2]["view"] == (1.0, 0.0, -2.0)
    for bad in ("0,0,0", "up", "1,2"):
        assert cli.main(["curvature", str(path), "--camera", bad]) == 2
        assert "--camera" in one_error_line(capsys.readouterr().err)


def test_viewer_unavailable_is_a_user_error(sphere, tmp_path, monkeypatch, capsys):
    from igl_hhj import viewer

    def unavailable(*args, **kwargs):
        raise viewer.ViewerUnavailable("no EGL\nsecond line")
    monkeypatch.setattr(viewer, "register_curvature", unavailable)
    path, _, _ = sphere
    assert cli.main(["curvature", str(path), "--screenshot", str(tmp_path / "x.png")]) == 2
    assert "libegl1" in one_error_line(capsys.readouterr().err)
    assert cli.main(["curvature", str(path), "--view"]) == 2
    assert "--screenshot" in one_error_line(capsys.readouterr().err)


# --------------------------------------------------------------------------- info
def info(path, capsys):
    code = cli.main(["info", str(path)])
    cap = capsys.readouterr()
    rows = {}
    for line in cap.out.splitlines()[1:]:
        key, _, value = line.strip().partition("  ")
        rows[key.strip()] = value.strip()
    return code, rows, cap


def test_info_sphere(sphere, capsys):
    path, V, F = sphere
    code, rows, cap = info(path, capsys)
    assert code == 0 and cap.err == ""
    assert rows["vertices"] == f"{len(V)} (0 unreferenced)" and rows["faces"] == str(len(F))
    assert rows["edges"] == f"{len(V) + len(F) - 2} (0 on the boundary)"    # Euler: V - E + F = 2
    assert rows["components"] == "1" and rows["boundary loops"] == "0"
    assert rows["Euler char."] == "2" and rows["genus"] == "0"
    assert rows["edge-manifold"] == "yes" and rows["vertex-manifold"] == "yes"
    assert rows["orientation"] == "consistent, orientable"
    assert rows["degenerate faces"] == "0 zero-area or sliver, 0 with a repeated vertex"
    assert rows["verdict"] == "accepted by igl_hhj"


def test_info_torus_and_two_components(tmp_path, capsys):
    from igl_hhj.surfaces import torus_coarse
    V, F = torus_coarse(n_phi=12, n_t=6, amount=0.0)
    code, rows, _ = info(write_off(tmp_path / "torus.off", V, F), capsys)
    assert code == 0 and rows["genus"] == "1" and rows["Euler char."] == "0"
    # a hole (one face removed) adds a boundary loop, keeps the genus: χ = 2 - 2g - b
    code, rows, _ = info(write_off(tmp_path / "holed.off", V, F[1:]), capsys)
    assert code == 0 and rows["boundary loops"] == "1 (edges per loop: 3)"
    assert rows["Euler char."] == "-1" and rows["genus"] == "1"
    V, F = unit_sphere(1)
    two = write_off(tmp_path / "two.off", np.vstack([V, V + 3]), np.vstack([F, F + len(V)]))
    code, rows, _ = info(two, capsys)
    assert code == 0 and rows["components"] == "2" and rows["genus"] == "0 (per component: 0, 0)"


def test_info_real_meshes(capsys):
    path = real_mesh("camelhead.off")
    code, rows, _ = info(path, capsys)
    mesh = TriangleMesh(*igl.read_triangle_mesh(str(path)))
    loops = sorted((len(lp) for lp in mesh.boundary_loops), reverse=True)    # libigl's loops
    assert code == 0 and len(loops) >= 1
    assert rows["boundary loops"] == f"{len(loops)} (edges per loop: {', '.join(map(str, loops))})"
    assert rows["genus"] == "0"
    path = real_mesh("fertility.off")
    code, rows, _ = info(path, capsys)
    assert code == 0 and rows["genus"] == "4" and rows["boundary loops"] == "0"


NONMANIFOLD = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1.0]]),
               np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]]))                # three faces on edge 0-1
DEGENERATE = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0.0]]),
              np.array([[0, 1, 2], [0, 3, 1]]))                            # face 1 is collinear
FLIPPED = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]]),
           np.array([[0, 1, 2], [1, 2, 3]]))                               # both traverse 1 -> 2


def moebius(n=8, w=0.3):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    V = np.vstack([np.c_[(1 + s * np.cos(t / 2)) * np.cos(t), (1 + s * np.cos(t / 2)) * np.sin(t),
                         s * np.sin(t / 2)] for s in (-w, w)])
    i = np.arange(n)
    j = (i + 1) % n
    a1 = np.where(j == 0, n, j)                       # the seam swaps the two rims
    b1 = np.where(j == 0, 0, j + n)
    return V, np.vstack([np.c_[i, a1, i + n], np.c_[i + n, a1, b1]])


@pytest.mark.parametrize("mesh, row, value", [
    (NONMANIFOLD, "edge-manifold", "no (1 edges with more than two faces)"),
    (DEGENERATE, "degenerate faces", "1 zero-area or sliver, 0 with a repeated vertex"),
    (FLIPPED, "orientation", "inconsistent (1 edges traversed twice in the same direction), orientable"),
    (moebius(), "genus", "not defined: non-orientable"),
], ids=["nonmanifold", "degenerate", "flipped", "moebius"])
def test_info_rejected_meshes(tmp_path, capsys, mesh, row, value, request):
    path = write_off(tmp_path / "m.off", *mesh)
    with pytest.raises(ValueError) as exc:
        TriangleMesh(*igl.read_triangle_mesh(str(path)))
    code, rows, cap = info(path, capsys)
    assert code == 1 and cap.err == ""
    assert rows[row] == value
    assert rows["verdict"] == f"rejected: {exc.value}"
    assert rows["drop-in repairs"].startswith(REPAIRS[request.node.callspec.id])


REPAIRS = {   # what `info` says the drop-in's repair does (issue 24)
    "nonmanifold": "2 vertex copies made to split non-manifold edges/vertices; principal_curvature "
                   "computes on the repaired mesh",
    "degenerate": "1 degenerate (zero-area or sliver) faces dropped; 1 vertices left without a face",
    "flipped": "1 faces re-oriented to the majority orientation of their patch; principal_curvature",
    "moebius": "16 faces of non-orientable (Möbius) patches removed; 16 vertices left without a face "
               "(NaN); no face left",
}


def test_info_accepted_and_unrepairable_repair_rows(sphere, tmp_path, capsys):
    path, _, _ = sphere
    assert info(path, capsys)[1]["drop-in repairs"] == "none needed"
    V, F = DEGENERATE
    path = write_off(tmp_path / "tiny.off", V * 1e-62, F)       # too small comes first: no repair
    code, rows, _ = info(path, capsys)
    assert code == 1 and rows["drop-in repairs"] == "none possible (the drop-in refuses it too)"
    assert rows["verdict"].startswith("rejected: the mesh is too small")
    path = write_off(tmp_path / "tiny2.off", FLIPPED[0] * 1e-62, FLIPPED[1])   # refused before
    assert info(path, capsys)[1]["drop-in repairs"] == "none possible (the drop-in refuses it too)"


def test_info_mesh_with_bad_indices_is_rejected_not_crashed(tmp_path, capsys):
    path = tmp_path / "oor.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    code, rows, _ = info(path, capsys)
    assert code == 1 and rows["topology"].startswith("not analysed")
    assert rows["verdict"].startswith("rejected: F has out-of-range vertex indices")


def test_info_stl_vertices_are_welded(tmp_path, capsys):
    V, F = unit_sphere(1)
    path = tmp_path / "s.stl"
    igl.write_triangle_mesh(str(path), V, F)
    code, rows, cap = info(path, capsys)
    assert code == 0 and rows["vertices"] == f"{len(V)} (0 unreferenced)" and rows["genus"] == "0"
    assert "merged coincident STL vertices" in cap.err


@pytest.mark.slow
def test_info_subprocess_exit_codes(sphere, tmp_path):
    path, _, _ = sphere
    run = subprocess.run([sys.executable, "-m", "igl_hhj.cli", "info", str(path)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and "accepted by igl_hhj" in run.stdout and run.stderr == ""
    bad = write_off(tmp_path / "nm.off", *NONMANIFOLD)
    run = subprocess.run([sys.executable, "-m", "igl_hhj.cli", "info", str(bad)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 1 and "rejected: mesh has non-manifold edges" in run.stdout


# --------------------------------------------------------------------------- bad input
BAD_FILES = {
    "missing.off": None,
    "empty.off": b"",
    "garbage.off": b"OFF\nfoo bar\n",
    "random.off": bytes(range(256)) * 4,
    "garbage.obj": b"hello world\n",
    "points.xyz": b"1 2 3\n",
    "no_faces.off": b"OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n",
    "huge_counts.off": b"OFF\n100000000 1 0\n0 0 0\n",                         # libigl: 5 GB
    "truncated.off": b"OFF\n3 1 0\n0 0 0\n1 0 0\n",
    # libigl: endless loop
    "huge_counts.ply": (b"ply\nformat binary_little_endian 1.0\nelement vertex 100000000000\n"
                        b"property float x\nproperty float y\nproperty float z\nend_header\n"),
    "short_faces.ply": (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        b"property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                        b"end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),           # libigl: double free
    # (a PLY of mixed triangles and quads, on which libigl aborts, is read with numpy since
    # issue 26: tests/io/test_polygon_io.py)
    "short_quad.ply": (b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                       b"property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                       b"end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n3 0 1 2\n4 0 1 2\n"),
    "garbage.stl": bytes(range(256)) + b"solid",
    "garbage.mesh": b"garbage",
}


@pytest.mark.parametrize("command", ["curvature", "info"])
@pytest.mark.parametrize("name", sorted(BAD_FILES))
def test_bad_files_give_one_line(tmp_path, capfd, command, name):
    """capfd: libigl's own C/C++ messages on file descriptors 1/2 must not leak either."""
    path = tmp_path / name
    if BAD_FILES[name] is not None:
        path.write_bytes(BAD_FILES[name])
    assert cli.main([command, str(path)]) == cli.EXIT_UNREADABLE
    cap = capfd.readouterr()
    assert str(path) in one_error_line(cap.err)
    assert cap.out == ""


def test_directory_and_unreadable_file(tmp_path, capsys):
    folder = tmp_path / "folder.off"
    folder.mkdir()
    assert cli.main(["info", str(folder)]) == cli.EXIT_UNREADABLE
    assert "directory" in one_error_line(capsys.readouterr().err)
    if hasattr(os, "geteuid") and os.geteuid() != 0:       # root reads everything
        locked = write_off(tmp_path / "locked.off", *FLIPPED)
        locked.chmod(0)
        assert cli.main(["curvature", str(locked)]) == cli.EXIT_UNREADABLE
        assert "cannot read" in one_error_line(capsys.readouterr().err)


@pytest.mark.parametrize("mesh, match", [(NONMANIFOLD, "non-manifold"), (DEGENERATE, "degenerate"),
                                         (FLIPPED, "not consistently oriented")])
def test_curvature_bad_mesh_is_one_line(tmp_path, capsys, mesh, match):
    """--strict refuses what the drop-in repairs (without it: tests/app/test_cli_parity.py)."""
    path = write_off(tmp_path / "bad.off", *mesh)
    assert cli.main(["curvature", str(path), "--strict"]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert match in line and "igl-hhj info" in line and "--strict" in line


def test_usage_errors_are_one_line(capsys):
    assert cli.main([]) == 2
    one_error_line(capsys.readouterr().err)
    assert cli.main(["curvature", "x.off", "--per", "edge"]) == 2
    assert "invalid choice" in one_error_line(capsys.readouterr().err)
    assert cli.main(["curvature", "x.off", "--robust", "50"]) == 2
    assert "--robust" in one_error_line(capsys.readouterr().err)
    assert cli.main(["curvature", "--help"]) == 0
    assert "--method" in capsys.readouterr().out


@pytest.mark.slow
def test_demo_without_egl_end_to_end(tmp_path):
    """A real process whose libEGL cannot be loaded (shadowed by an empty file):
    the table, one warning line naming the Debian packages, exit 0, no picture,
    no polyscope chatter and no crash."""
    for lib in ("libEGL.so", "libEGL.so.1"):
        (tmp_path / lib).write_bytes(b"")
    env = dict(os.environ, LD_LIBRARY_PATH=str(tmp_path))
    out = subprocess.run([sys.executable, "-m", "igl_hhj.cli", "demo", "--levels", "1",
                          "--screenshot", str(tmp_path / "d.png")],
                         capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "HHJ err H" in out.stdout
    err = out.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("igl-hhj: warning: no screenshot") and "libegl1" in err[0]
    assert not (tmp_path / "d.png").exists()


# --------------------------------------------------------------------------- packaging hygiene (issue 14)
def test_version(capsys):
    import igl_hhj
    assert cli.main(["--version"]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"igl-hhj {igl_hhj.__version__} ") and "libigl 2.6" in out


def test_quiet_silences_the_summary(sphere, tmp_path, capsys):
    path, _, _ = sphere
    out = tmp_path / "k.npz"
    assert cli.main(["curvature", str(path), "-o", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    out.unlink()
    assert cli.main(["curvature", str(path), "-o", str(out), "-q"]) == 0
    cap = capsys.readouterr()
    assert cap.out == "" and cap.err == "" and out.exists()


def test_named_demo_help_and_bad_name(capsys):
    from igl_hhj.demos import DEMOS
    for name in DEMOS:
        assert cli.main(["demo", name, "--help"]) == 0
        out = capsys.readouterr().out
        assert out.startswith(f"usage: igl-hhj demo {name}") and "What you see" in out
    assert cli.main(["demo", "nosuch"]) == 2
    assert "invalid choice" in one_error_line(capsys.readouterr().err)
    assert cli.main(["demo", "regge", "--levels", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("igl-hhj demo regge: error: --levels")


@pytest.mark.slow
@pytest.mark.parametrize("argv", [["demo", "--levels", "1"],
                                  ["demo", "regge", "--levels", "2", "--screenshot", "r.png", "--size", "64", "64"]])
def test_demos_leave_no_files_and_no_egl_chatter(tmp_path, argv):
    """igl-hhj demo [NAME] in a fresh folder: only the picture it announces, no
    imgui.ini / .polyscope.ini, and none of polyscope's '[polyscope] EGL ...' lines."""
    from conftest import require_egl
    require_egl()
    res = subprocess.run([sys.executable, "-m", "igl_hhj.cli", *argv], cwd=tmp_path, capture_output=True,
                         text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-2000:]
    assert sorted(p.name for p in tmp_path.iterdir()) == [("r.png" if "regge" in argv else "igl_hhj_demo.png")]
    assert "[polyscope]" not in res.stdout + res.stderr, res.stdout + res.stderr


def test_output_that_is_the_input_is_refused(sphere, tmp_path, capsys):
    """``curvature in.ply -o in.ply`` used to overwrite the mesh with its curvature."""
    _, V, F = sphere
    mesh_path = tmp_path / "in.ply"
    igl.write_triangle_mesh(str(mesh_path), V, F)
    before = mesh_path.read_bytes()
    link = tmp_path / "link.ply"
    link.symlink_to(mesh_path)
    for out in (mesh_path, link, tmp_path / "." / "in.ply"):
        assert cli.main(["curvature", str(mesh_path), "-o", str(out)]) == 2
        assert "is the input mesh itself" in one_error_line(capsys.readouterr().err)
    assert mesh_path.read_bytes() == before


def test_empty_output_path_is_a_usage_error(sphere, capsys):
    path, _, _ = sphere
    assert cli.main(["curvature", str(path), "-o", ""]) == 2
    assert "empty output path" in one_error_line(capsys.readouterr().err)


@pytest.mark.parametrize("extra", [[], ["--method", "igl"], ["--per", "face"]])
def test_huge_radius_is_a_usage_error(sphere, capsys, extra):
    """--radius 10**300 used to exit 70 (internal error: OverflowError)."""
    path, _, _ = sphere
    assert cli.main(["curvature", str(path), "--radius", str(10**300)] + extra) == 2
    assert "--radius must be at most 1000000" in one_error_line(capsys.readouterr().err)


def test_install_hints_work_from_a_checkout(capsys):
    """Issue 26 (8): hints said ``pip install "igl-hhj[io]"``, which pip looks up on the
    package index (no such release) instead of the checkout; they name ``.[extra]`` and
    the package itself now, and a missing optional package is a user error (exit 2)."""
    from pathlib import Path

    from igl_hhj.errors import install_hint, missing_optional
    assert install_hint("gpytoolbox") == 'pip install gpytoolbox (in a checkout of igl-hhj: pip install ".[demos]")'
    assert install_hint("distributed").startswith('pip install "dask[distributed]"')
    assert missing_optional(ModuleNotFoundError("x", name="triangle")) == "triangle"
    assert missing_optional(ModuleNotFoundError("x", name="igl_hhj.nothing")) is None
    code, message = cli.program._failure(ModuleNotFoundError("No module named 'meshio'", name="meshio"))
    assert code == 2 and 'pip install ".[io]"' in message
    assert cli.program._failure(ModuleNotFoundError("No module named 'igl_hhj.x'", name="igl_hhj.x"))[0] == 70
    root = Path(cli.__file__).resolve().parents[1]          # the igl_hhj package
    stale = [str(p.relative_to(root)) for p in root.rglob("*.py") if "igl-hhj[" in p.read_text()]
    assert stale == []
