"""Sharp features (issue 27): creases as internal boundaries, the crease line measure.

The rate test runs on the exact capped cylinder (:mod:`igl_hhj.surfaces.creased`): with
features on, the vertex H error in the 2-ring band along the rims converges and
Σ θ_e|e| → ∫ θ ds; with features off the band error grows (the rim's Dirac measure,
smeared over a band whose width in rings is fixed)."""
import warnings

import igl
import numpy as np
import pytest
import scipy.sparse as sp
from conftest import MESH_DIR

import igl_hhj
from igl_hhj import creases, intrinsic, recovery
from igl_hhj import features as ft
from igl_hhj.convergence import eoc
from igl_hhj.mesh import as_mesh
from igl_hhj.surfaces.creased import CappedCylinder, HalfEllipsoid, capped_cylinder, half_ellipsoid
from reference_creases import dihedral_magnitudes_reference

FANDISK = MESH_DIR / "fandisk.off"


def ring_distance(mesh, seeds, max_rings):
    """(#V,) graph distance in rings from the vertices ``seeds`` (max_rings + 1 beyond)."""
    E, n = mesh.edges, mesh.n_vertices
    A = sp.coo_matrix((np.ones(2 * len(E)), (np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]])),
                      shape=(n, n)).tocsr()
    d = np.full(n, max_rings + 1)
    reached = np.zeros(n, dtype=bool)
    reached[seeds] = True
    d[reached] = 0
    for k in range(1, max_rings + 1):
        nxt = reached | (A @ reached > 0)
        d[nxt & ~reached] = k
        reached = nxt
    return d


def side_exact_H(surface, cut, face_normals):
    """Exact H of every cut vertex, from the patch its faces lie on (each side of a crease
    vertex lies in one patch): the capped cylinder's side / caps, or the half ellipsoid's
    dome (H of the ellipsoid at the vertex) / flat bottom."""
    if isinstance(surface, CappedCylinder):
        flat = np.abs(face_normals[:, 2]) > 0.5
        return np.where(_on_faces(cut, flat), 0.0, surface.side_mean_curvature())
    flat = face_normals[:, 2] < -0.5
    return surface.mean_curvature_at(cut.V, _on_faces(cut, flat))


def _on_faces(cut, face_mask):
    """(#Vc,) bool: cut vertices with an incident face in ``face_mask``."""
    out = np.zeros(len(cut.V), dtype=bool)
    out[cut.F[face_mask].ravel()] = True
    return out


SURFACES = {"capped cylinder": (CappedCylinder, capped_cylinder),
            "half ellipsoid": (HalfEllipsoid, half_ellipsoid)}


@pytest.fixture(scope="module", params=list(SURFACES))
def crease_study(request):
    make_surface, make_mesh = SURFACES[request.param]
    s = make_surface()
    rows = []
    for level in range(1, 5):
        V, F, _ = make_mesh(level)
        mesh = as_mesh(V, F)
        on = ft.feature_principal_curvature(V, F)
        _, _, PV1, PV2, _ = igl_hhj.principal_curvature(V, F)
        Hex = side_exact_H(s, on.cut, mesh.face_normals)
        band = ring_distance(mesh, np.unique(on.creases.edges), 2) <= 2
        e_on = np.abs(on.side_mean_curvature - Hex)
        e_off = np.abs(0.5 * (PV1 + PV2) - Hex[:len(V)])
        err_on = e_on[band[on.side_parent]].max()
        err_off = e_off[band].max()
        far = ~band                                         # the smooth parts: > 2 rings from a rim
        rows.append((mesh.edge_lengths.max(), err_on, err_off, on.creases.total_angle_length,
                     on.creases.n_chains, len(on.creases.corners), np.abs(Hex).max(),
                     np.sqrt(np.mean(e_on[:len(V)][far] ** 2)), np.sqrt(np.mean(e_off[far] ** 2))))
    return request.param, s, np.array(rows)


@pytest.mark.slow
def test_band_converges_with_features_and_not_without(crease_study):
    name, s, rows = crease_study
    hs, on, off, Hmax = rows[:, 0], rows[:, 1], rows[:, 2], rows[-1, 6]
    r_on, r_off = eoc(on, hs), eoc(off, hs)
    assert (r_on >= 0.9).all(), f"{name}, features on, band EOCs {np.round(r_on, 3)} (errors {on})"
    assert on[-1] < 0.02 * Hmax, f"{name}: finest band error {on[-1]:.3g}"
    # without features the rim's Dirac measure is smeared into the band: no convergence
    assert (r_off <= 0).all(), f"{name}, features off, band EOCs {np.round(r_off, 3)} (errors {off})"
    assert off[-1] > Hmax, f"{name}, features off, finest band error {off[-1]:.3g}"


def test_smooth_parts_converge_with_features_and_not_without(crease_study):
    """Issue 27's "smooth parts stay smooth", on the exact surfaces: the RMS vertex H error
    farther than 2 rings from a rim converges with features; without, the rim's curvature
    carried by the smoothing (up to 25 rings) makes it grow."""
    name, s, rows = crease_study
    hs, on, off = rows[:, 0], rows[:, 7], rows[:, 8]
    r_on, r_off = eoc(on, hs), eoc(off, hs)
    assert (r_on >= 0.9).all(), f"{name}, features on, RMS EOCs beyond 2 rings {np.round(r_on, 3)} ({on})"
    assert (r_off <= 0).all(), f"{name}, features off, RMS EOCs beyond 2 rings {np.round(r_off, 3)} ({off})"
    assert on[-1] < 0.01 * off[-1], f"{name}: finest RMS beyond 2 rings {on[-1]:.3g} on, {off[-1]:.3g} off"


def test_crease_line_measure_converges(crease_study):
    name, s, rows = crease_study
    hs, total = rows[:, 0], rows[:, 3]
    err = np.abs(total - s.crease_integral)
    r = eoc(err, hs)
    assert (r >= 0.9).all(), f"{name}: Σθ|e| EOCs {np.round(r, 3)} (errors {err})"
    assert err[-1] < 0.02 * s.crease_integral
    rims = 2 if name == "capped cylinder" else 1
    assert (rows[:, 4] == rims).all() and (rows[:, 5] == 0).all()      # the rims, no corners


def test_shape_operator_with_features_is_flat_on_the_caps():
    V, F, _ = capped_cylinder(2)
    mesh = as_mesh(V, F)
    cap = np.abs(mesh.face_normals[:, 2]) > 0.5
    S_on = igl_hhj.shape_operator(V, F, feature_angle=40)
    S_off = igl_hhj.shape_operator(V, F)
    np.testing.assert_array_equal(S_on, ft.feature_shape_operator(V, F, feature_angle=40))
    assert S_on.shape == (len(F), 3, 3)
    scale = CappedCylinder().side_mean_curvature()
    assert np.abs(S_on[cap]).max() < 1e-8 * scale           # planar caps: S_h = 0 exactly
    assert np.abs(S_off[cap]).max() > scale                 # the rim's jump leaks into the caps


def test_named_creases_in_the_dropin_and_shape_operator():
    """crease_edges= names the creases: the capped cylinder's rims named by hand give the
    bits of feature_angle=40 (which detects exactly them), in both public functions; named
    creases on a mesh that needs repair are refused (a repair renumbers the vertices)."""
    V, F, _ = capped_cylinder(2)
    mesh = as_mesh(V, F)
    rims = mesh.edges[ft.crease_edges(mesh, 40)]
    assert len(rims) > 0
    named = igl_hhj.principal_curvature(V, F, crease_edges=rims[:, ::-1])      # either order
    detected = igl_hhj.principal_curvature(V, F, feature_angle=40)
    for a, b in zip(named[:4], detected[:4]):
        np.testing.assert_array_equal(a, b)
    assert named[4] == detected[4]
    np.testing.assert_array_equal(igl_hhj.shape_operator(V, F, crease_edges=rims),
                                  igl_hhj.shape_operator(V, F, feature_angle=40))
    half = igl_hhj.principal_curvature(V, F, crease_edges=rims[: len(rims) // 2])
    assert not np.array_equal(half[2], detected[2])       # fewer creases: other values
    Fd = np.vstack([F, F[:1]])                            # a duplicate face: repaired
    with pytest.raises(ValueError, match="crease_edges cannot be used on a mesh that needs repair"):
        igl_hhj.principal_curvature(V, Fd, crease_edges=rims)
    with pytest.raises(ValueError, match="crease_edges cannot be used on a mesh that needs repair"):
        igl_hhj.shape_operator(V, Fd, crease_edges=rims, repair=True)
    with pytest.raises(ValueError, match="crease_edges"):
        igl_hhj.principal_curvature(V, F, crease_edges=[[0, 10 ** 6]])


def test_default_is_the_libigl_contract_bit_for_bit():
    """feature_angle=None is today's drop-in; on a smooth mesh (no crease above 40°) the
    cut is the mesh itself and features on give the same bits."""
    from igl_hhj.curvature import _shape_operator, dropin_vertex_values
    from igl_hhj.surfaces import icosphere
    V, F = icosphere(3)
    mesh = as_mesh(V, F)
    ref = dropin_vertex_values(mesh, _shape_operator(mesh, None, None, None, "auto"), 5)
    for out in (igl_hhj.principal_curvature(V, F), igl_hhj.principal_curvature(V, F, feature_angle=None),
                igl_hhj.principal_curvature(V, F, feature_angle=40)):
        for a, b in zip(out[:4], ref[:4]):
            np.testing.assert_array_equal(a, b)
        assert out[4] == ref[4] == []
    np.testing.assert_array_equal(igl_hhj.shape_operator(V, F, feature_angle=40), igl_hhj.shape_operator(V, F))


def _cube():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                  [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
    return V, F


def test_cube_cut_chains_corners_and_signs():
    V, F = _cube()
    mesh = as_mesh(V, F)
    theta = ft.dihedral_angles(mesh)
    crease = ft.crease_edges(mesh)
    assert crease.sum() == 12
    np.testing.assert_allclose(theta[crease], np.pi / 2)               # convex: +
    np.testing.assert_allclose(np.abs(theta[~crease]), 0, atol=1e-12)   # face diagonals
    np.testing.assert_allclose(ft.dihedral_angles(as_mesh(V, F[:, ::-1]))[crease], -np.pi / 2)
    net = ft.crease_network(mesh, crease)
    assert net.n_chains == 12 and len(net.corners) == 8 and len(net.endpoints) == 0
    np.testing.assert_allclose(net.total_angle_length, 12 * np.pi / 2)
    cut = ft.cut_along(mesh, crease)
    assert len(cut.V) == 24                                 # 3 sides per corner
    np.testing.assert_array_equal(cut.parent[:8], np.arange(8))
    np.testing.assert_array_equal(cut.parent[cut.F], F)     # same faces, same corner order
    _, cut_mesh = creases.cut_mesh(mesh, crease)              # (no unwelded-seam warning)
    assert cut_mesh.boundary_edges.sum() == 24              # each cube edge twice
    with warnings.catch_warnings():
        warnings.simplefilter("error")                      # the drop-in with features: silent
        igl_hhj.principal_curvature(V, F, feature_angle=40)


def test_detection_matches_igl_sharp_edges():
    V, F, _ = capped_cylinder(1)
    V = V + 0.0
    mesh = as_mesh(V, F)
    for angle in (20.0, 40.0, 60.0):
        ours = {tuple(e) for e in mesh.edges[ft.crease_edges(mesh, angle)]}
        theirs = {tuple(sorted(e)) for e in igl.sharp_edges(V, F, np.radians(angle))}
        assert ours == theirs


def test_slit_end_is_not_split_and_user_edges():
    from igl_hhj.surfaces import square_grid
    V2, F = square_grid(6, amount=0.0)
    V = np.column_stack([V2, np.zeros(len(V2))])
    mesh = as_mesh(V, F)
    # a flat mesh: no crease by angle; three user edges along an inner grid line
    inner = np.flatnonzero(~mesh.boundary_vertices)
    row = inner[np.isclose(V[inner, 1], V[inner, 1][0])]
    row = row[np.argsort(V[row, 0])]
    pairs = np.column_stack([row[:-1], row[1:]])
    crease = ft.crease_edges(mesh, None, edges=pairs)
    assert crease.sum() == len(pairs)
    net = ft.crease_network(mesh, crease)
    np.testing.assert_array_equal(np.sort(net.endpoints), np.sort(row[[0, -1]]))
    cut = ft.cut_along(mesh, crease)
    assert len(cut.V) == len(V) + len(row) - 2              # the two ends keep one side
    r = ft.feature_principal_curvature(V, F, crease_edges=pairs, feature_angle=None)
    np.testing.assert_allclose(r.side_PV1, 0, atol=1e-9)    # flat: zero on every side
    with pytest.raises(ValueError, match="not an edge"):
        ft.crease_edges(mesh, None, edges=[[row[0], row[2]]])
    b = mesh.edges[mesh.boundary_edges][0]
    with pytest.raises(ValueError, match="boundary edge"):
        ft.crease_edges(mesh, None, edges=[b])


@pytest.mark.parametrize("bad,exc", [(True, TypeError), ("40", TypeError), (0, ValueError),
                                     (180, ValueError), (float("nan"), ValueError)])
def test_feature_angle_validation(bad, exc):
    V, F = _cube()
    with pytest.raises(exc, match="feature_angle"):
        igl_hhj.principal_curvature(V, F, feature_angle=bad)


def test_features_refuse_boundary_data_and_plain():
    V, F, _ = capped_cylinder(0)
    with pytest.raises(ValueError, match="boundary_normals"):
        igl_hhj.principal_curvature(V, F, feature_angle=40, boundary_normals=np.ones((len(V), 3)))
    with pytest.raises(ValueError, match="boundary='estimate'"):
        igl_hhj.shape_operator(V, F, feature_angle=40, boundary="plain")


def _fandisk():
    if not FANDISK.is_file():
        pytest.skip(f"{FANDISK} not available")
    V, F = igl.read_triangle_mesh(str(FANDISK))
    return V, F, as_mesh(V, F)


def test_fandisk_smooth_parts_stay_smooth():
    """Planar vertices farther than 2 rings from a crease (exact H = 0): with features on
    their RMS H is a quarter or less of today's (the crease leaks into them without;
    what remains is the smoothing's ordinary bias next to the soft 10°-40° edges where
    a plane meets a curved blend); curved vertices beyond the smoothing's reach change
    by at most 5 %."""
    V, F, mesh = _fandisk()
    on = ft.feature_principal_curvature(V, F)
    _, _, PV1, PV2, _ = igl_hhj.principal_curvature(V, F)
    H0, H1 = 0.5 * (PV1 + PV2), 0.5 * (on.PV1 + on.PV2)
    d = ring_distance(mesh, np.unique(on.creases.edges), 40)
    fn, N = mesh.face_normals, mesh.vertex_normals
    spread = np.zeros(mesh.n_vertices)                      # 1 - min ν_T·N over the star
    np.maximum.at(spread, F.ravel(), 1 - np.einsum("ma,ma->m", np.repeat(fn, 3, axis=0), N[F.ravel()]))
    planar = (spread < 1e-12) & (d > 2)
    scale = np.median(np.abs(H0))
    assert planar.sum() > 100
    rms_on, rms_off = np.sqrt(np.mean(H1[planar] ** 2)), np.sqrt(np.mean(H0[planar] ** 2))
    assert 4 * rms_on <= rms_off, f"planar RMS H: features on {rms_on:.3g}, off {rms_off:.3g}"
    # reach of the smoothing in rings: 2.5 times its largest length
    # (SMOOTHING_PER_RADIUS · radius · the adaptive factor's upper bound)
    reach = int(np.ceil(2.5 * recovery.SMOOTHING_PER_RADIUS * 5 * intrinsic.ADAPTIVE_RANGE[1]))
    curved = np.abs(H0) > scale
    rel = np.abs(H1 - H0) / np.where(curved, np.abs(H0), np.inf)
    profile = [rel[d >= k].max() for k in (3, 5, 8, reach)]   # the change is the leak: it decays
    assert np.all(np.diff(profile) < 0), f"max relative change at 3, 5, 8, {reach} rings: {profile}"
    assert (curved & (d >= reach)).sum() >= 5
    assert profile[-1] <= 0.05, f"max relative change {profile[-1]:.3f} beyond {reach} rings"


def test_fandisk_face_saw_tooth_is_gone():
    """The per-face S_h jumps between neighbouring faces near a crease (red/blue
    saw-tooth) as much as anywhere else with features on, and far more without."""
    V, F, mesh = _fandisk()
    crease = ft.crease_edges(mesh)
    near = np.zeros(mesh.n_vertices, dtype=bool)
    near[mesh.edges[crease].ravel()] = True
    strip = near[F].any(axis=1)                             # faces touching a crease
    inner = np.flatnonzero((mesh.edge_face_count == 2) & ~crease)
    f0, f1 = mesh.edge_faces[inner, 0], mesh.edge_faces[inner, 1]
    in_strip, away = strip[f0] & strip[f1], ~strip[f0] & ~strip[f1]

    def jumps(S):
        H = 0.5 * np.trace(S, axis1=1, axis2=2)
        d = H[f0] - H[f1]
        return np.sqrt(np.mean(d[in_strip] ** 2)), np.sqrt(np.mean(d[away] ** 2))

    s_on, a_on = jumps(igl_hhj.shape_operator(V, F, feature_angle=40))
    s_off, a_off = jumps(igl_hhj.shape_operator(V, F))
    assert s_on <= 1.25 * a_on, f"features on: strip {s_on:.3f}, away {a_on:.3f}"
    assert s_off >= 4 * a_off, f"features off: strip {s_off:.3f}, away {a_off:.3f}"


def test_cli_and_batch_feature_angle(tmp_path, capsys):
    from igl_hhj import batch, cli
    V, F, _ = capped_cylinder(1)
    path = tmp_path / "capped.off"
    igl.write_triangle_mesh(str(path), V, F)
    V, F = igl.read_triangle_mesh(str(path))                # what the CLI reads
    ref = igl_hhj.principal_curvature(V, F, feature_angle=40)
    out = tmp_path / "c.npz"
    assert cli.main(["curvature", str(path), "--feature-angle", "40", "-o", str(out)]) == 0
    said = capsys.readouterr().out
    assert "creases (--feature-angle 40): 72 edges in 2 chains, 0 corners" in said
    with np.load(out) as z:
        np.testing.assert_array_equal(z["k1"], ref[2])
        np.testing.assert_array_equal(z["S"], igl_hhj.shape_operator(V, F, feature_angle=40))
    res = batch.run_batch([path], tmp_path / "b", workers=0, progress=False, feature_angle=40)
    assert res.counts()["ok"] == 1
    with np.load(tmp_path / "b" / "capped.npz") as z:
        np.testing.assert_array_equal(z["k1"], ref[2])
    assert batch.options_key("hhj", "vertex", None) == {"method": "hhj", "per": "vertex", "radius": 5}
    for argv in (["--feature-angle", "200"], ["--feature-angle", "40", "--method", "igl"],
                 ["--feature-angle", "40", "--per", "face", "--radius", "2"]):
        assert cli.main(["curvature", str(path)] + argv) == 2
        assert "feature-angle" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_screenshot_draws_the_creases(tmp_path):
    import os
    import subprocess
    import sys

    from conftest import png_stats, require_egl
    require_egl()
    V, F, _ = capped_cylinder(1)
    path = tmp_path / "capped.off"
    igl.write_triangle_mesh(str(path), V, F)
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ, PYTHONPATH=root + os.pathsep + os.environ.get("PYTHONPATH", ""))
    pngs = {}
    for tag, extra in (("off", []), ("on", ["--feature-angle", "40"])):
        pngs[tag] = tmp_path / f"{tag}.png"
        res = subprocess.run([sys.executable, "-m", "igl_hhj.cli", "curvature", str(path), "-q",
                              "--screenshot", str(pngs[tag]), "--size", "400", "300", *extra],
                             env=env, capture_output=True, text=True, timeout=120)
        assert res.returncode == 0, res.stderr
    import matplotlib.image as mpimg
    assert (png_stats(pngs["on"])["width"], png_stats(pngs["on"])["height"]) == (400, 300)
    bars = {}
    for tag, p in pngs.items():                             # the colour-bar strip at the bottom
        im = mpimg.imread(str(p))[..., :3]
        bars[tag] = float((im[-40:].min(axis=2) < 0.9).mean())
    assert bars["on"] > 1.3 * bars["off"], bars             # a second bar: crease angle θ


def test_cut_mesh_is_the_validated_cut():
    """The cut mesh is built without a second validation (TriangleMesh._same_faces): its
    topology, face metrics and normals are those of the validated mesh of the same arrays."""
    V, F, _ = capped_cylinder(1)
    mesh = as_mesh(V, F)
    mesh.face_normals                                       # cached: passed on to the cut
    cut, cm = creases.cut_mesh(mesh, ft.crease_edges(mesh))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                     # the seams coincide: that is the cut
        ref = as_mesh(cut.V, cut.F)
    for name in ("edges", "face_edges", "edge_faces", "edge_local_index", "edge_face_count",
                 "boundary_edges", "face_double_areas", "face_normals", "edge_lengths", "vertex_normals"):
        np.testing.assert_array_equal(getattr(cm, name), getattr(ref, name), err_msg=name)
    assert not cm.V.flags.writeable and not cm.F.flags.writeable
    with pytest.raises(ValueError, match="_same_faces"):
        type(mesh)._same_faces(mesh, cut.V, cut.F[:-1])


def _count_calls(monkeypatch, cls, name):
    calls = []
    orig = getattr(cls, name)

    def counted(self, *a, **k):
        calls.append(self)
        return orig(self, *a, **k)
    monkeypatch.setattr(cls, name, counted)
    return calls


def test_cut_mesh_costs_one_solve_and_one_validation(monkeypatch):
    """Cost without timing: on a connected mesh the sides of the cut are one HHJ system
    (the groups of the caller's mesh, not of the cut: fandisk's 12 sides were 4 solves, 3
    by PCG and the small sides together by LDLᵀ), and only the caller's mesh is validated."""
    from igl_hhj.mesh import TriangleMesh
    from igl_hhj.solvers import HHJSystem
    V, F, mesh = _fandisk()
    _, cm = creases.cut_mesh(mesh, ft.crease_edges(mesh))
    from igl_hhj import kernels
    assert kernels.vertex_components(cm)[1] == 12           # 12 sides ...
    systems = _count_calls(monkeypatch, HHJSystem, "__init__")
    checks = _count_calls(monkeypatch, TriangleMesh, "_check_manifold_and_orientation")
    igl_hhj.principal_curvature(V, F, feature_angle=40)
    assert len(systems) == 1 and systems[0].mesh.n_faces == len(F)   # ... one solve
    assert len(checks) == 1                                  # the caller's mesh only
    igl_hhj.shape_operator(V, F, feature_angle=40)
    ft.feature_shape_operator(V, F)
    assert len(systems) == 3


def test_parts_of_the_callers_mesh_stay_independent():
    """Two disjoint parts: each part's values with features do not depend on the other
    (its own solve group, as without features; issue 23's locality, to the same ≤ 1e-12
    absolute as tests/vertex_stage/test_intrinsic.py::test_components_do_not_see_each_other)."""
    V, F, _ = capped_cylinder(2)
    V2 = np.vstack([V, V * 0.5 + (5.0, 0.0, 0.0)])
    F2 = np.vstack([F, F + len(V)])
    a = ft.feature_principal_curvature(V, F)
    b = ft.feature_principal_curvature(V2, F2)
    nV = len(V)
    for x, y in ((a.side_PV1, b.side_PV1[b.side_parent < nV]), (a.side_PV2, b.side_PV2[b.side_parent < nV])):
        assert np.abs(x - y).max() <= 1e-12
    S = ft.feature_shape_operator(V2, F2)
    assert np.abs(ft.feature_shape_operator(V, F) - S[:len(F)]).max() <= 1e-12


def test_corner_components_are_scipys():
    """cut_along's union-find (kernels.graph_components) labels the components like
    scipy.sparse.csgraph.connected_components (in the order of their smallest node), isolated
    nodes included, so the side numbering of the cut is unchanged; bad indices raise."""
    from igl_hhj import kernels
    rng = np.random.default_rng(4)
    n = 500
    pairs = rng.integers(0, n, size=(300, 2))
    label, count = kernels.graph_components(pairs, n)
    A = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    ref_count, ref = sp.csgraph.connected_components(A, directed=False)
    assert count == ref_count and (ref_count > 200)          # many isolated nodes
    np.testing.assert_array_equal(label, ref)
    with pytest.raises(ValueError, match="out of range"):
        kernels.graph_components([[0, n]], n)
    with pytest.raises(ValueError, match="at most 2"):         # refused before any allocation
        kernels.graph_components(np.zeros((0, 2), dtype=np.int64), 2**31)


def test_side_tolerance_in_the_units_of_the_part(monkeypatch):
    """The cut's smoothing solves each side to the part's scale (intrinsic.adaptive_smoothing_by_parts
    with scale_groups): the flat caps of the capped cylinder (values ~1e-14 of the side's
    curvature) take one CG iteration per solve instead of converging relative to their own
    round-off, the curved side's solves are unchanged, and every value stays within the
    smoothing tolerance (1e-3) of the part's RMS of the unscaled solves."""
    from igl_hhj import kernels, runtime
    from igl_hhj.recovery import QUALITY_FLOOR, smoothing_coefficients
    V, F, _ = capped_cylinder(3)
    mesh = as_mesh(V, F)
    cut, cm = creases.cut_mesh(mesh, ft.crease_edges(mesh))
    labels, n = kernels.vertex_components(cm)
    assert n == 3 and (np.bincount(labels) >= intrinsic.SPLIT_MIN_VERTICES).all()   # caps, side
    N = cm.vertex_normals
    w = kernels.recovery_weights(cm, QUALITY_FLOOR)
    X, rough = kernels.intrinsic_patch_recovery(cm, ft.feature_shape_operator(V, F), N, w)
    C0, m = smoothing_coefficients(cm, w)
    args = (C0, m, kernels.transport_phases(cm, N), rough, 5, 1e-6)
    calls = []
    orig = kernels.intrinsic_smoothing

    def counted(sub, *a, **k):
        out = orig(sub, *a, **k)
        calls.append((sub.n_vertices, out[1]))
        return out
    monkeypatch.setattr(kernels, "intrinsic_smoothing", counted)
    monkeypatch.setattr(runtime, "task_workers", lambda: 1)     # the calls in part order (run_tasks's policy)
    own, scaled = X.copy(), X.copy()
    intrinsic.adaptive_smoothing_by_parts(cm, own, *args)
    plain_calls, calls[:] = list(calls), []
    intrinsic.adaptive_smoothing_by_parts(cm, scaled, *args, scale_groups=np.zeros(len(cut.V), dtype=int))
    side = int(np.argmax(np.bincount(labels)))
    caps = [c for c in range(3) if c != side]
    rms = np.sqrt(np.mean((own ** 2).sum(axis=1)))
    assert calls[side] == plain_calls[side]                  # the curved side: its own test already
    for c in caps:
        assert plain_calls[c][1] > 20 and calls[c][1] <= 5, (plain_calls, calls)
        cap = labels == c
        assert np.abs(own[cap]).max() < 1e-9 * rms           # a cap's values: round-off of the part's
    assert np.abs(scaled - own).max() <= 1e-3 * rms
    with pytest.raises(ValueError, match="scale_groups"):
        intrinsic.adaptive_smoothing_by_parts(cm, X.copy(), *args, scale_groups=np.zeros(3, dtype=int))


def _random_creased_meshes():
    """Meshes whose cut exercises every branch of the numbering: the cube (corners with
    three sides), the capped cylinder (two sides of equal area on a symmetric rim), a
    jittered half ellipsoid with user-named creases (open boundary, ties broken by label),
    and fandisk when present."""
    yield ("cube", *_cube(), None)
    V, F, _ = capped_cylinder(2)
    yield "capped cylinder", V, F, None
    V, F, _ = half_ellipsoid(2)
    rng = np.random.default_rng(3)
    mesh = as_mesh(V, F)
    inner = np.flatnonzero(mesh.edge_face_count == 2)
    yield "half ellipsoid", V, F, mesh.edges[rng.choice(inner, 40, replace=False)]
    if FANDISK.is_file():
        V, F, _ = _fandisk()
        yield "fandisk", V, F, None


def test_compiled_cut_is_the_reference_cut():
    """cut_along's kernel (kernels.crease_cut) gives the numpy reference's arrays exactly
    (cut_along_reference: the corner graph by graph_components, the numbering by lexsort),
    and the compiled |θ_e| (kernels.dihedral_magnitudes) agree with the numpy reference to
    one ulp of π, with the same crease edges."""
    for name, V, F, named in _random_creased_meshes():
        mesh = as_mesh(V, F)
        theta = creases.dihedral_magnitudes(mesh)
        ref = dihedral_magnitudes_reference(mesh)
        assert np.abs(theta - ref).max() <= 4e-16, name
        crease = ft.crease_edges(mesh, 40.0, edges=named, theta=theta)
        np.testing.assert_array_equal(crease, ft.crease_edges(mesh, 40.0, edges=named, theta=ref))
        assert crease.any(), name
        a, b = ft.cut_along(mesh, crease), ft.cut_along_reference(mesh, crease)
        for field in ("V", "F", "parent"):
            np.testing.assert_array_equal(getattr(a, field), getattr(b, field), err_msg=f"{name} {field}")
        assert a.F.dtype == b.F.dtype == np.int64 and a.parent.dtype == np.int64
        assert len(a.V) > mesh.n_vertices, name                # there are extra sides


def test_crease_cut_refuses_a_joined_edge_without_two_faces():
    """The kernel checks its inputs (a joined boundary edge would index face -1)."""
    from igl_hhj import kernels
    V, F, _ = half_ellipsoid(1)
    mesh = as_mesh(V[:, :], F[1:])                             # one face less: an open mesh
    join = np.ones(mesh.n_edges, dtype=bool)                   # its boundary edges included
    with pytest.raises(ValueError, match="two faces"):
        kernels.crease_cut(mesh, join)
    with pytest.raises(ValueError, match="join"):
        kernels.crease_cut(mesh, join[:-1])


def test_empty_and_unsigned_crease_edges():
    """``crease_edges=[]`` is no pair, as ``np.zeros((0, 2))`` (it was refused for its shape);
    uint64 indices beyond int64 are reported as given, not wrapped to negative numbers."""
    import igl_hhj
    from igl_hhj.surfaces import icosphere
    V, F = icosphere(1)
    a = igl_hhj.principal_curvature(V, F, crease_edges=[])
    b = igl_hhj.principal_curvature(V, F, crease_edges=np.zeros((0, 2), dtype=np.int64))
    for x, y in zip(a[:4], b[:4]):
        np.testing.assert_array_equal(x, y)
    for big in (2**64 - 1, 2**63 + 5):
        with pytest.raises(ValueError, match=rf"row 0 \(0, {big}\) is not an edge.*out of range"):
            igl_hhj.principal_curvature(V, F, crease_edges=np.array([[0, big]], dtype=np.uint64))
