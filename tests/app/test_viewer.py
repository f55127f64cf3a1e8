"""igl_hhj.viewer: registration (polyscope's mock backend) and real headless renders (EGL).

The mock tests check what is registered (names, element counts, colour
ranges) both in the returned Registration and in polyscope's own buffers.
The render tests draw with ``openGL3_egl`` and check the PNG: requested size,
not blank, and coloured by the quantity (the structures are grey without one).
They skip only when EGL is missing and ``$CI`` is unset (conftest.require_egl).
"""
import subprocess
import sys

import numpy as np
import pytest

from conftest import png_stats, require_egl
from igl_hhj.surfaces.exact import Ellipsoid, Sphere
from igl_hhj.surfaces.meshing import ellipsoid_coarse, icosphere, jitter_tangentially, refine

ps = pytest.importorskip("polyscope")

from igl_hhj import viewer  # noqa: E402
from igl_hhj.viewer import backend, render  # noqa: E402  (package-private names the tests inspect)

CURV = ("kappa1", "kappa2", "mean H", "Gauss K")


@pytest.fixture(scope="module")
def ellipsoid():
    s = Ellipsoid()
    V, F = ellipsoid_coarse(s, subdivisions=1)
    return refine(V, F, s, 2)


@pytest.fixture(scope="module")
def sphere():
    s = Sphere()
    V, F = icosphere(3)
    return jitter_tangentially(V, F, s, 0.2, seed=3), F


@pytest.fixture
def mock():
    viewer.init("openGL_mock")
    yield ps
    ps.remove_all_structures()


@pytest.fixture
def egl():
    require_egl()
    viewer.init("openGL3_egl")
    yield ps
    ps.remove_all_structures()


def _buffer_size(sname, qname):
    return ps.get_surface_mesh(sname).get_quantity_buffer(qname, "values").size()


# --------------------------------------------------------------------------- registration (mock)
def test_register_curvature_faces_and_vertices(mock, ellipsoid):
    V, F = ellipsoid
    reg = viewer.register_curvature(V, F, name="ell", enabled="k2", robust=None)   # full range
    assert list(reg.structures) == ["ell"] and ps.has_surface_mesh("ell")
    for lab in CURV:
        for where, n in (("faces", len(F)), ("vertices", len(V))):
            info = reg.quantities[("ell", f"{lab} (HHJ {where})")]
            assert info.kind == "scalar" and info.defined_on == where and info.values.shape == (n,)
            assert _buffer_size("ell", f"{lab} (HHJ {where})") == n
    # the face and vertex values of one curvature share one symmetric range that contains them all
    for q, lab in zip(viewer.QUANTITIES, CURV):
        lo, hi = reg.ranges[q]
        assert lo == -hi > -np.inf and hi > 0
        for where in ("faces", "vertices"):
            info = reg.quantities[("ell", f"{lab} (HHJ {where})")]
            assert info.vminmax == (lo, hi)
            assert np.nanmax(np.abs(info.values)) == pytest.approx(hi, rel=1e-12) or \
                np.nanmax(np.abs(info.values)) < hi
    assert max(np.nanmax(np.abs(reg.quantities[("ell", f"kappa1 (HHJ {w})")].values))
               for w in ("faces", "vertices")) == pytest.approx(reg.ranges["k1"][1])
    enabled = [k for k, q in reg.quantities.items() if q.enabled]
    assert enabled == [("ell", "kappa2 (HHJ faces)")]


def test_directions_are_tangent_and_scaled_by_local_edge_length(mock, ellipsoid):
    V, F = ellipsoid
    reg = viewer.register_curvature(V, F, name="ell", per="face", direction_scale=0.4, show_directions=True)
    from igl_hhj.mesh import TriangleMesh
    mesh = TriangleMesh(V, F)
    lf = viewer.local_edge_length(mesh, "face")
    for lab in ("PD1", "PD2"):
        d = reg.quantities[("ell", f"{lab} (HHJ faces)")]
        assert d.kind == "line" and d.values.shape == (len(F), 3) and d.enabled
        np.testing.assert_allclose(np.linalg.norm(d.values, axis=1), 0.4 * lf, rtol=1e-10)
        assert np.abs(np.einsum("ij,ij->i", d.values, mesh.face_normals)).max() < 1e-10 * lf.max()
    lv = viewer.local_edge_length(mesh, "vertex")
    assert lv.shape == (len(V),) and lv.min() > 0
    # a vertex's mean incident edge length lies between its shortest and longest incident edge
    assert lv.max() <= mesh.unique_edge_lengths.max() and lv.min() >= mesh.unique_edge_lengths.min()


def test_register_curvature_methods_and_robust_range(mock, ellipsoid):
    V, F = ellipsoid
    full = viewer.register_curvature(V, F, method="igl", name="igl")
    assert {q for _, q in full.quantities} >= {f"{lab} (libigl vertices)" for lab in CURV}
    assert all(q.defined_on == "vertices" for q in full.quantities.values())
    rob = viewer.register_curvature(V, F, method="heine", name="heine", robust=10, symmetric=False)
    k1 = rob.quantities[("heine", "kappa1 (Heine vertices)")].values
    assert rob.ranges["k1"] == pytest.approx(tuple(np.nanpercentile(k1, [10, 90])))
    est = viewer.curvature_estimate(V, F, method="hhj", per="vertex")
    pre = viewer.register_curvature(V, F, est, name="pre", ranges={"H": (-9.0, 9.0)})
    assert pre.quantities[("pre", "mean H (HHJ vertices)")].vminmax == (-9.0, 9.0)


def test_register_comparison_shares_ranges(mock, ellipsoid):
    V, F = ellipsoid
    reg = viewer.register_comparison(V, F, name="cmp", enabled="K")
    assert set(reg.structures) == {"cmp HHJ", "cmp libigl"}
    for q, lab in zip(viewer.QUANTITIES, CURV):
        a = reg.quantities[("cmp HHJ", f"{lab} (HHJ vertices)")]     # like with like: the default
        b = reg.quantities[("cmp libigl", f"{lab} (libigl vertices)")]
        assert a.vminmax == b.vminmax == reg.ranges[q]
        assert reg.ranges[q] == viewer.color_range(a.values, b.values, robust=1.0)   # the default
    assert _buffer_size("cmp libigl", "Gauss K (libigl vertices)") == len(V)
    # the libigl copy is translated along x so the two do not overlap
    width = V[:, 0].max() - V[:, 0].min()
    assert reg.bounds[1, 0] - reg.bounds[0, 0] == pytest.approx(2.15 * width)
    one = viewer.register_comparison(V, F, name="both", layout="quantities")
    assert list(one.structures) == ["both"] and len(one.names("both")) == 12  # 2 × (4 scalars + 2 directions)


def test_register_hessian_biharmonic_regge_scalars(mock, sphere):
    V, F = sphere
    h = viewer.register_hessian(V, F, lambda X: X[:, 2], name="hess")
    tr = h.quantities[("hess", "Hess w trace (surface Laplacian)")].values
    # Δ_Γ z = -2 z on the unit sphere: the face traces correlate with -2 z
    z = V[F].mean(axis=1)[:, 2]
    assert np.corrcoef(tr, -2 * z)[0, 1] > 0.95
    assert h.quantities[("hess", "w")].defined_on == "vertices"
    assert h.ranges["lambda"][0] == -h.ranges["lambda"][1]
    u = V[:, 0] ** 2
    b = viewer.register_biharmonic(V, F, u + 0.01, -u, exact=u, name="bih")
    assert b.quantities[("bih", "u1 (approx. u)")].vminmax == b.quantities[("bih", "u exact")].vminmax
    err = b.quantities[("bih", "error u1 - u")]
    np.testing.assert_allclose(err.values, 0.01)
    assert err.vminmax[0] == -err.vminmax[1]
    r = viewer.register_regge_curvature(V, F, name="regge")
    assert {q for _, q in r.quantities} == {"Regge K_h (vertices)", "angle defect / area (vertices)",
                                            "HHJ Gauss K (faces)"}
    assert len({q.vminmax for q in r.quantities.values()}) == 1
    assert abs(np.nanmedian(r.quantities[("regge", "Regge K_h (vertices)")].values) - 1.0) < 0.05
    s = viewer.register_scalars(V, F, {"x": V[:, 0], "area": np.ones(len(F))}, name="sc", offset=(3, 0, 0))
    assert s.quantities[("sc", "x")].defined_on == "vertices"
    assert s.quantities[("sc", "area")].defined_on == "faces"
    assert s.bounds[0, 0] == pytest.approx(V[:, 0].min() + 3)
    fixed = viewer.register_scalars(V, F, {"x": V[:, 0], "y": V[:, 1]}, name="fx", vminmax=(0, 5))
    assert {q.vminmax for q in fixed.quantities.values()} == {(0.0, 5.0)}
    with pytest.raises(ValueError, match="lo < hi"):
        viewer.register_scalars(V, F, {"x": V[:, 0]}, vminmax=(1, 1))


def test_offsets_and_explicit_ranges(mock, sphere):
    V, F = sphere
    shift = np.array([4.0, -1.0, 0.5])
    regs = [viewer.register_curvature(V, F, name="c", offset=shift),
            viewer.register_hessian(V, F, V[:, 0], name="h", offset=shift),
            viewer.register_biharmonic(V, F, V[:, 0], name="b", offset=shift, ranges={"u1": (-3, 3)}),
            viewer.register_regge_curvature(V, F, name="r", offset=shift, vminmax=(-2, 2))]
    for reg in regs:
        np.testing.assert_allclose(reg.bounds, np.stack([V.min(0), V.max(0)]) + shift)
    assert regs[2].quantities[("b", "u1 (approx. u)")].vminmax == (-3.0, 3.0)
    assert {q.vminmax for q in regs[3].quantities.values()} == {(-2.0, 2.0)}
    with pytest.raises(ValueError, match="offset must be 3 finite numbers"):
        viewer.register_regge_curvature(V, F, offset=(1, 2))
    with pytest.raises(ValueError, match="lo < hi"):
        viewer.register_regge_curvature(V, F, vminmax=(2, -2))
    with pytest.raises(ValueError, match="ranges key must be one of"):
        viewer.register_curvature(V, F, ranges={"k3": (0, 1)})


def test_color_range():
    assert viewer.color_range(np.array([1.0, 2.0]), np.array([3.0]), symmetric=False) == (1.0, 3.0)
    assert viewer.color_range(np.array([1.0, 2.0, 3.0])) == (-3.0, 3.0)
    assert viewer.color_range(np.array([-1.0, 2.0])) == (-2.0, 2.0)
    assert viewer.color_range(np.array([np.nan, np.inf])) == (-1.0, 1.0)
    lo, hi = viewer.color_range(np.zeros(4))
    assert lo < hi
    x = np.concatenate([np.linspace(-1, 1, 99), [1e6]])           # one outlier
    assert viewer.color_range(x)[1] == 1e6
    assert viewer.color_range(x, robust=2)[1] < 1.5


def test_bad_input(mock, ellipsoid, tmp_path):
    V, F = ellipsoid
    with pytest.raises(ValueError, match="enabled must be one of"):
        viewer.register_curvature(V, F, enabled="k3")
    with pytest.raises(ValueError, match="enabled must be one of"):
        viewer.register_comparison(V, F, enabled="k3")
    with pytest.raises(ValueError, match="method must be one of"):
        viewer.register_curvature(V, F, method="cgal")
    with pytest.raises(ValueError, match="per-vertex curvature only"):
        viewer.curvature_estimate(V, F, method="igl", per="face")
    with pytest.raises(ValueError, match="layout must be one of"):
        viewer.register_comparison(V, F, layout="grid")
    with pytest.raises(ValueError, match="robust must be a percentile"):
        viewer.color_range(np.ones(3), robust=60)
    est = viewer.curvature_estimate(V[:10], F[(F < 10).all(axis=1)], per="face") if (F < 10).all(axis=1).any() \
        else viewer.curvature_estimate(*ellipsoid_coarse(subdivisions=0), per="face")
    with pytest.raises(ValueError, match="face values"):
        viewer.register_curvature(V, F, est)
    with pytest.raises(ValueError, match="w must have shape"):
        viewer.register_hessian(V, F, np.ones(3))
    with pytest.raises(ValueError, match="NaN or inf"):
        viewer.register_hessian(V, F, np.full(len(V), np.nan))
    with pytest.raises(ValueError, match="has shape"):
        viewer.register_scalars(V, F, {"x": np.ones(5)})
    with pytest.raises(TypeError, match="non-empty dict"):
        viewer.register_scalars(V, F, {})
    with pytest.raises(ValueError, match="does not exist"):
        viewer.register_curvature(V, F, screenshot=tmp_path / "no" / "x.png")
    with pytest.raises(ValueError, match="at least 16"):
        viewer.register_curvature(V, F, screenshot=tmp_path / "x.png", size=(4, 4))
    assert viewer.init("auto").get_render_engine_backend_name() == "openGL_mock"  # the checks ran first
    with pytest.raises(viewer.ViewerUnavailable, match="mock backend draws nothing"):
        viewer.screenshot(tmp_path / "x.png")
    Fb = F.copy()
    Fb[0, 0] = -1
    with pytest.raises(ValueError, match="negative vertex indices"):
        viewer.register_comparison(V, Fb)
    with pytest.raises(ValueError, match=r"size must be \(width, height\)"):
        viewer.register_curvature(V, F, screenshot=tmp_path / "x.png", size=800)
    with pytest.raises(ValueError, match=r"a colour range must be \(lo, hi\), got"):
        viewer.register_scalars(V, F, {"x": V[:, 0]}, vminmax="wide")
    with pytest.raises(ValueError, match=r"u1 must have shape"):
        viewer.register_biharmonic(V, F, np.ones(4))
    with pytest.raises(ValueError, match="enabled must be one of"):
        viewer.register_biharmonic(V, F, V[:, 0], enabled="error")      # no exact solution given
    with pytest.raises(ValueError, match="enabled must be one of"):
        viewer.register_regge_curvature(V, F, compare=False, enabled="hhj")
    with pytest.raises(ValueError, match="enabled must be one of"):
        viewer.register_hessian(V, F, V[:, 0], enabled="det")


def test_screenshot_path_not_writable(mock, ellipsoid, tmp_path, monkeypatch):
    # permissions cannot be tested as root (root writes anywhere): fake the access check
    monkeypatch.setattr(render.os, "access", lambda path, mode: False)
    with pytest.raises(ValueError, match="is not writable"):
        viewer.register_curvature(*ellipsoid, screenshot=tmp_path / "x.png")


def test_render_refuses_removed_structures(egl, sphere, tmp_path):
    V, F = sphere
    reg = viewer.register_scalars(V, F, {"x": V[:, 0]}, name="gone")
    ps.remove_surface_mesh("gone")
    with pytest.raises(ValueError, match="no longer registered"):
        viewer.screenshot(tmp_path / "g.png", reg)
    assert not (tmp_path / "g.png").exists()


# --------------------------------------------------------------------------- pictures as arrays / notebooks
def _decode_png(data):
    import io

    import matplotlib.image as mpimg
    return np.round(mpimg.imread(io.BytesIO(data) if isinstance(data, bytes) else str(data)) * 255).astype(np.uint8)


def test_png_bytes_round_trip():
    rng = np.random.default_rng(1)
    image = rng.integers(0, 256, size=(17, 23, 4), dtype=np.uint8)
    data = render._png_bytes(image)
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    np.testing.assert_array_equal(_decode_png(data), image)


def test_no_picture_without_a_renderer(mock, sphere):
    """Under the mock backend a registration has no picture: Jupyter falls back to the text repr."""
    V, F = sphere
    reg = viewer.register_scalars(V, F, {"x": V[:, 0]}, name="m")
    assert reg._repr_png_() is None
    assert viewer.Registration()._repr_png_() is None
    with pytest.raises(viewer.ViewerUnavailable, match="mock"):
        viewer.to_image(reg)
    with pytest.raises(ValueError, match="16 x 16"):
        viewer.to_image(reg, size=(8, 8))


def test_to_image_is_the_screenshot(egl, sphere, tmp_path):
    """to_image returns the picture screenshot writes: (H, W, 4) uint8, opaque, the PNG's
    pixels exactly (full colour, no palette); with and without titles / colour bars;
    reg.screenshot is left alone."""
    V, F = sphere
    reg = viewer.register_curvature(V, F, name="s", per="face")
    for annotate in (True, False):
        im = viewer.to_image(reg, size=(320, 240), annotate=annotate)
        assert im.shape == (240, 320, 4) and im.dtype == np.uint8 and (im[..., 3] == 255).all()
        viewer.screenshot(tmp_path / f"s{annotate}.png", reg, size=(320, 240), annotate=annotate)
        np.testing.assert_array_equal(im[..., :3], _decode_png(tmp_path / f"s{annotate}.png")[..., :3])
    assert reg.screenshot == str(tmp_path / "sFalse.png")
    viewer.to_image(reg, size=(64, 64))
    assert reg.screenshot == str(tmp_path / "sFalse.png")
    st = _check_png(tmp_path / "sTrue.png", (320, 240))
    assert st["foreground"] > 0.1


def test_registration_shows_as_png_in_notebooks(egl, sphere):
    V, F = sphere
    reg = viewer.register_curvature(V, F, name="nb", per="face")
    data = reg._repr_png_()
    assert data is not None and data[:8] == b"\x89PNG\r\n\x1a\n"
    w, h = viewer.REPR_PNG_SIZE
    np.testing.assert_array_equal(_decode_png(data), viewer.to_image(reg, size=(w, h)))
    pytest.importorskip("IPython")
    from IPython.core.formatters import DisplayFormatter
    fmt, _ = DisplayFormatter().format(reg)
    assert fmt["image/png"] == data and fmt["text/plain"].startswith("Registration(")
    ps.remove_surface_mesh("nb")
    assert reg._repr_png_() is None                   # removed structures: text repr only


# --------------------------------------------------------------------------- headless renders (EGL)
def _check_png(path, size, *, red=True, blue=False):
    st = png_stats(path)
    assert (st["width"], st["height"]) == tuple(size)
    assert st["std"] > 0.05 and 0.05 < st["foreground"] < 0.95, st      # not blank, object in frame
    if red:
        assert st["red"] > 0.01, st          # coloured by the (coolwarm) quantity, not the grey mesh
    if blue:
        assert st["blue"] > 0.01, st
    return st


def test_render_curvature(egl, ellipsoid, tmp_path):
    V, F = ellipsoid
    reg = viewer.register_curvature(V, F, screenshot=tmp_path / "c.png", size=(320, 240))
    assert reg.screenshot == str(tmp_path / "c.png")
    _check_png(tmp_path / "c.png", (320, 240))
    # the same structure name again with another quantity enabled is still coloured
    viewer.register_curvature(V, F, enabled="k1", screenshot=tmp_path / "c2.png", size=(320, 240))
    _check_png(tmp_path / "c2.png", (320, 240))


def test_render_comparison(egl, ellipsoid, tmp_path):
    V, F = ellipsoid
    viewer.register_comparison(V, F, enabled="H", robust=2, screenshot=tmp_path / "cmp.png", size=(480, 240))
    st = _check_png(tmp_path / "cmp.png", (480, 240))
    assert st["foreground"] > 0.15        # both copies in frame


def test_render_hessian(egl, sphere, tmp_path):
    V, F = sphere
    viewer.register_hessian(V, F, lambda X: X[:, 0] * X[:, 1], enabled="trace",  # -6xy: both signs
                            screenshot=tmp_path / "h.png", size=(256, 256))
    _check_png(tmp_path / "h.png", (256, 256), red=True, blue=True)


def test_render_biharmonic(egl, sphere, tmp_path):
    V, F = sphere
    viewer.register_biharmonic(V, F, V[:, 0], enabled="u1", screenshot=tmp_path / "b.png", size=(256, 256))
    _check_png(tmp_path / "b.png", (256, 256), red=True, blue=True)


def test_render_regge(egl, ellipsoid, tmp_path):
    V, F = ellipsoid
    viewer.register_regge_curvature(V, F, screenshot=tmp_path / "r.png", size=(256, 256))
    _check_png(tmp_path / "r.png", (256, 256))


def test_render_scalars_and_merged_screenshot(egl, sphere, tmp_path):
    V, F = sphere
    a = viewer.register_scalars(V, F, {"x": V[:, 0]}, name="left")
    b = viewer.register_scalars(V, F, {"y": V[:, 1]}, name="right", offset=(2.5, 0, 0))
    viewer.register_scalars(V, F, {"z": V[:, 2]}, name="not drawn", offset=(0, 0, 50))
    out = viewer.screenshot(tmp_path / "m.png", [a, b], size=(400, 200))
    st = _check_png(out, (400, 200), red=True, blue=True)
    assert st["foreground"] > 0.2         # the far-away third structure did not shrink the framing


def test_missing_egl_is_a_clear_error_not_a_crash(tmp_path):
    """Without usable EGL libraries polyscope used to segfault the interpreter; the
    viewer must raise ViewerUnavailable naming the Debian packages, and the process
    must stay usable and exit cleanly."""
    for lib in ("libEGL.so", "libEGL.so.1"):
        (tmp_path / lib).write_bytes(b"")          # shadows the real library: dlopen fails
    code = ("from igl_hhj import viewer\n"
            "from igl_hhj.surfaces.meshing import ellipsoid_coarse\n"
            "V, F = ellipsoid_coarse(subdivisions=1)\n"
            "for _ in range(2):\n"
            "    try:\n"
            f"        viewer.register_curvature(V, F, screenshot={str(tmp_path / 'x.png')!r})\n"
            "    except viewer.ViewerUnavailable as exc:\n"
            "        print('UNAVAILABLE', exc)\n"
            "viewer.init('openGL_mock'); viewer.register_curvature(V, F); print('STILL USABLE')\n")
    env = dict(__import__("os").environ, LD_LIBRARY_PATH=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.count("UNAVAILABLE") == 2 and "libegl1 libegl-mesa0 libgl1-mesa-dri" in out.stdout
    assert "STILL USABLE" in out.stdout and "Exception ignored" not in out.stderr
    assert not (tmp_path / "x.png").exists()


def test_registration_repr_is_short(mock, ellipsoid):
    reg = viewer.register_comparison(*ellipsoid, name="r")
    text = repr(reg)
    assert len(text) < 400 and "array" not in text
    assert "'r HHJ'" in text and "mean H (HHJ vertices)" in text


# --------------------------------------------------------------------------- views, titles, colour bars (issue 14)
@pytest.mark.parametrize("view", ["+x", "-x", "+y", "-y", "+z", "-z", (1.0, 2.0, -0.5)])
def test_view_rotation_is_a_rotation_looking_from_view(view):
    R = viewer.view_rotation(view)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)
    d = np.zeros(3)
    if isinstance(view, str):
        d["xyz".index(view[1])] = 1.0 if view[0] == "+" else -1.0
    else:
        d = np.asarray(view) / np.linalg.norm(view)
    np.testing.assert_allclose(R @ d, [0, 0, 1], atol=1e-12)   # the camera (on +z) looks from `view`


def test_best_view_is_the_largest_projected_area(ellipsoid):
    """Ellipsoid x² + (2y)² + (2z/3)² = 1: the largest silhouette (the x-z ellipse, area
    π·1·1.5, against π·1·0.5 and π·0.5·1.5) is seen along the short y axis; an open
    hemisphere is seen from its outer (convex) side."""
    V, F = ellipsoid
    d = viewer.best_view_direction(V, F)
    assert abs(d[1]) > 0.97, d
    V2, F2 = icosphere(3)
    keep = (V2[F2][:, :, 2] > -1e-9).all(axis=1)
    d2 = viewer.best_view_direction(V2, F2[keep])
    assert d2[2] > 0.97, d2
    with pytest.raises(ValueError, match="view must be one of"):
        viewer.view_rotation((0, 0, 0))
    with pytest.raises(ValueError, match="view must be one of"):
        viewer.view_rotation("top")


def test_titles_and_turned_copies(mock, ellipsoid):
    V, F = ellipsoid
    plain = viewer.register_comparison(V, F, name="cmp")
    assert plain.titles == {"cmp HHJ": f"HHJ, per vertex — cmp, {len(F):,} faces",
                            "cmp libigl": f"libigl quadric fit, per vertex — cmp, {len(F):,} faces"}
    assert viewer.register_curvature(V, F, name="c", title="").titles == {}
    turned = viewer.register_comparison(V, F, name="cmp", view="+x")
    R = viewer.view_rotation("+x")
    np.testing.assert_allclose(turned.rotations["cmp HHJ"], R)
    box = backend._REGISTERED["cmp HHJ"]
    np.testing.assert_allclose(box, [(V @ R.T).min(axis=0), (V @ R.T).max(axis=0)])
    # the registration keeps the values as computed (directions in the mesh's own coordinates)
    for key, q in plain.quantities.items():
        np.testing.assert_allclose(turned.quantities[key].values, q.values)
    # colour bars: one per (label, range, colour map) shown
    assert render._colour_bars(plain) == [("mean curvature H [1/length unit]", plain.ranges["H"], "coolwarm")]


def test_screenshot_has_a_colour_bar(egl, sphere, tmp_path):
    """The unit sphere has H = 1 > 0 everywhere: without annotation no blue pixel; the
    coolwarm colour bar below the picture brings its blue half (and the dark tick text)."""
    V, F = sphere
    reg = viewer.register_curvature(V, F, name="s", per="face", robust=None)
    viewer.screenshot(tmp_path / "plain.png", reg, size=(400, 300), annotate=False)
    viewer.screenshot(tmp_path / "bar.png", reg, size=(400, 300))
    plain, bar = png_stats(tmp_path / "plain.png"), png_stats(tmp_path / "bar.png")
    assert (bar["width"], bar["height"]) == (400, 300)
    assert plain["blue"] < 1e-4 and bar["blue"] > 2e-3, (plain, bar)
    import matplotlib.image as mpimg
    im = mpimg.imread(str(tmp_path / "bar.png"))[..., :3]
    assert (im[:20].min(axis=2) < 0.3).any()          # the title's dark text at the top


def test_interactive_layout_leaves_the_panel_free(egl, ellipsoid):
    V, F = ellipsoid
    viewer.register_comparison(V, F, name="win")
    (cx, cy), wpp = backend._window_layout(ps, (1200, 700))
    lo = min(backend._REGISTERED[n][0, 0] for n in ("win HHJ", "win libigl"))
    hi = max(backend._REGISTERED[n][1, 0] for n in ("win HHJ", "win libigl"))
    left_px, right_px = 600 + (lo - cx) / wpp, 600 + (hi - cx) / wpp
    assert viewer.PANEL_PX <= left_px and right_px <= 1200, (left_px, right_px)


def test_register_curvature_defaults_to_the_robust_range(sphere):
    """Issue 26 (8): the viewer's default colour range is the 1st-99th percentile one
    the command line uses (--robust 1), so one outlier does not wash the picture out."""
    V, F = sphere
    viewer.init("openGL_mock")
    est = viewer.curvature_estimate(V, F, method="hhj", per="face")
    est.H[0] = 1e6                                               # one wild value
    reg = viewer.register_curvature(V, F, est, name="robust")
    assert reg.ranges["H"] == viewer.color_range(est.H, robust=1.0) and reg.ranges["H"][1] < 10
    assert viewer.register_curvature(V, F, est, name="full", robust=None).ranges["H"][1] == 1e6
    cmp = viewer.register_comparison(V, F, name="cmp")
    assert cmp.ranges["H"][1] < 10
    ps.remove_all_structures()


def test_png_is_full_colour(tmp_path):
    """A smooth field keeps every level (the 256-colour palette banded the biharmonic demo):
    a 2-D ramp of 4096 colours round-trips exactly."""
    from PIL import Image

    from igl_hhj.viewer.render import save_png
    i, j = np.meshgrid(np.arange(64), np.arange(64), indexing="ij")
    img = np.stack([4 * i, 4 * j, (i + j) % 256], axis=-1).astype(np.uint8)
    assert save_png(tmp_path / "ramp.png", img)
    back = np.asarray(Image.open(tmp_path / "ramp.png"))
    assert back.shape == (64, 64, 3)
    np.testing.assert_array_equal(back, img)
