"""The solvers of the HHJ system and of generic SPD systems: the compiled block PCG,
the direct solvers and their fall-backs, the two-level preconditioner, the envelope LDLᵀ."""

import numpy as np
import pytest
import scipy.sparse as sp

import igl_hhj
from igl_hhj import kernels
from igl_hhj.errors import SolverError
from igl_hhj.hhj import solve_spd
from igl_hhj.mesh import TriangleMesh, as_mesh
from igl_hhj.solvers import HHJSystem
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially
from kernel_cases import RTOL, closed, rel, saddle  # noqa: F401 (closed, saddle: pytest fixtures)


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
