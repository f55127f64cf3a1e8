"""The drop-in repairs meshes that libigl accepts and the strict functions refuse
(issue 24 item 1): :mod:`igl_hhj.repair`, ``principal_curvature``'s repair path,
``shape_operator(repair=True)``."""
import warnings

import igl
import numpy as np
import pytest
from conftest import MESH_DIR, fin, fins, moebius, sequence

import igl_hhj
from igl_hhj import repair as rp
from igl_hhj.mesh import MeshDefectError, MeshWarning, TriangleMesh
from igl_hhj.convergence import eoc, vertex_errors
from igl_hhj.surfaces import icosphere

V2, F2 = icosphere(2)


# --------------------------------------------------------------------------- helpers
def call(fn, *args, **kwargs):
    """Run ``fn`` and return (result, list of MeshWarnings)."""
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        out = fn(*args, **kwargs)
    return out, [w for w in rec if issubclass(w.category, MeshWarning)]


def check_structure(out, nV):
    PD1, PD2, PV1, PV2, bad = out
    assert PD1.shape == PD2.shape == (nV, 3) and PV1.shape == PV2.shape == (nV,)
    for a in (PD1, PD2, PV1, PV2):
        assert a.dtype == np.float64
    assert isinstance(bad, list) and all(type(i) is int for i in bad) and bad == sorted(bad)
    rows = np.column_stack([PD1, PD2, PV1, PV2])
    nan = ~np.isfinite(rows).all(axis=1)
    assert np.isnan(rows[nan]).all()
    assert np.flatnonzero(nan).tolist() == bad
    ok = ~nan
    assert np.all(PV1[ok] >= PV2[ok])


def far_from(F, verts, nV, rings=2):
    """(nV,) bool: vertices at least ``rings`` rings away from ``verts``."""
    near = np.zeros(nV, dtype=bool)
    near[np.asarray(verts, dtype=np.int64)] = True
    for _ in range(rings - 1):
        near[F[near[F].any(axis=1)].ravel()] = True
    return ~near


@pytest.fixture(scope="module")
def clean():
    return igl_hhj.principal_curvature(V2, F2)


def compare_far(out, clean, F, defect_verts, nV=len(V2), tol=0.05):
    far = far_from(F2, defect_verts, nV)
    PV1, PV2 = out[2][:len(V2)], out[3][:len(V2)]
    assert np.isfinite(PV1[far]).all()
    assert np.abs(PV1[far] - clean[2][far]).max() < tol
    assert np.abs(PV2[far] - clean[3][far]).max() < tol


def one_warning(ws, *words):
    assert len(ws) == 1, [str(w.message) for w in ws]
    msg = str(ws[0].message)
    for w in words:
        assert w in msg, msg
    return msg


# --------------------------------------------------------------------------- one test per defect
def test_fin_on_an_edge(clean):
    V, F, verts = fin(V2, F2)
    with pytest.raises(MeshDefectError, match="non-manifold"):
        TriangleMesh(V, F)
    out, ws = call(igl_hhj.principal_curvature, V, F)
    check_structure(out, len(V))
    assert out[4] == []
    one_warning(ws, "non-manifold", "vertex copies")
    compare_far(out, clean, F, verts)
    # the sphere's copy of a split vertex (the larger incident area) gives its row
    np.testing.assert_allclose(out[2][verts], clean[2][verts], atol=0.05)


def test_duplicated_face(clean):
    F = np.vstack([F2, F2[7:8]])
    out, ws = call(igl_hhj.principal_curvature, V2, F)
    check_structure(out, len(V2))
    one_warning(ws, "1 duplicate faces dropped")
    compare_far(out, clean, F, F2[7])
    np.testing.assert_allclose(out[2], clean[2], atol=1e-12)


def test_reversed_duplicate_face(clean):
    F = np.vstack([F2[:30], F2[30:31, ::-1], F2[30:]])     # the reverse before the original
    out, ws = call(igl_hhj.principal_curvature, V2, F)
    check_structure(out, len(V2))
    one_warning(ws, "duplicate")
    np.testing.assert_allclose(out[2], clean[2], atol=1e-10)   # majority orientation wins


def test_one_flipped_face(clean):
    F = F2.copy()
    F[9] = F[9, ::-1]
    with pytest.raises(ValueError, match="not consistently oriented"):
        igl_hhj.shape_operator(V2, F)                          # the strict function still refuses
    out, ws = call(igl_hhj.principal_curvature, V2, F)
    check_structure(out, len(V2))
    one_warning(ws, "1 faces re-oriented")
    np.testing.assert_allclose(out[2], clean[2], atol=1e-10)
    assert np.median(out[2]) > 0.9                             # the caller's (outward) sign


def test_whole_mesh_reversed_keeps_its_sign(clean):
    F = F2[:, ::-1].copy()
    F[9] = F2[9]                                               # one face against the majority
    out, ws = call(igl_hhj.principal_curvature, V2, F)
    one_warning(ws, "re-oriented")
    np.testing.assert_allclose(out[2], -clean[3], atol=1e-10)  # inward normals: -κ


def test_moebius_strip_plus_sphere(clean):
    Vm, Fm = moebius()
    V = np.vstack([V2, Vm])
    F = np.vstack([F2, Fm + len(V2)])
    out, ws = call(igl_hhj.principal_curvature, V, F)
    check_structure(out, len(V))
    one_warning(ws, "non-orientable", f"{len(Vm)} vertices left without a face")
    assert out[4] == list(range(len(V2), len(V)))              # the strip's vertices are bad
    np.testing.assert_allclose(out[2][:len(V2)], clean[2], atol=1e-12)
    R = rp.repair_mesh(V, F)
    assert R.summary["non-orientable"] == len(Fm) and len(R.F) == len(F2)


def test_zero_area_face(clean):
    a, b = F2[0][0], F2[0][1]
    V = np.vstack([V2, 0.5 * (V2[a] + V2[b])])                 # collinear with a, b
    F = np.vstack([F2, [[a, b, len(V2)]]])
    out, ws = call(igl_hhj.principal_curvature, V, F)
    check_structure(out, len(V))
    one_warning(ws, "degenerate")
    assert out[4] == [len(V2)]                                 # only on the dropped face
    compare_far(out, clean, F, [a, b])


def test_sliver_inside_the_mesh(clean):
    V = V2.copy()
    a, b, c = F2[40]
    V[a] = 0.5 * (V[b] + V[c]) + 1e-9 * (V[a] - 0.5 * (V[b] + V[c]))
    out, ws = call(igl_hhj.principal_curvature, V, F2)
    check_structure(out, len(V))
    one_warning(ws, "degenerate")
    compare_far(out, clean, F2, np.unique(F2[(F2 == a).any(axis=1)]))


def test_repeated_corner(clean):
    a, b = F2[3][0], F2[3][1]
    F = np.vstack([F2, [[a, a, b]]])
    out, ws = call(igl_hhj.principal_curvature, V2, F)
    check_structure(out, len(V2))
    one_warning(ws, "repeated corner")
    np.testing.assert_allclose(out[2], clean[2], atol=1e-12)


def test_everything_dropped_gives_all_nan():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    out, ws = call(igl_hhj.principal_curvature, V, [[0, 1, 2]])
    check_structure(out, 3)
    assert out[4] == [0, 1, 2]
    one_warning(ws, "degenerate")


# --------------------------------------------------------------------------- contract
def test_clean_mesh_does_no_repair_work(monkeypatch, clean):
    def boom(*a, **k):
        raise AssertionError("repair_mesh called on a clean mesh")
    monkeypatch.setattr(rp, "repair_mesh", boom)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = igl_hhj.principal_curvature(V2, F2)
    np.testing.assert_array_equal(out[2], clean[2])


def test_non_repairable_errors_are_kept():
    F = np.vstack([F2, F2[:1]])                                # a duplicate and ...
    V = V2.copy()
    V[5] = np.nan                                              # ... NaN coordinates
    with pytest.raises(ValueError, match="NaN or inf"):
        igl_hhj.principal_curvature(V, F)
    with pytest.raises(ValueError, match="out-of-range"):
        igl_hhj.principal_curvature(V2, np.vstack([F, [[0, 1, len(V2)]]]))
    with pytest.raises(ValueError, match="shape"):
        igl_hhj.principal_curvature(V2[:, :2], F)
    with pytest.raises(ValueError, match="F is empty"):
        igl_hhj.principal_curvature(V2, np.zeros((0, 3), dtype=int))
    with pytest.raises(TypeError):
        igl_hhj.principal_curvature(V2, F.astype(float))
    with pytest.raises(ValueError, match="too small"):        # found on the repaired mesh
        igl_hhj.principal_curvature(V2 * 1e-62, F)


def test_strict_functions_keep_refusing():
    F = np.vstack([F2, F2[:1]])
    for fn in (igl_hhj.shape_operator, igl_hhj.face_principal_curvature, TriangleMesh):
        with pytest.raises(ValueError, match="non-manifold"):
            fn(V2, F)
    assert issubclass(MeshDefectError, ValueError)


def test_no_second_repair(monkeypatch):
    """A repaired mesh that still fails validation raises instead of recursing."""
    F = np.vstack([F2, F2[:1]])
    monkeypatch.setattr(rp, "repair_mesh", lambda V, F: rp.RepairedMesh(
        np.asarray(V, float), np.asarray(F), np.arange(len(V)), np.arange(len(F)), len(V), len(F),
        {"duplicate": 1}))
    with pytest.raises(MeshDefectError, match="non-manifold"):
        igl_hhj.principal_curvature(V2, F)


def test_shape_operator_repair_rows_in_callers_order():
    S0 = igl_hhj.shape_operator(V2, F2)
    F = F2.copy()
    F[9] = F[9, ::-1]
    F = np.vstack([F[:20], F[20:21], F[20:]])                  # a duplicate right after face 20
    S, ws = call(igl_hhj.shape_operator, V2, F, repair=True)
    one_warning(ws, "duplicate", "re-oriented")
    assert S.shape == (len(F), 3, 3)
    assert np.isnan(S[21]).all()                               # the dropped copy
    keep = np.r_[0:21, 22:len(F)]
    np.testing.assert_allclose(S[keep], S0, atol=1e-8)         # face 9 with the majority's sign


def test_surface_hessian_repair():
    w = np.c_[V2[:, 2] ** 2, V2[:, 0] * V2[:, 1]]
    H0 = igl_hhj.surface_hessian(V2, F2, w)
    F = np.vstack([F2[:20], F2[20:21, ::-1], F2[20:], [[4, 4, 5]]])   # reversed duplicate, repeated corner
    with pytest.raises(ValueError, match="repeated vertex"):
        igl_hhj.surface_hessian(V2, F, w)                      # strict by default
    H, ws = call(igl_hhj.surface_hessian, V2, F, w, repair=True)
    one_warning(ws, "surface Hessian", "duplicate", "repeated corner")
    assert H.shape == (len(F), 2, 3, 3) and H.dtype == np.float64
    assert np.isnan(H[[21, len(F) - 1]]).all()
    np.testing.assert_allclose(H[np.r_[0:21, 22:len(F) - 1]], H0, atol=1e-8)
    h1, _ = call(igl_hhj.surface_hessian, V2, F, w[:, 0], repair=True)
    assert h1.shape == (len(F), 3, 3)
    with pytest.raises(ValueError, match="one row per vertex"):
        igl_hhj.surface_hessian(V2, F, w[:-1], repair=True)


def test_boundary_data_is_mapped_to_the_repaired_vertices():
    keep = V2[F2].mean(axis=1)[:, 2] > 0.05                    # a cap: open mesh
    F = F2[keep]
    N = V2 / np.linalg.norm(V2, axis=1, keepdims=True)
    ref = igl_hhj.principal_curvature(V2, F, boundary_normals=N)
    Fd = np.vstack([F, F[:3]])
    out, ws = call(igl_hhj.principal_curvature, V2, Fd, boundary_normals=N)
    one_warning(ws, "duplicate")
    check_structure(out, len(V2))
    np.testing.assert_allclose(out[2], ref[2], atol=1e-12, equal_nan=True)
    assert out[4] == ref[4]


def test_repair_mesh_maps_and_summary():
    V, F, verts = fin(V2, F2)
    F = np.vstack([F, F[:2, ::-1], [[0, 0, 1]]])
    R = rp.repair_mesh(V, F)
    assert R.summary == {"repeated corner": 1, "degenerate": 0, "duplicate": 2, "two-sided": 0, "flipped": 0,
                         "non-orientable": 0, "non-manifold": 2}
    assert R.F.dtype == np.int64 and R.V.dtype == np.float64
    np.testing.assert_array_equal(R.V, V[R.vertex_map])
    assert (np.diff(R.face_map) > 0).all()                     # the caller's order
    np.testing.assert_array_equal(R.vertex_map[R.F], F[R.face_map])
    TriangleMesh(R.V, R.F)                                     # passes strict validation
    (vals,) = rp.vertex_values_to_caller(R, np.arange(len(R.V), dtype=float))
    assert vals.shape == (len(V),) and np.isfinite(vals).all()
    (fv,) = rp.face_values_to_caller(R, np.ones(len(R.F)))
    assert np.isnan(fv[-3:]).all() and np.isfinite(fv[:-3]).all()
    with pytest.raises(ValueError, match="out-of-range"):
        rp.repair_mesh(V, F + len(V))


# --------------------------------------------------------------------------- convergence
def _with_defects(V, F, kind, rng):
    """~1 % of the faces duplicated, flipped or with a fin glued on one edge (or a third
    of a percent of each, "mixed"). Returns ``(V, F, defect faces of the clean F)``."""
    n = max(1, len(F) // (300 if kind == "mixed" else 100))
    pick = rng.choice(len(F), 3 * n if kind == "mixed" else n, replace=False)
    dup, flip, fin_at = {"duplicate": (pick, [], []), "flip": ([], pick, []), "fin": ([], [], pick),
                         "mixed": (pick[:n], pick[n:2 * n], pick[2 * n:])}[kind]
    Fd = F.copy()
    Fd[flip] = Fd[flip, ::-1]
    Vd, Fd = fins(V, Fd, fin_at) if len(fin_at) else (V, Fd)
    return Vd, np.vstack([Fd, F[dup]]), pick


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["duplicate", "flip", "fin", "mixed"])
def test_convergence_with_defects(kind):
    """~1 % of the faces duplicated / flipped / with a fin glued on, on the non-uniform
    ellipsoid sequence (the rate tests' ``sequence("ellipsoid")``): the vertex
    mean-curvature error measured away (≥ 3 rings) from the defects keeps EOC ≥ 0.9 on
    every level, and is the clean mesh's error there to 1 %."""
    surface, seq = sequence("ellipsoid", 5)
    errs, clean_errs, hs = [], [], []
    for level, (V, F) in enumerate(seq):
        Vd, Fd, pick = _with_defects(V, F, kind, np.random.default_rng(level))
        out, ws = call(igl_hhj.principal_curvature, Vd, Fd, 1)
        assert len(ws) == 1
        check_structure(out, len(Vd))
        far = far_from(F, np.unique(F[pick]), len(V), rings=3)
        assert far.mean() > 0.5
        nV = len(V)
        assert np.isfinite(out[2][:nV][far]).all()
        e = vertex_errors(V, F, out[2][:nV], out[3][:nV], surface, mask=far)
        _, _, PV1, PV2, _ = igl_hhj.principal_curvature(V, F, 1)
        clean_errs.append(vertex_errors(V, F, PV1, PV2, surface, mask=far)["H"])
        errs.append(e["H"])
        hs.append(e["h"])
    rates = eoc(errs, hs)
    assert rates.min() >= 0.9, (errs, rates)
    np.testing.assert_allclose(errs, clean_errs, rtol=0.01)


def test_real_mesh_with_duplicates_and_flips():
    """A scanned mesh (skipped when the shared meshes are absent): duplicated and
    flipped faces give the clean mesh's values."""
    path = MESH_DIR / "bunny.off"
    if not path.exists():
        pytest.skip(f"no real meshes in {MESH_DIR}")
    V, F = igl.read_triangle_mesh(str(path))[:2]
    clean_out = igl_hhj.principal_curvature(V, F)
    rng = np.random.default_rng(0)
    Fd = F.copy()
    flip = rng.choice(len(F), 5, replace=False)
    Fd[flip] = Fd[flip, ::-1]
    Fd = np.vstack([Fd, F[rng.choice(len(F), len(F) // 100, replace=False)]])
    out, ws = call(igl_hhj.principal_curvature, V, Fd)
    one_warning(ws, "duplicate", "re-oriented")
    check_structure(out, len(V))
    np.testing.assert_allclose(out[2], clean_out[2], atol=1e-8, equal_nan=True)


# --------------------------------------------------------------------------- repair's own cost
def test_unique_rows_is_numpys_row_unique():
    """The integer-key row unique of the repair gives np.unique(axis=0)'s index, inverse and
    counts, also through its fallback (indices too large for one int64 key)."""
    rng = np.random.default_rng(3)
    for n, k in ((50, 2), (50, 3), (2 ** 40, 2), (2 ** 30, 3)):
        A = rng.integers(0, min(n, 40), size=(500, k))
        A[::7] += n - min(n, 40)                       # the largest indices too
        want = np.unique(A, axis=0, return_index=True, return_inverse=True, return_counts=True)[1:]
        got = rp._unique_rows(A, n, return_index=True, return_inverse=True, return_counts=True)
        for w, g in zip(want, got):
            assert np.array_equal(np.ravel(w), np.ravel(g))
    assert rp._row_keys(np.zeros((1, 3), dtype=np.int64), 2 ** 30) is None


def test_consistently_oriented_non_manifold_mesh_skips_bfs_orient_with_its_result():
    """The repair calls igl.bfs_orient only where an edge of two faces is traversed twice in the
    same direction: elsewhere bfs_orient returns the faces unchanged (checked here), so
    skipping it changes nothing; a flipped face still goes through it."""
    fan = np.array([[F2[0, 0], F2[0, 1], len(V2)]])        # a third face on edge (F[0,0], F[0,1])
    V = np.vstack([V2, V2[F2[0]].mean(axis=0) + 0.3])
    F = np.vstack([F2, fan])
    assert not rp._inconsistent_faces(F).any()
    assert np.array_equal(np.asarray(igl.bfs_orient(F)[0]), F)
    R = rp.repair_mesh(V, F)
    assert R.summary["non-manifold"] > 0 and R.summary["flipped"] == 0
    Ff = F.copy()
    Ff[5] = Ff[5, ::-1]
    assert rp._inconsistent_faces(Ff).any()
    assert rp.repair_mesh(V, Ff).summary["flipped"] == 1


def test_inconsistent_faces_from_the_compiled_edge_maps_match_the_numpy_form():
    """_inconsistent_faces reads kernels.topology's edge maps; on random triangle soups (non-manifold
    edges, both directions) it flags exactly the faces the half-edge np.unique form flags."""
    def numpy_form(F):
        he = np.concatenate([F[:, [1, 2]], F[:, [2, 0]], F[:, [0, 1]]])
        _, inv, cnt = np.unique(np.sort(he, axis=1), axis=0, return_inverse=True, return_counts=True)
        inv = inv.ravel()
        pos = np.bincount(inv, weights=he[:, 0] < he[:, 1], minlength=len(cnt))
        return ((cnt == 2) & (pos != 1))[inv].reshape(3, len(F)).any(axis=0)
    rng = np.random.default_rng(5)
    flagged = 0
    for _ in range(100):
        n = int(rng.integers(4, 30))
        F = np.array([rng.choice(n, 3, replace=False) for _ in range(int(rng.integers(1, 60)))])
        want = numpy_form(F)
        assert np.array_equal(rp._inconsistent_faces(F), want)
        flagged += int(want.any())
    assert flagged > 10                                   # the soups do exercise the test


def test_the_repair_warning_points_at_the_callers_line():
    """The one MeshWarning of a repaired call names the caller's file (not igl_hhj's)."""
    F = np.vstack([F2, F2[:1]])
    for fn, args, kw in ((igl_hhj.principal_curvature, (V2, F), {}),
                         (igl_hhj.shape_operator, (V2, F), {"repair": True}),
                         (igl_hhj.surface_hessian, (V2, F, V2[:, 0]), {"repair": True})):
        with warnings.catch_warnings(record=True) as ws:
            warnings.simplefilter("always")
            fn(*args, **kw)
        assert [w.filename for w in ws] == [__file__], fn.__name__
