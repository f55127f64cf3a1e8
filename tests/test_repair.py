"""The drop-in repairs meshes that libigl accepts and the strict functions refuse
(issue 24 item 1): :mod:`igl_hhj.repair`, ``principal_curvature``'s repair path,
``shape_operator(repair=True)``."""
import warnings

import igl
import numpy as np
import pytest

import igl_hhj
from igl_hhj import repair as rp
from igl_hhj.mesh import MeshDefectError, MeshWarning, TriangleMesh
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


# --------------------------------------------------------------------------- defect meshes
def fin(V, F, f=0):
    a, b = F[f][0], F[f][1]
    tip = 1.5 * 0.5 * (V[a] + V[b])
    return np.vstack([V, tip]), np.vstack([F, [[a, b, len(V)]]]), [a, b]


def moebius(n=16, width=0.6, centre=(4.0, 0.0, 0.0)):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)

    def p(s):
        r = 1 + s * np.cos(t / 2)
        return np.stack([r * np.cos(t), r * np.sin(t), s * np.sin(t / 2)], axis=-1)

    V = np.vstack([p(-width / 2), p(width / 2)]) + np.asarray(centre)
    i = np.arange(n)
    j = (i + 1) % n
    top_j = np.where(i == n - 1, j, j + n)           # the half twist at the seam
    bot_j = np.where(i == n - 1, j + n, j)
    return V, np.vstack([np.stack([i, bot_j, top_j], 1), np.stack([i, top_j, i + n], 1)])


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
    assert R.summary == {"repeated corner": 1, "degenerate": 0, "duplicate": 2, "flipped": 0,
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
def test_convergence_with_duplicates_and_flips():
    """~1 % duplicated faces and a few flipped ones: the vertex mean curvature away
    from the defects still converges at O(h) (exact H = 1 on the unit sphere)."""
    errs, hs = [], []
    for level in range(2, 6):
        V, F = icosphere(level)
        rng = np.random.default_rng(level)
        nd = max(1, len(F) // 100)
        dup = rng.choice(len(F), nd, replace=False)
        flip = rng.choice(np.setdiff1d(np.arange(len(F)), dup), 3, replace=False)
        Fd = F.copy()
        Fd[flip] = Fd[flip, ::-1]
        Fd = np.vstack([Fd, F[dup]])
        out, ws = call(igl_hhj.principal_curvature, V, Fd)
        assert len(ws) == 1
        check_structure(out, len(V))
        far = far_from(F, np.unique(F[np.r_[dup, flip]]), len(V))
        H = 0.5 * (out[2] + out[3])
        errs.append(np.abs(H[far] - 1.0).max())
        hs.append(TriangleMesh(V, F).max_edge_length)
    eoc = np.diff(np.log(errs)) / np.diff(np.log(hs))
    assert eoc.min() >= 0.9, (errs, eoc)


# --------------------------------------------------------------------------- fuzz
SMALL = {1: icosphere(1), 2: icosphere(2)}
DEFECTS = ["duplicate", "reversed duplicate", "flip", "fin", "zero-area face", "repeated corner",
           "sliver", "hole", "moebius"]


def defect_mesh(seed):
    rng = np.random.default_rng(seed)
    V, F = SMALL[int(rng.integers(1, 3))]
    V, F = V.copy(), F.copy()
    kinds = rng.choice(DEFECTS, int(rng.integers(1, 4)))
    for kind in kinds:
        f = int(rng.integers(len(F)))
        if kind == "duplicate":
            F = np.vstack([F, F[f:f + 1]])
        elif kind == "reversed duplicate":
            F = np.vstack([F, F[f:f + 1, ::-1]])
        elif kind == "flip":
            F[f] = F[f, ::-1]
        elif kind == "fin":
            V, F, _ = fin(V, F, f)
        elif kind == "zero-area face":
            a, b = F[f][0], F[f][1]
            V = np.vstack([V, 0.5 * (V[a] + V[b])])
            F = np.vstack([F, [[a, b, len(V) - 1]]])
        elif kind == "repeated corner":
            F = np.vstack([F, [[F[f][0], F[f][0], F[f][1]]]])
        elif kind == "sliver":
            a, b, c = F[f]
            m = 0.5 * (V[b] + V[c])
            V[a] = m + 10.0 ** -rng.uniform(8, 16) * (V[a] - m)
        elif kind == "hole":
            F = np.delete(F, f, axis=0)
        else:
            Vm, Fm = moebius(int(rng.integers(8, 16)))
            F = np.vstack([F, Fm + len(V)])
            V = np.vstack([V, Vm])
    return V, F


def test_fuzz_against_libigl():
    """1,000 seeded defect meshes: the drop-in's structure matches libigl's (shapes,
    dtypes), NaN rows are exactly ``bad_vertices``, and a vertex libigl gives a finite
    value is bad only when the repaired mesh leaves it no face or no tangent plane."""
    n_repaired = 0
    for seed in range(1000):
        V, F = defect_mesh(seed)
        ref = igl.principal_curvature(V, F)
        out, ws = call(igl_hhj.principal_curvature, V, F, solver="direct")
        check_structure(out, len(V))
        assert len(ws) <= 1
        n_repaired += len(ws)
        for a, b in zip(out[:4], ref[:4]):
            assert a.shape == np.asarray(b).shape, seed
        igl_finite = np.isfinite(np.column_stack(ref[:4])).all(axis=1)
        R = rp.repair_mesh(V, F)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshWarning)       # split seams coincide on purpose
            m = TriangleMesh(R.V, R.F) if len(R.F) else None
        explained = np.ones(len(V), dtype=bool)
        if m is not None:
            ok2 = m.referenced_vertices & ~m.folded_vertices
            explained[R.vertex_map[ok2]] = False
        bad = np.zeros(len(V), dtype=bool)
        bad[out[4]] = True
        assert not (bad & igl_finite & ~explained).any(), seed
    assert n_repaired > 900


def test_real_mesh_with_duplicates_and_flips():
    """A scanned mesh (skipped when the shared meshes are absent): duplicated and
    flipped faces give the clean mesh's values."""
    from pathlib import Path
    path = Path("/work/shared/data/meshes/bunny.off")
    if not path.exists():
        pytest.skip("shared meshes absent")
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
