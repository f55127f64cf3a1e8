"""The compiled core (igl_hhj._hhj_core via igl_hhj.kernels) equals the numpy reference.

Every kernel is compared with its readable numpy twin (hhj.py, mesh.py,
curvature.py ``*_reference``) on closed, open, boundary-data and sliver meshes;
results must be bit-identical across runs, thread counts and concurrent callers.
"""
import subprocess
import sys
import threading

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import sequence

import igl_hhj
from igl_hhj import kernels
from igl_hhj.curvature import (
    _principal_from_shape_operator_reference, _shape_operator, _shape_operator_reference,
    _vertex_shape_operator_reference, principal_from_shape_operator,
)
from igl_hhj.errors import SolverError
from igl_hhj.hhj import (
    HHJProjection, face_schwarz_preconditioner, face_tensors, jump_matrix, mass_matrix, solve_spd,
)
from igl_hhj.mesh import DEGENERATE_AREA_RTOL, TriangleMesh, as_mesh, topology_reference
from igl_hhj.solvers import HHJSystem
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially
from igl_hhj.surfaces.boundary_data import exact_boundary_normals, exact_boundary_shape_operator

RTOL = 1e-9


def rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(b).max()


def _bumpy(level=3, seed=3):
    V, F = icosphere(level)
    V = jitter_tangentially(V, F, Sphere(), 0.3, seed=seed)
    return V * np.array([1.0, 0.7, 1.3]), F


def _sliver_mesh(height=5e-3):
    """A bent jittered sphere with needle triangles: one vertex of several faces pulled
    towards the opposite edge's midpoint, leaving ``height`` of its distance.
    5e-3: minimum angle ~0.6° (camelhead's is 0.55°).  Any two implementations differ
    by about cond(A)·eps·10 (measured: 4e-12 at 1.1°, cond 1e5; 2e-9 at 0.12°, cond 1e8),
    so the ≤1e-9 comparison is made at real meshes' sliver level; 1e-9 (relative area
    ~1e-9, near the validation limit) is used to check that nothing raises."""
    V, F = _bumpy(3, seed=5)
    V = V.copy()
    for f in (10, 200, 777):
        a, b, c = F[f]
        V[c] = 0.5 * (V[a] + V[b]) + height * (V[c] - 0.5 * (V[a] + V[b]))
    return V, F


@pytest.fixture(scope="module")
def closed():
    return TriangleMesh(*_bumpy())


@pytest.fixture(scope="module")
def saddle():
    surface, seq = sequence("saddle", 3)
    V, F = seq[-1]
    return surface, TriangleMesh(V, F)


def _meshes():
    V, F = _bumpy()
    keep = V[F].mean(axis=1)[:, 2] < 0.5
    Fo = F[keep]
    perm = np.random.default_rng(0).permutation(len(F))
    return {"closed": (V, F), "open": (V, Fo), "permuted": (V, F[perm]), "sliver": _sliver_mesh()}


@pytest.mark.parametrize("name", ["closed", "open", "permuted", "sliver"])
def test_topology_equals_libigl_reference(name):
    V, F = _meshes()[name]
    m = TriangleMesh(V, F)
    for got, want in zip(m._topology, topology_reference(F)):
        assert got.dtype == want.dtype
        np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("name", ["closed", "open", "sliver"])
def test_assembly_and_schwarz_equal_reference(name):
    m = TriangleMesh(*_meshes()[name])
    cols, A, M, _, sin_min = kernels.hhj_system(m)
    n = m.n_edges
    rows = np.repeat(np.arange(n), 5)
    Ac = sp.csr_matrix((A.ravel(), (rows, cols.ravel())), shape=(n, n))
    Mc = sp.csr_matrix((M.ravel(), (rows, cols.ravel())), shape=(n, n))
    Aref = mass_matrix(m)
    assert abs(Ac - Aref).max() <= RTOL * abs(Aref).max()
    Mref = face_schwarz_preconditioner(m, Aref)
    assert abs(Mc - Mref).max() <= RTOL * abs(Mref).max()
    l = m.edge_lengths
    assert rel(sin_min, m.face_double_areas * l.min(axis=1) / l.prod(axis=1)) <= 1e-12
    W = np.random.default_rng(1).normal(size=(m.n_vertices, 3))
    Bw = kernels.jump_apply(m, W)
    assert rel(Bw, jump_matrix(m) @ W) <= RTOL


def test_face_tensors_and_shape_operator_faces(closed):
    s = np.random.default_rng(2).normal(size=(closed.n_edges, 3))
    ref = face_tensors(closed, s)                         # (#F, 3, 3, 3)
    assert rel(kernels.face_tensors(closed, s), ref) <= RTOL
    S_ref = -np.einsum("fkab,fk->fab", ref, closed.face_normals)
    assert rel(kernels.shape_operator_faces(closed, s), S_ref) <= RTOL


def _boundary_cases(surface, m):
    V = m.V
    N = exact_boundary_normals(V, m.F, surface)
    S = exact_boundary_shape_operator(V, m.F, surface)
    ss = V[:, 0] > 0
    return {
        "plain": {},
        "clamped": {"boundary_normals": N},
        "simply_supported": {"boundary_shape_operator": S},
        "mixed": {"boundary_normals": N, "boundary_shape_operator": S, "simply_supported": ss},
    }


@pytest.mark.parametrize("case", ["plain", "clamped", "simply_supported", "mixed"])
@pytest.mark.parametrize("solver", ["direct", "cg"])
def test_shape_operator_equals_reference_with_boundary_data(saddle, case, solver):
    surface, m = saddle
    kw = _boundary_cases(surface, m)[case]
    S = _shape_operator(m, kw.get("boundary_normals"), kw.get("boundary_shape_operator"),
                        kw.get("simply_supported"), solver, rtol=1e-13)
    R = _shape_operator_reference(m, **kw)
    assert rel(S, R) <= RTOL


@pytest.mark.parametrize("name", ["closed", "open", "sliver"])
@pytest.mark.parametrize("solver", ["direct", "cg", "auto"])
def test_shape_operator_equals_reference(name, solver):
    m = TriangleMesh(*_meshes()[name])
    S = _shape_operator(m, None, None, None, solver, rtol=1e-13)
    R = _shape_operator_reference(m)
    assert np.isfinite(S).all()
    assert rel(S, R) <= RTOL


def test_surface_hessian_equals_reference(saddle):
    _, m = saddle
    W = np.column_stack([np.sin(m.V[:, 0]) * m.V[:, 1], np.exp(m.V[:, 2])])
    H = igl_hhj.surface_hessian(m, None, W, solver="cg", rtol=1e-13)
    proj = HHJProjection(m, solver="direct")
    ref = face_tensors(m, proj.solve(W), proj.phi)
    assert rel(H, ref) <= RTOL
    G = np.random.default_rng(3).normal(size=(m.n_vertices, 2, 3))
    H = igl_hhj.surface_hessian(m, None, W, boundary_gradient=G, solver="direct")
    from igl_hhj.hhj import clamped_load
    load = proj.plain_boundary_load(W)
    bnd = m.boundary_edges
    load[bnd] = clamped_load(m, bnd, G)[bnd]
    ref = face_tensors(m, proj.solve(W, load=load), proj.phi)
    assert rel(H, ref) <= RTOL


def test_recovery_and_eigen_equal_reference(closed):
    S = _shape_operator_reference(closed)
    N = closed.vertex_normals
    Sv = kernels.lumped_vertex_recovery(closed, S, N)
    Sv_ref, _ = _vertex_shape_operator_reference(closed, S)
    assert rel(Sv, Sv_ref) <= RTOL
    PD1, PD2, PV1, PV2 = principal_from_shape_operator(Sv, N)
    rPD1, rPD2, rPV1, rPV2 = _principal_from_shape_operator_reference(Sv, N)
    assert rel(PV1, rPV1) <= RTOL and rel(PV2, rPV2) <= RTOL
    gap = (rPV1 - rPV2) > 1e-6 * np.abs(rPV1).max()
    assert gap.mean() > 0.9
    # directions agree up to sign where κ1 ≠ κ2
    np.testing.assert_allclose(np.abs(np.einsum("na,na->n", PD1, rPD1))[gap], 1.0, atol=1e-8)
    np.testing.assert_allclose(np.einsum("na,na->n", np.cross(N, PD1), PD2), 1.0, atol=1e-12)


def test_sliver_face_schwarz_never_raises():
    """A face of relative area 1e-9 used to make the Schwarz setup raise LinAlgError; validation
    now stops at DEGENERATE_AREA_RTOL, and a face just above it must not either."""
    V, F = _sliver_mesh(3 * DEGENERATE_AREA_RTOL)
    m = TriangleMesh(V, F)
    M = face_schwarz_preconditioner(m, mass_matrix(m))
    assert np.isfinite(M.data).all()
    cols, A, Mk, n_jacobi, _ = kernels.hhj_system(m)
    assert n_jacobi >= 1 and np.isfinite(Mk).all()
    for solver in ("direct", "auto"):
        S = igl_hhj.shape_operator(V, F, solver=solver)
        assert np.isfinite(S).all()
    # PCG in floating point cannot solve this (cond(A) ~ 1e20); it must say so promptly
    try:
        S = igl_hhj.shape_operator(V, F, solver="cg")
    except SolverError as exc:
        assert "did not converge" in str(exc)
    else:
        assert np.isfinite(S).all()


def test_bit_identical_across_runs_threads_and_concurrent_callers():
    V, F = _bumpy(5)            # 30k edges: above the kernels' single-thread threshold
    m = TriangleMesh(V, F)
    nt = kernels.max_threads()
    adapt, kernels.ADAPT_TO_LOAD = kernels.ADAPT_TO_LOAD, False
    try:
        kernels.set_num_threads(1)
        one = _shape_operator(m, None, None, None, "cg", 1e-10)
        kernels.set_num_threads(max(2, nt))
        two = _shape_operator(m, None, None, None, "cg", 1e-10)
        again = _shape_operator(m, None, None, None, "cg", 1e-10)
    finally:
        kernels.set_num_threads(nt)
        kernels.ADAPT_TO_LOAD = adapt
    assert np.array_equal(one, two) and np.array_equal(two, again)
    out = [None] * 3

    def work(i):
        out[i] = igl_hhj.principal_curvature(V, F, solver="cg")

    threads = [threading.Thread(target=work, args=(i,)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    ref = igl_hhj.principal_curvature(V, F, solver="cg")
    for o in out:
        for a, b in zip(o[:4], ref[:4]):
            assert np.array_equal(a, b)


def test_solve_spd_cg_is_compiled_and_matches_direct(closed):
    import igl
    L = -igl.cotmatrix(closed.V, closed.F)
    Mm = igl.massmatrix(closed.V, closed.F, igl.MASSMATRIX_TYPE_VORONOI)
    K = sp.csr_matrix(Mm + 0.01 * L)
    R = np.random.default_rng(4).normal(size=(K.shape[0], 2))
    X = solve_spd(K, R, method="cg", rtol=1e-12)
    Xd = solve_spd(K, R, method="direct")
    assert rel(X, Xd) <= 1e-9 and rel(K @ Xd, R) <= 1e-12
    x1 = solve_spd(K, R[:, 0], method="cg", rtol=1e-12)
    assert x1.shape == (K.shape[0],) and rel(x1, Xd[:, 0]) <= 1e-9


def test_auto_switches_early_on_slow_convergence(closed):
    """"auto" probes the PCG rate and factorises instead of running 600 iterations."""
    system = HHJSystem(closed)
    rhs = -kernels.jump_apply(closed, closed.V)
    import igl_hhj.solvers as solvers
    old = solvers.AUTO_DIRECT_MAX, solvers._direct_seconds
    try:
        solvers.AUTO_DIRECT_MAX = 0
        solvers._direct_seconds = lambda n: 0.0      # pretend factorising is free
        X, info = system.solve(rhs, "auto", 1e-12)
    finally:
        solvers.AUTO_DIRECT_MAX, solvers._direct_seconds = old
    assert info["switched"] and info["solver"] == "direct"
    assert info["iterations"] <= solvers.PROBE_ITER
    Xd, _ = system.solve(rhs, "direct")
    assert rel(X, Xd) <= 1e-12


def test_rtol_keyword_and_errors(closed):
    S6 = igl_hhj.shape_operator(closed, None, rtol=1e-6, solver="cg")
    S12 = igl_hhj.shape_operator(closed, None, rtol=1e-12, solver="cg")
    assert 0 < rel(S6, S12) < 1e-3
    with pytest.raises(ValueError, match="rtol"):
        igl_hhj.shape_operator(closed, None, rtol=0.0)
    with pytest.raises(TypeError, match="rtol"):
        igl_hhj.principal_curvature(closed.V, closed.F, rtol="tight")
    with pytest.raises(ValueError, match="unknown solver"):
        igl_hhj.shape_operator(closed, None, solver="lu")
    assert issubclass(SolverError, RuntimeError)


def test_missing_extension_is_an_import_error_naming_the_fix():
    code = ("import sys; sys.modules['igl_hhj._hhj_core'] = None\n"
            "try:\n    from igl_hhj import kernels\nexcept ImportError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "compiled core" in out.stdout and "C++17 compiler" in out.stdout


# --------------------------------------------------------------------------- vertex stage
def _vertex_stage_meshes():
    out = _meshes()
    V, F = _bumpy()
    out["unreferenced"] = (np.vstack([V, [[5.0, 5.0, 5.0]]]), F)    # a vertex no face uses
    return out


@pytest.mark.parametrize("name", ["closed", "open", "sliver", "unreferenced"])
@pytest.mark.parametrize("smoothing", [0, 2, 5])
def test_vertex_stage_equals_numpy_reference(name, smoothing):
    """The compiled ambient patch recovery + smoothing (recovery.recover_and_smooth) equals
    the numpy reference (recover_vertex_tensors + smooth_vertex_tensors), NaN rows included.
    (The drop-in's intrinsic stage: tests/vertex_stage/test_intrinsic.py.)"""
    from igl_hhj.curvature import _vertex_shape_operator_numpy, vertex_shape_operator
    m = TriangleMesh(*_vertex_stage_meshes()[name])
    S = _shape_operator(m, None, None, None, "direct")
    Sv, N = vertex_shape_operator(m, S, smoothing=smoothing, recovery="patch")
    Sr, Nr = _vertex_shape_operator_numpy(m, S, smoothing=smoothing)
    ref = m.referenced_vertices
    assert np.array_equal(np.isnan(Sv).any(axis=(1, 2)), ~ref)
    assert np.array_equal(np.isnan(Sr).any(axis=(1, 2)), ~ref)
    assert rel(Sv[ref], Sr[ref]) <= RTOL and np.array_equal(N, Nr, equal_nan=True)


def test_recovery_kernels_equal_reference(closed):
    from igl_hhj import recovery as rc
    m = TriangleMesh(*_sliver_mesh())
    for mesh in (closed, m):
        w = kernels.recovery_weights(mesh, rc.QUALITY_FLOOR)
        assert rel(w, rc.recovery_weights(mesh)) <= 1e-13
        S = _shape_operator(mesh, None, None, None, "direct")
        X = kernels.patch_recovery(mesh, S, mesh.vertex_normals, w)
        Sv, _ = rc.recover_vertex_tensors(mesh, S, weights=w)
        assert rel(rc._from6(X), Sv) <= 1e-13
    cross, dbl, l2max = kernels.face_metrics(closed.V, closed.F)
    ev = closed._edge_vectors
    np.testing.assert_allclose(cross, np.cross(ev[:, 2], -ev[:, 1]), rtol=0, atol=1e-15)
    np.testing.assert_allclose(dbl, np.linalg.norm(cross, axis=1), rtol=1e-15)
    np.testing.assert_allclose(l2max, (ev ** 2).sum(axis=2).max(axis=1), rtol=1e-15)


def test_patch_fit_of_vertices_whose_faces_all_weigh_zero(closed):
    """The compiled patch fit gathers each vertex's corners; a vertex whose corners all weigh 0
    falls back to the plain average of its faces (weight 1 each) there too: the compiled
    recoveries equal the numpy references on a mesh with such vertices."""
    from igl_hhj import intrinsic
    from igl_hhj import recovery as rc
    S = _shape_operator(closed, None, None, None, "direct")
    N = closed.vertex_normals
    w = kernels.recovery_weights(closed, rc.QUALITY_FLOOR)
    lost = np.arange(0, closed.n_vertices, 37)
    w[np.isin(closed.F, lost).any(axis=1)] = 0.0
    assert (np.bincount(closed.F.ravel(), np.repeat(w, 3), closed.n_vertices)[lost] == 0).all()
    X = kernels.patch_recovery(closed, S, N, w)
    Sv, _ = rc.recover_vertex_tensors(closed, S, weights=w)
    assert rel(rc._from6(X), Sv) <= 1e-13
    Xi, rough = kernels.intrinsic_patch_recovery(closed, S, N, w)
    assert rel(Xi, intrinsic.recover(closed, S, N, w)) <= 1e-13
    assert rel(rough, intrinsic.roughness(closed, S, N, Xi, w)) <= 1e-13
    assert np.isfinite(Xi).all() and np.abs(Xi[lost]).max() > 0


def test_gathered_vertex_kernels_bit_identical_across_thread_counts():
    """The recovery and the adaptive radius gather every vertex's corners in face order, in
    parallel over vertices: one and two threads give the same bits (>= 20k vertices, where
    the kernels take two)."""
    from igl_hhj import recovery as rc
    m = TriangleMesh(*icosphere(6))
    S = _shape_operator(m, None, None, None, "cg", 1e-10)
    N = m.vertex_normals
    w = kernels.recovery_weights(m, rc.QUALITY_FLOOR)
    P = np.random.default_rng(1).normal(size=(m.n_vertices, 3))

    def kernels_once():
        Xi, rough = kernels.intrinsic_patch_recovery(m, S, N, w)
        return (kernels.patch_recovery(m, S, N, w), Xi, rough,
                kernels.adaptive_radius(m, P, rough, 5.0, 0.3, 0.25, 0.2, 5.0))
    for a, b in zip(*_on_one_and_two_threads(kernels_once)):
        assert np.array_equal(a, b)


def test_smoothing_with_edges_out_of_lexicographic_order(closed):
    """The compiled smoothing sums each diagonal row by row when the edges are listed in
    lexicographic order (TriangleMesh.edges); any other order takes the serial scatter,
    which must give the same smoothing (to round-off: the rows list their entries in
    another order)."""
    import types
    from igl_hhj import intrinsic
    from igl_hhj import recovery as rc
    S = _shape_operator(closed, None, None, None, "direct")
    N = closed.vertex_normals
    w = kernels.recovery_weights(closed, rc.QUALITY_FLOOR)
    X0, rough = kernels.intrinsic_patch_recovery(closed, S, N, w)
    C0, mass = rc.smoothing_coefficients(closed, w)
    phase = kernels.transport_phases(closed, N)
    perm = np.random.default_rng(3).permutation(closed.n_edges)
    shuffled = types.SimpleNamespace(
        V=closed.V, F=closed.F, n_vertices=closed.n_vertices, n_faces=closed.n_faces, n_edges=closed.n_edges,
        edges=closed.edges[perm], edge_faces=closed.edge_faces[perm],
        edge_local_index=closed.edge_local_index[perm])
    out = []
    for mesh, ph in ((closed, phase), (shuffled, phase[perm])):
        X = X0.copy()
        status, its, _, r = intrinsic.adaptive_smoothing(mesh, X, C0, mass, ph, rough, 5, 1e-12)
        assert status == 0 and its > 0
        out.append((X, r))
    assert rel(out[1][0], out[0][0]) <= 1e-9 and rel(out[1][1], out[0][1]) <= 1e-12


def test_smoothing_falls_back_to_the_reference_when_a_solve_stalls(closed, monkeypatch):
    from igl_hhj import recovery as rc
    S = _shape_operator(closed, None, None, None, "direct")
    length = rc.smoothing_length(closed, 5)
    good, _ = rc.recover_and_smooth(closed, S, length)
    monkeypatch.setattr(kernels, "smooth_vertex_tensors", lambda *a, **k: (1, 500))
    fallback, _ = rc.recover_and_smooth(closed, S, length)
    assert rel(fallback, good) <= RTOL


def test_stalled_smoothing_kernel_leaves_its_input_unchanged(closed):
    """The compiled smoothing returns a non-zero status without touching X when a solve
    does not converge, so the fallback restarts from the recovered tensors (the drop-in
    has freed the face tensors by then)."""
    from igl_hhj import recovery as rc
    S = _shape_operator(closed, None, None, None, "direct")
    X, N, w = rc.patch_recover(closed, S)
    X0 = X.copy()
    C, m = rc.smoothing_coefficients(closed, w)
    t = rc.smoothing_length(closed, 5) ** 2 / 2
    status, its = kernels.smooth_vertex_tensors(closed, X, C, m, t, 2, [2.0, -1.0], 1e-14, 2)
    assert status != 0 and np.array_equal(X, X0)
    status, _ = kernels.smooth_vertex_tensors(closed, X, C, m, t, 2, [2.0, -1.0], 3e-3, 500)
    assert status == 0 and not np.array_equal(X, X0)


def test_fused_jacobi_pcg_equals_csr_preconditioner(closed):
    """Jacobi is fused into the PCG sweeps (no z vector); the same preconditioner as an
    explicit diagonal CSR matrix runs the unfused code path: the bits must agree."""
    import igl
    K = sp.csr_matrix(-igl.cotmatrix(closed.V, closed.F) + sp.diags(np.full(closed.n_vertices, 1e-2)))
    K.sort_indices()
    R = np.random.default_rng(7).normal(size=(K.shape[0], 6))
    dinv = 1.0 / K.diagonal()
    D = sp.diags(dinv).tocsr()
    a = kernels.block_pcg(K.indptr, K.indices, K.data, R, rtol=1e-10, maxiter=2000, dinv=dinv)
    b = kernels.block_pcg(K.indptr, K.indices, K.data, R, rtol=1e-10, maxiter=2000,
                          M=(D.indptr, D.indices, D.data))
    assert a[1] == b[1] and a[2] == b[2] == 0 and np.array_equal(a[0], b[0])


@pytest.mark.slow
def test_block_pcg_int32_and_int64_row_pointers_give_the_same_bits(closed, monkeypatch):
    """The HHJ system's fixed-width row pointer is int32 (memory at the solve): the PCG runs
    on it uncopied, with the operations of the int64 path; mixed types take the int64 one."""
    import igl
    K = sp.csr_matrix(-igl.cotmatrix(closed.V, closed.F) + sp.diags(np.full(closed.n_vertices, 1e-2)))
    K.sort_indices()
    R = np.random.default_rng(3).normal(size=(K.shape[0], 3))
    D = sp.diags(1.0 / K.diagonal()).tocsr()
    kw = dict(rtol=1e-10, maxiter=2000)
    p32, p64 = K.indptr.astype(np.int32), K.indptr.astype(np.int64)
    d32, d64 = D.indptr.astype(np.int32), D.indptr.astype(np.int64)
    calls = []
    for name in ("block_pcg", "block_pcg32"):
        f = getattr(kernels._core, name)
        monkeypatch.setattr(kernels._core, name, lambda *a, _f=f, _n=name: calls.append((_n, a[0])) or _f(*a))
    runs = [kernels.block_pcg(p, K.indices, K.data, R, M=(d, D.indices, D.data), **kw)
            for p, d in ((p32, d32), (p64, d64), (p32, d64))]
    assert [c[0] for c in calls] == ["block_pcg32", "block_pcg", "block_pcg"]
    assert calls[0][1] is p32                          # no copy of an int32 row pointer
    for r in runs[1:]:
        assert r[1] == runs[0][1] and r[2] == 0 and np.array_equal(r[0], runs[0][0])
    assert kernels.ell_indptr(10).dtype == np.int32 and kernels.ell_indptr(2**29).dtype == np.int64


def test_vertex_stage_bit_identical_across_thread_counts():
    from igl_hhj import recovery as rc
    m = TriangleMesh(*_bumpy(5))
    S = _shape_operator(m, None, None, None, "cg", 1e-10)
    nt = kernels.max_threads()
    adapt, kernels.ADAPT_TO_LOAD = kernels.ADAPT_TO_LOAD, False
    try:
        kernels.set_num_threads(1)
        one, _ = rc.recover_and_smooth(m, S, rc.smoothing_length(m, 5))
        kernels.set_num_threads(max(2, nt))
        two, _ = rc.recover_and_smooth(m, S, rc.smoothing_length(m, 5))
    finally:
        kernels.set_num_threads(nt)
        kernels.ADAPT_TO_LOAD = adapt
    assert np.array_equal(one, two)


def _on_one_and_two_threads(fn):
    """[fn() on one thread, fn() on two] (the load adaptation off)."""
    nt = kernels.max_threads()
    adapt, kernels.ADAPT_TO_LOAD = kernels.ADAPT_TO_LOAD, False
    try:
        out = []
        for k in (1, max(2, nt)):
            kernels.set_num_threads(k)
            out.append(fn())
        return out
    finally:
        kernels.set_num_threads(nt)
        kernels.ADAPT_TO_LOAD = adapt


def _vertex_stage_on_one_and_two_threads(m):
    """intrinsic.vertex_stage at radius 5 on one thread, then on two: [(X, info)] * 2."""
    from igl_hhj.intrinsic import vertex_stage
    S = _shape_operator(m, None, None, None, "cg", 1e-10)

    def stage():
        X, _ = vertex_stage(m, S, 5, info=(info := {}))
        return X, info
    return _on_one_and_two_threads(stage)


@pytest.mark.parametrize("parts", [1, 2])
def test_smoothing_tasks_bit_identical_to_one_pcg(parts):
    """Below the two-thread sweep size (2k-20k vertices) the smoothing runs the h and z parts
    of each solve as two tasks on two threads; on one thread one PCG solves both.  The bits
    and the iteration count must agree (one and several parts)."""
    V0, F0 = _bumpy(4)
    V, F = V0, F0
    if parts == 2:
        V = np.vstack([V0, 0.5 * V0 + 3.0])
        F = np.vstack([F0, F0 + len(V0)])
    m = TriangleMesh(V, F)
    assert 2000 <= m.n_vertices < 20000
    (one, i1), (two, i2) = _vertex_stage_on_one_and_two_threads(m)
    assert i1["components"] == i2["components"] == parts
    assert i1["smoothing_iterations"] == i2["smoothing_iterations"] > 0
    assert np.array_equal(one, two)


def test_smoothing_of_several_parts_bit_identical_across_thread_counts():
    """The intrinsic smoothing of a mesh with several parts (per-part CG scalars) runs its
    reductions in parallel chunks: the same bits on one and two threads (>= 20k vertices,
    where the kernel takes two)."""
    from igl_hhj.surfaces import icosphere
    V0, F0 = icosphere(5)
    V = np.vstack([V0, 0.5 * V0 * [1.0, 0.8, 0.6] + 3.0])
    F = np.vstack([F0, F0 + len(V0)])
    m = TriangleMesh(V, F)
    assert m.n_vertices >= 20000
    (one, i1), (two, i2) = _vertex_stage_on_one_and_two_threads(m)
    assert i1["components"] == i2["components"] == 2
    assert np.array_equal(one, two)


def test_vertex_kernels_reject_bad_arrays(closed):
    S = np.zeros((closed.n_faces, 3, 3))
    with pytest.raises(ValueError, match="patch_recovery"):
        kernels.patch_recovery(closed, S[:-1], closed.vertex_normals, closed.face_areas)
    X = np.zeros((closed.n_vertices, 5))
    with pytest.raises(ValueError, match="smooth_vertex_tensors"):
        kernels.smooth_vertex_tensors(closed, X, np.zeros((closed.n_faces, 3)),
                                      np.ones(closed.n_vertices), 1.0, 2, [2, -1], 1e-3, 10)


def test_mass_solver_equals_direct_solve_and_falls_back(closed, monkeypatch):
    """``solvers.mass_solver``: lumped-preconditioned compiled PCG for the consistent P1
    mass (biharmonic Schur complement, Regge lifting) equals a sparse direct solve for
    (n,) and (n, k) right-hand sides in ≤ 30 iterations; a stalled PCG factorises."""
    import igl
    import scipy.sparse.linalg as spla
    from igl_hhj import solvers
    M = sp.csr_matrix(igl.massmatrix(closed.V, closed.F, igl.MASSMATRIX_TYPE_FULL))
    minv = 1.0 / np.asarray(M.sum(axis=1)).ravel()
    B = np.random.default_rng(0).normal(size=(M.shape[0], 2))
    ref = spla.spsolve(M.tocsc(), B)
    its, real = [], solvers.pcg
    monkeypatch.setattr(solvers, "pcg", lambda *a, **k: its.append(real(*a, **k)) or its[-1])
    solve = solvers.mass_solver(M, minv, rtol=1e-13)
    assert rel(solve(B), ref) <= RTOL and rel(solve(B[:, 0]), ref[:, 0]) <= RTOL
    assert solve(B[:, 0]).shape == (M.shape[0],)
    assert all(0 < it <= 30 and st == 0 for _, it, st, _ in its)
    monkeypatch.setattr(solvers, "pcg", lambda *a, **k: (np.zeros((M.shape[0], 1)), 500, 1, [1.0]))
    stalled = solvers.mass_solver(M, minv)
    assert rel(stalled(B[:, 0]), ref[:, 0]) <= RTOL


def test_direct_solvers_agree_qdldl_cholmod_superlu(closed, monkeypatch):
    """``factorize``: QDLDL up to ``LDL_MAX`` unknowns, CHOLMOD above, pivoted SuperLU as the
    fallback; the three give the same solution of the HHJ system (1 and 3 columns)."""
    from igl_hhj import solvers
    A = HHJSystem(closed).csr()
    R = np.random.default_rng(2).normal(size=(A.shape[0], 3))
    used = []
    for name in ("_ldl", "_cholmod", "_splu"):
        real = getattr(solvers, name)
        monkeypatch.setattr(solvers, name, lambda M, _r=real, _n=name: used.append(_n) or _r(M))
    X = solvers.factorize(A)(R)
    x1 = solvers.factorize(A)(R[:, 0])
    monkeypatch.setattr(solvers, "LDL_MAX", 0)
    Xc = solvers.factorize(A)(R)
    Xl = solvers.factorize(A, prefer_lu=True)(R)
    assert used == ["_ldl", "_ldl", "_cholmod", "_splu"]
    assert rel(A @ X, R) <= 1e-12 and x1.shape == (A.shape[0],) and rel(x1, X[:, 0]) <= 1e-12
    assert rel(Xc, X) <= RTOL and rel(Xl, X) <= RTOL


def test_direct_solve_checks_its_residual_and_falls_back_to_pivoted_lu(closed, monkeypatch):
    """An unpivoted factorisation whose solution does not satisfy A X = R to
    ``DIRECT_RESIDUAL_RTOL`` (tiny pivots of a numerically semi-definite A) is replaced by
    pivoted LU; a zero pivot (qdldl refuses) goes to pivoted LU as well."""
    from igl_hhj import solvers
    A = HHJSystem(closed).csr()
    R = np.random.default_rng(3).normal(size=(A.shape[0], 2))
    good = solvers.cholesky_solve(A, R)
    calls = []
    real_lu = solvers._splu
    monkeypatch.setattr(solvers, "_splu", lambda M: calls.append(1) or real_lu(M))
    monkeypatch.setattr(solvers, "_ldl", lambda M: (lambda B, out=None: 1.001 * solvers._cholmod(M)(B)))
    X = solvers.cholesky_solve(A, R)
    assert calls == [1] and rel(X, good) <= RTOL
    Z = sp.csr_matrix(np.diag([1.0, 0.0, 2.0]))             # singular: qdldl's zero pivot
    monkeypatch.undo()
    assert solvers._ldl(Z) is None
    with pytest.raises(SolverError):
        solvers.cholesky_solve(Z, np.ones(3))


def _jittered_sliver_system():
    """An HHJ system of a jittered sphere with enough sliver DOFs for the two-level."""
    from igl_hhj import solvers
    V, F = icosphere(3)
    V = jitter_tangentially(V, F, Sphere(), 0.45, seed=7)
    m = TriangleMesh(V, F)
    system = HHJSystem(m)
    return system, system.sliver_dofs(angle=30.0), -kernels.jump_apply(m, m.V)[system.perm], solvers


def test_submatrix_equals_slicing_the_assembled_matrix(saddle):
    """HHJSystem.submatrix(S) (from the fixed-width rows of S alone) is A[S][:, S] of the
    assembled CSR, entry for entry, also with fixed (clamped) DOFs."""
    system, S, _, _ = _jittered_sliver_system()
    for sys_, dofs in ((system, S), (system, np.arange(system.n)), (system, S[:1])):
        ref = sys_.csr()[dofs][:, dofs].tocsr()
        ref.sum_duplicates()
        ref.eliminate_zeros()
        got = sys_.submatrix(dofs)
        assert np.array_equal(got.indptr, ref.indptr) and np.array_equal(got.indices, ref.indices)
        assert np.array_equal(got.data, ref.data)
    m = saddle[1]
    fixed = m.boundary_edges.copy()
    clamped = HHJSystem(m, fixed)
    free = np.flatnonzero(~clamped.fixed)
    ref = clamped.csr()[free][:, free].tocsr()
    ref.sum_duplicates()
    ref.eliminate_zeros()
    got = clamped.submatrix(free)
    assert np.array_equal(got.toarray(), ref.toarray())


def test_native_ldl_subdomain_equals_python_subdomain_solve():
    """The two-level's sliver solve through ``subdomain_ldl`` (QDLDL's factor solved in the
    compiled PCG, k columns at once) gives the iterates of the same factor solved from Python
    (``subdomain_solve``), run after run."""
    system, S, rhs, solvers = _jittered_sliver_system()
    assert len(S) > 20
    A = system.csr()[S][:, S].tocsr()
    level = system._two_level(S)
    assert set(level) == {"subdomain_ldl"}
    py = solvers._ldl(A)
    kw = dict(rtol=1e-10, maxiter=500, M=(system.indptr, system._cols_flat, system.M.ravel()), subdomain=S)
    args = (system.indptr, system._cols_flat, system.A.ravel(), rhs)
    Xn, itn, stn, _ = solvers.pcg(*args, subdomain_ldl=level["subdomain_ldl"], **kw)
    Xp, itp, stp, _ = solvers.pcg(*args, subdomain_solve=lambda r, z: py(r, out=z), **kw)
    assert stn == stp == 0 and abs(itn - itp) <= 1
    assert rel(Xn, Xp) <= 1e-9
    assert np.array_equal(Xn, solvers.pcg(*args, subdomain_ldl=level["subdomain_ldl"], **kw)[0])


def test_native_ldl_subdomain_is_bit_identical_for_one_and_two_threads(monkeypatch):
    """Above the PCG's thread threshold the sliver factor is solved by two threads, one per
    group of elimination trees (scattered slivers: many trees); the iterates are the same
    bits as with one thread, and agree with the factor solved from Python."""
    from igl_hhj import solvers
    V, F = icosphere(6)
    V = jitter_tangentially(V, F, Sphere(), 0.45, seed=7)
    m = TriangleMesh(V, F)
    system = HHJSystem(m)
    S = system.sliver_dofs(angle=30.0)
    rhs = -kernels.jump_apply(m, m.V)[system.perm]
    assert system.n * 3 >= 200_000 and len(S) > 1000
    level = system._two_level(S)
    assert set(level) == {"subdomain_ldl"}
    kw = dict(rtol=1e-10, maxiter=500, M=(system.indptr, system._cols_flat, system.M.ravel()), subdomain=S)
    args = (system.indptr, system._cols_flat, system.A.ravel(), rhs)
    monkeypatch.setattr(kernels, "ADAPT_TO_LOAD", False)
    nt = kernels.max_threads()
    try:
        kernels.set_num_threads(1)
        one = solvers.pcg(*args, subdomain_ldl=level["subdomain_ldl"], **kw)
        kernels.set_num_threads(2)
        two = solvers.pcg(*args, subdomain_ldl=level["subdomain_ldl"], **kw)
    finally:
        kernels.set_num_threads(nt)
    assert one[2] == two[2] == 0 and one[1] == two[1]
    assert np.array_equal(one[0], two[0])
    py = solvers._ldl(system.csr()[S][:, S].tocsr())
    ref = solvers.pcg(*args, subdomain_solve=lambda r, z: py(r, out=z), **kw)
    assert rel(two[0], ref[0]) <= 1e-9


def test_two_level_falls_back_to_pivoted_lu_when_ldl_is_not_positive(monkeypatch):
    """A sliver block whose LDLᵀ has a non-positive pivot (numerically semi-definite) is
    solved by pivoted LU from Python instead."""
    system, S, rhs, solvers = _jittered_sliver_system()
    real = solvers._qdldl_factor

    class Negative:
        def __init__(self, A):
            self.f = real(A)

        def factors(self):
            L, d, p = self.f.factors()
            return L, np.where(np.arange(len(d)) == 0, -d, d), p
    monkeypatch.setattr(solvers, "_qdldl_factor", Negative)
    level = system._two_level(S)
    assert set(level) == {"subdomain_solve"}
    r = np.random.default_rng(0).normal(size=(len(S), 3))
    z = np.empty_like(r)
    level["subdomain_solve"](r, z)
    assert rel(system.csr()[S][:, S] @ z, r) <= 1e-10


def test_block_pcg_rejects_bad_subdomain_ldl():
    system, S, rhs, solvers = _jittered_sliver_system()
    L, d, perm = solvers._qdldl_factor(system.csr()[S][:, S].tocsr()).factors()
    L = sp.csc_matrix(L)
    good = (L.indptr, L.indices, L.data, d, perm)
    kw = dict(rtol=1e-8, maxiter=50, M=(system.indptr, system._cols_flat, system.M.ravel()), subdomain=S)
    args = (system.indptr, system._cols_flat, system.A.ravel(), rhs)
    bad_perm = perm.copy()
    bad_perm[0] = bad_perm[1]
    upper = L.indices.copy()
    upper[0] = 0
    j = int(np.flatnonzero(np.diff(L.indptr) > 0)[0])      # a column with entries
    decreasing = L.indptr.copy()
    decreasing[j + 1] = decreasing[j] - 1 if j > 0 else decreasing[j + 2] + 1
    shifted = L.indptr.copy()
    shifted[0] = 1
    for bad, match in [((L.indptr, L.indices, L.data, d, bad_perm), "permutation"),
                       ((L.indptr, upper, L.data, d, perm), "strictly lower"),
                       ((decreasing, L.indices, L.data, d, perm), "not monotone"),
                       ((shifted, L.indices, L.data, d, perm), "subdomain_ldl Lp$"),
                       ((L.indptr[:-1], L.indices, L.data, d, perm), "shapes"),
                       (good[:4], "Lp, Li, Lx, D, perm")]:
        with pytest.raises(ValueError, match=match):
            kernels.block_pcg(*args, subdomain_ldl=bad, **kw)
    with pytest.raises(TypeError, match="not both"):
        kernels.block_pcg(*args, subdomain_ldl=good, subdomain_solve=lambda r, z: None, **kw)


def test_topology_refuses_sizes_beyond_its_32_bit_keys():
    """The topology kernel packs (vertex, half-edge) into 64-bit keys: more than 2**32 - 1
    vertices (or 1.43e9 faces) is a ValueError, not a wrong answer."""
    with pytest.raises(ValueError, match="at most"):
        kernels.topology(np.array([[0, 1, 2]]), 2 ** 32)


def test_topology_refuses_sizes_beyond_its_int32_maps():
    """The maps hold int32 indices: 2**31 vertices or faces are a ValueError before any
    work (the face array is a broadcast view: no 2**31 x 3 array is made)."""
    with pytest.raises(ValueError, match="at most 2\\*\\*31 - 1 vertices, faces"):
        kernels.topology(np.array([[0, 1, 2]]), 2 ** 31)
    with pytest.raises(ValueError, match="at most 2\\*\\*31 - 1 vertices, faces"):
        kernels.topology(np.broadcast_to(np.array([[0, 1, 2]]), (2 ** 31, 3)), 3)
    with pytest.raises(ValueError, match="2\\*\\*31 - 1 vertices"):     # the binding's own check
        kernels._core.topology(np.array([[0, 1, 2]]), 2 ** 31)


def test_topology_count_saturates_and_the_error_names_the_true_count():
    """edge_face_count is int8, saturated at 127: an edge of 200 faces stays non-manifold
    (not 200 mod 256 = 72 -> 'fine'), and the error counts the faces exactly."""
    k = 200
    a = np.linspace(0, 2 * np.pi, k, endpoint=False)
    V = np.r_[[[0.0, 0, 0], [0, 0, 1]], np.c_[np.cos(a), np.sin(a), np.full(k, 0.5)]]
    F = np.c_[np.zeros(k, int), np.ones(k, int), 2 + np.arange(k)]
    count = kernels.topology(F, len(V))[2]
    assert count.dtype == np.int8 and count.max() == 127
    assert np.array_equal(count, topology_reference(F)[2])
    with pytest.raises(ValueError, match=f"non-manifold.*with {k} faces"):
        TriangleMesh(V, F)


# --- large-call heap scope (igl_hhj/_core/heap.cpp) -------------------------------------

def test_large_call_heap_engages_only_above_glibc_ceiling(monkeypatch):
    monkeypatch.delenv("MALLOC_MMAP_THRESHOLD_", raising=False)
    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)
    monkeypatch.delenv("GLIBC_TUNABLES", raising=False)
    with kernels.large_call_heap(100_000) as active:      # (#E, 3) arrays of 3.6 MB
        assert active is False
        assert kernels._core.heap_scope_depth() == 0
    on_glibc = sys.platform.startswith("linux")
    with kernels.large_call_heap(1_000_000) as active:    # 36 MB > 32 MiB
        assert kernels._core.heap_scope_depth() == 1
        assert active is on_glibc
        with kernels.large_call_heap(2_000_000):           # nests
            assert kernels._core.heap_scope_depth() == 2
        assert kernels._core.heap_scope_depth() == 1
    assert kernels._core.heap_scope_depth() == 0
    monkeypatch.setattr(kernels, "LARGE_CALL_HEAP", False)
    with kernels.large_call_heap(10_000_000) as active:
        assert active is False and kernels._core.heap_scope_depth() == 0


def test_large_call_heap_leaves_a_user_malloc_policy_alone(monkeypatch):
    for var, value in (("MALLOC_MMAP_THRESHOLD_", "1000000"),
                       ("GLIBC_TUNABLES", "glibc.malloc.trim_threshold=1000000")):
        with monkeypatch.context() as mp:
            mp.setenv(var, value)
            with kernels.large_call_heap(10_000_000) as active:
                assert active is False and kernels._core.heap_scope_depth() == 0


def test_large_call_heap_closes_on_errors_and_across_threads(monkeypatch):
    monkeypatch.setattr(kernels, "_GLIBC_MMAP_CEILING", 0)   # engage on small meshes
    V, F = icosphere(2)
    with pytest.raises(ValueError):
        igl_hhj.principal_curvature(V, F[:, :2])
    assert kernels._core.heap_scope_depth() == 0
    errors = []

    def work():
        try:
            for _ in range(3):
                igl_hhj.principal_curvature(V, F)
        except Exception as exc:   # pragma: no cover - reported below
            errors.append(exc)
    threads = [threading.Thread(target=work) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert kernels._core.heap_scope_depth() == 0


def test_large_call_heap_does_not_change_results(monkeypatch):
    V, F = icosphere(3)
    V = jitter_tangentially(V, F, Sphere(), 0.3, seed=3)
    monkeypatch.setattr(kernels, "LARGE_CALL_HEAP", False)
    ref = igl_hhj.principal_curvature(V, F)
    S_ref = igl_hhj.shape_operator(V, F)
    monkeypatch.setattr(kernels, "LARGE_CALL_HEAP", True)
    monkeypatch.setattr(kernels, "_GLIBC_MMAP_CEILING", 0)
    out = igl_hhj.principal_curvature(V, F)
    for a, b in zip(ref[:4], out[:4]):
        np.testing.assert_array_equal(a, b)
    assert ref[4] == out[4]
    np.testing.assert_array_equal(S_ref, igl_hhj.shape_operator(V, F))


def test_dropin_frees_the_face_tensors_before_its_memory_peak(monkeypatch):
    """The drop-in frees the (#F, 3, 3) face tensors after the recovery, before the
    smoothing (its memory peak), and gives the same values as the public composition."""
    import weakref

    from igl_hhj import curvature
    V, F = icosphere(4)
    V = jitter_tangentially(V, F, Sphere(), 0.3, seed=1)
    alive = {}
    real_S, real_smooth = curvature._shape_operator, kernels.intrinsic_smoothing

    def shape_operator(*a, **k):
        S = real_S(*a, **k)
        alive["S"] = weakref.ref(S)
        return S

    def smooth(*a, **k):
        alive["at smoothing"] = alive["S"]() is not None
        return real_smooth(*a, **k)
    monkeypatch.setattr(curvature, "_shape_operator", shape_operator)
    monkeypatch.setattr(kernels, "intrinsic_smoothing", smooth)
    out = igl_hhj.principal_curvature(V, F)
    assert alive["at smoothing"] is False
    monkeypatch.undo()
    m = TriangleMesh(V, F)
    ref = curvature.dropin_vertex_values(m, igl_hhj.shape_operator(m), 5)
    for a, b in zip(ref, out):
        np.testing.assert_array_equal(a, b)


def test_envelope_ldl_agrees_with_the_sparse_direct_solve():
    """The compiled small-system solve (tiny meshes) is the sparse direct solve to round-off,
    refuses a semi-definite matrix (status 1: the caller pivots) and a bad index (status 3)."""
    from igl_hhj import solvers
    V, F = icosphere(1)
    rng = np.random.default_rng(3)
    mesh = as_mesh(V + 0.02 * rng.standard_normal(V.shape), F)
    system = solvers.HHJSystem(mesh)
    assert system.n <= solvers.ENVELOPE_MAX
    R = rng.standard_normal((system.n, 3))
    X, status = kernels.envelope_ldl_solve(system.indptr, system._cols_flat, system.A.ravel(), R, 1e-8)
    assert status == 0
    Y = solvers.cholesky_solve(system.csr(), R)
    assert np.abs(X - Y).max() <= 1e-12 * np.abs(Y).max()
    # a larger system: its packed envelope (~1 MB) lives in its own mapping, not the heap
    big = solvers.HHJSystem(as_mesh(*icosphere(3)))
    R = rng.standard_normal((big.n, 3))
    X, status = kernels.envelope_ldl_solve(big.indptr, big._cols_flat, big.A.ravel(), R, 1e-8)
    Y = solvers.cholesky_solve(big.csr(), R)
    assert status == 0 and np.abs(X - Y).max() <= 1e-12 * np.abs(Y).max()
    # a singular matrix: the unpivoted factorisation stops and says so
    indptr = np.array([0, 2, 4])
    cols = np.array([0, 1, 0, 1], dtype=np.int32)
    _, status = kernels.envelope_ldl_solve(indptr, cols, np.array([1.0, 1.0, 1.0, 1.0]), np.ones((2, 1)), 1e-8)
    assert status == 1
    _, status = kernels.envelope_ldl_solve(indptr, np.array([0, 5, 0, 1], dtype=np.int32),
                                           np.array([2.0, 1.0, 1.0, 2.0]), np.ones((2, 1)), 1e-8)
    assert status == 3


def test_tiny_meshes_take_the_envelope_solve_and_match_the_reference(monkeypatch):
    """A drop-in call on a tiny mesh uses the compiled envelope solve, never scipy's
    sparse factorisation, and its shape operator is the numpy reference's."""
    from igl_hhj import curvature, solvers
    V, F = icosphere(1)
    called = []
    monkeypatch.setattr(solvers, "cholesky_solve", lambda *a, **k: called.append(1))
    S = curvature.shape_operator(V, F)
    assert not called
    monkeypatch.undo()
    ref = curvature._shape_operator_reference(as_mesh(V, F))
    assert np.abs(S - ref).max() <= 1e-10 * np.abs(ref).max()


def _open_meshes_for_boundary_normals():
    """Open meshes whose boundary normal fits take every branch: a jittered saddle, a
    jittered cap cut from a sphere, a flat 6×6 grid (its corners' 1-rings have < 10
    vertices: one ring more), a strip too small for a fit (fewer than 6 neighbours), and
    a fan whose vertices all lie on two lines (xy ≡ 0: a singular Gram matrix, decided by
    the eigenvalue test, not the cheap condition bound)."""
    surface, seq = sequence("saddle", 3)
    out = {"saddle": seq[-1]}
    V, F = _bumpy(2)
    keep = V[F].mean(axis=1)[:, 2] < 0.2
    out["cap"] = (V, F[keep])
    n = 6
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    Vg = np.c_[x.ravel(), y.ravel(), np.zeros(n * n)]
    q = np.arange(n * n).reshape(n, n)[:-1, :-1].ravel()
    Fg = np.r_[np.c_[q, q + 1, q + n + 1], np.c_[q, q + n + 1, q + n]]
    out["flat grid"] = (Vg, Fg)
    out["strip"] = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.1], [0, 2, 0.3]], float),
                    np.array([[0, 1, 2], [1, 3, 2], [2, 3, 4]]))
    Va = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [0, 2, 0], [-1, 0, 0], [-2, 0, 0]], float)
    out["axes"] = (Va, np.array([[0, 1, 3], [1, 2, 3], [3, 2, 4], [0, 3, 5], [5, 3, 4], [5, 4, 6]]))
    return out


@pytest.mark.parametrize("name", ["saddle", "cap", "flat grid", "strip", "axes"])
@pytest.mark.parametrize("rings", [1, 3])
def test_boundary_normal_fits_equal_reference(name, rings):
    """The compiled quadric fits of estimate_boundary_normals equal the numpy reference."""
    from igl_hhj.boundary_estimation import boundary_normal_fits_reference, estimate_boundary_normals
    V, F = _open_meshes_for_boundary_normals()[name]
    m = TriangleMesh(V, F)
    verts = np.flatnonzero(m.boundary_vertices)
    N0 = m.vertex_normals[verts]
    got = kernels.boundary_normal_fits(m, verts, rings, N0)
    ref = boundary_normal_fits_reference(m, verts, rings, N0)
    assert got.shape == (len(verts), 3)
    assert np.allclose(got, ref, rtol=0, atol=1e-12)
    a = estimate_boundary_normals(m, rings)
    b = estimate_boundary_normals(m, rings, reference=True)
    assert np.array_equal(np.isnan(a), np.isnan(b))
    assert np.allclose(a[~np.isnan(b)], b[~np.isnan(b)], rtol=0, atol=1e-12)


def test_boundary_normal_fits_reject_bad_arrays():
    V, F = _open_meshes_for_boundary_normals()["saddle"]
    m = TriangleMesh(V, F)
    verts = np.flatnonzero(m.boundary_vertices)
    N0 = m.vertex_normals[verts]
    with pytest.raises(ValueError, match="boundary_normal_fits"):
        kernels.boundary_normal_fits(m, verts, 3, N0[:-1])
    with pytest.raises(ValueError, match="rings"):
        kernels.boundary_normal_fits(m, verts, 0, N0)
    with pytest.raises(ValueError, match="out of range"):
        kernels.boundary_normal_fits(m, np.r_[verts[:-1], m.n_vertices], 3, N0)
