"""Solver strategy for the HHJ system ``A s^k = -B X^k + g^k`` (and generic SPD systems).

Three ways to solve, chosen per call:

* ``"direct"``: one sparse factorisation for all right-hand sides (:func:`factorize`):
  QDLDL (AMD ordering, LDLᵀ) up to :data:`LDL_MAX` unknowns, CHOLMOD (``cholespy``) above.
* ``"cg"``: the compiled fused block PCG (:func:`igl_hhj.kernels.block_pcg`),
  preconditioned by a two-level method: the face-Schwarz preconditioner (exact
  inverses of every face's 3×3 block of A) plus an exact sparse solve on the DOFs of
  the faces with a smallest angle below :data:`SLIVER_ANGLE` (where A's
  ill-conditioning lives; a QDLDL factor solved inside the compiled PCG).  Without
  the second level, sliver meshes need 400–800 iterations (camelhead 811, bunny
  upsampled twice 417); with it 40–60.
* ``"auto"`` (default): direct below :data:`AUTO_DIRECT_MAX` unknowns or when more
  than :data:`SLIVER_MAX_FRACTION` of the DOFs lie on sliver faces; otherwise
  the same PCG, which checks its convergence rate every :data:`PROBE_ITER`
  iterations and, when the iterations still needed (extrapolated from the rate so far)
  would cost more than the estimated factorisation (:func:`_direct_seconds`), stops and factorises instead.
  Above :data:`DIRECT_MAX` unknowns (memory) PCG always runs to the end.

Tolerance
---------
``rtol`` is the relative residual ``‖r_j‖ ≤ rtol ‖R_j‖`` per right-hand side.
The default :data:`DEFAULT_RTOL` = 1e-6 of the public curvature functions is tied to
the discretisation error: ``python -m igl_hhj.benchmarks.speed --rtol-study`` measures
the L2 vertex error of H against the exact surface on jittered ellipsoids (20k–328k
faces) and Walker's sliver torus; at 1e-6 it differs from the error at 1e-12 by at
most 0.0004 % (1e-4: up to 0.03 %, growing about 4× per refinement; 1e-3: 3.6 % at
328k faces), for 35–50 % fewer iterations than 1e-12.

Generic SPD systems
-------------------
:func:`solve_spd` solves any sparse SPD system (mass matrices, the curved HHJ systems of
:mod:`igl_hhj.curved`, the numpy reference :class:`igl_hhj.hhj.HHJProjection`) with a
simpler rule: ``"auto"`` factorises up to :data:`SPD_AUTO_DIRECT_MAX` (50 000) unknowns,
above runs PCG and switches after :data:`SPD_AUTO_CG_MAXITER` predicted iterations;
default tolerance 1e-10.  The drop-in's HHJ system never goes through it.
"""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

try:  # imported here, not in the first solve (so that a first call costs as the later ones)
    from cholespy import CholeskySolverD, MatrixType
except ImportError:  # pragma: no cover - cholespy is a dependency
    CholeskySolverD = MatrixType = None
try:
    import qdldl as _qdldl
except ImportError:  # pragma: no cover - qdldl is a dependency
    _qdldl = None

from . import kernels
# the strategy's constants (values and the measurements behind them: igl_hhj.constants), as
# globals of this module: a study may set e.g. ``solvers.SLIVER_ANGLE`` for the solver alone
from .constants import (AUTO_DIRECT_MAX, CG_MAXITER, DEFAULT_RTOL, DIRECT_MAX, DIRECT_RESIDUAL_RTOL,
                        ENVELOPE_MAX, LDL_MAX, PROBE_ITER, SLIVER_ANGLE, SLIVER_MAX_FRACTION,
                        SPD_AUTO_CG_MAXITER, SPD_AUTO_DIRECT_MAX)
from .errors import SolverDidNotConverge, SolverError

__all__ = ["DEFAULT_RTOL", "HHJSystem", "cholesky_solve", "mass_solver", "pcg", "SolveInfo", "solve_spd"]



class SolveInfo(dict):
    """What a solve did: ``solver`` ("direct"/"cg"), ``iterations``, ``seconds``, ``switched``."""


def _direct_seconds(n):
    """Estimated time of one sparse factorisation + solve of the HHJ matrix (n unknowns) by
    :func:`factorize`: power-law fits to ``python -m igl_hhj.benchmarks.speed --factor-study``
    on this machine.  QDLDL up to :data:`LDL_MAX`: 12 ms at 10k unknowns (bunny), 50 ms at
    34k (camelhead), 88 ms at 58k (the open scan), 0.46 s at 167k (bunny upsampled twice),
    0.55 s at 123k (the jittered ellipsoid, more fill); CHOLMOD above: 2.9 s at 393k."""
    if n <= LDL_MAX:
        return 5.0e-8 * n ** 1.33
    return 3.9e-7 * n ** 1.255


def _pcg_iter_seconds(n, k):
    """Estimated time of one fused PCG iteration (n unknowns, k right-hand sides), face-Schwarz
    level only: ≈ 1 ms at 34k unknowns with the sliver level (camelhead), 8.5 ms at 393k
    (Walker's sliver torus), 2 threads (``--sliver-study``; the two-level adds
    ``2|S|/n`` of this, see :meth:`HHJSystem._pcg`)."""
    return 0.6e-8 * n * (1 + k)


def _splu(A):
    """SuperLU with partial pivoting and its default COLAMD ordering (the fallback for
    numerically semi-definite matrices; the symmetric minimum-degree ordering loses its
    sparsity under pivoting: 30 s instead of 0.25 s on the open scan)."""
    # imported here, not with the module: scipy.sparse.linalg loads scipy's OpenBLAS, whose
    # worker threads spin for a while after loading and, on a 2-core machine, slowed the
    # libigl calls of a drop-in call made just after import by 4-8 ms each (fandisk: first
    # call 1.5x the later ones); the drop-in's usual path never needs it
    import scipy.sparse.linalg as spla
    try:
        return spla.splu(sp.csc_matrix(A)).solve
    except RuntimeError as exc:
        raise SolverError(f"sparse LU failed: {exc}") from None


def _qdldl_factor(A):
    """QDLDL factorisation (AMD + LDLᵀ, no pivoting) of symmetric CSR A: the ``qdldl.Solver``,
    or None when qdldl is missing or meets a zero pivot."""
    if _qdldl is None:  # pragma: no cover
        return None
    # CSR of a symmetric matrix read as CSC is the same matrix: no conversion
    try:
        return _qdldl.Solver(sp.csc_matrix((A.data, A.indices, A.indptr), shape=A.shape))
    except (ValueError, RuntimeError):
        return None


def _ldl(A):
    """QDLDL factorisation of symmetric CSR A: a ``solve(R, out=None)`` callable ((n,) or
    (n, k) R), or None (see :func:`_qdldl_factor`)."""
    f = _qdldl_factor(A)
    if f is None:
        return None

    def solve(R, out=None):
        R = np.asarray(R, dtype=np.float64)
        if R.ndim == 1:
            X = f.solve(R)
            if out is None:
                return X
            out[...] = X
            return out
        X = np.empty_like(R) if out is None else out
        for j in range(R.shape[1]):
            X[:, j] = f.solve(np.ascontiguousarray(R[:, j]))
        return X
    return solve


def _cholmod(A):
    """CHOLMOD (cholespy) factorisation of SPD CSR A: a solve(R) callable, or None when
    cholespy is missing or finds A not numerically positive definite."""
    if CholeskySolverD is None:  # pragma: no cover
        return None
    try:
        ch = CholeskySolverD(A.shape[0], A.indptr.astype(np.int32), A.indices.astype(np.int32),
                             np.ascontiguousarray(A.data), MatrixType.CSR)
    except (ValueError, RuntimeError):
        return None

    def solve(R, out=None):
        X = np.empty_like(R) if out is None else out
        ch.solve(R, X)
        return X
    return solve


def _canonical_csr(A):
    """``A`` as scipy CSR with sorted indices and summed duplicates; a copy when that
    needs changing (``sum_duplicates`` works in place: the caller's matrix is left alone)."""
    A = sp.csr_matrix(A)
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    return A


def factorize(A, *, prefer_lu=False):
    """One sparse factorisation of a symmetric positive (semi-)definite A: a ``solve(R)`` callable.

    Up to :data:`LDL_MAX` unknowns QDLDL, above CHOLMOD; LU with partial pivoting
    (SuperLU) when ``prefer_lu`` is set (matrices known to be numerically semi-definite,
    e.g. with faces of relative area ~1e-9) or when the first choice fails.
    ``R`` (n,) or (n, k) float64."""
    A = _canonical_csr(A)
    if not prefer_lu:
        fn = _ldl(A) if A.shape[0] <= LDL_MAX else _cholmod(A)
        if fn is not None:
            return fn
    return _splu(A)


def cholesky_solve(A, R):
    """Solve ``A X = R`` for SPD sparse A by one sparse factorisation (:func:`factorize`).

    ``R`` (n,) or (n, k).  The unpivoted factorisation is tried first even where A is
    numerically semi-definite (the open scan's one face with a singular 3×3 block:
    pivoted SuperLU took 3x longer than QDLDL); its solution is kept when its relative
    residual is at most :data:`DIRECT_RESIDUAL_RTOL` (one extra product with A), else
    pivoted LU solves again.  Raises :class:`SolverError` when the factorisation
    fails or the solution is not finite."""
    R = np.ascontiguousarray(R, dtype=np.float64)
    n = A.shape[0]
    if n == 0:
        return np.zeros_like(R)
    A = _canonical_csr(A)
    X = factorize(A)(R)
    R2 = R.reshape(n, -1)
    res = np.linalg.norm((A @ X.reshape(n, -1)) - R2, axis=0)
    if not (np.isfinite(X).all() and np.all(res <= DIRECT_RESIDUAL_RTOL * np.linalg.norm(R2, axis=0))):
        X = factorize(A, prefer_lu=True)(R)
    if not np.isfinite(X).all():
        raise SolverError("the sparse direct solve produced non-finite values (matrix numerically singular)")
    return X


def mass_solver(M, lumped_inv, rtol=1e-13):
    """``solve(b) = M⁻¹ b`` (b of shape (n,) or (n, k)) for a consistent P1 mass matrix,
    by the compiled PCG preconditioned with the lumped mass.

    On every P1 triangle the element mass ``|T|/12 (1 + δ_ij)`` has eigenvalues
    ``{1, 1/4, 1/4}`` times the lumped one ``|T|/3``, so the spectrum of ``M_L⁻¹ M`` lies
    in [1/4, 1] whatever the mesh quality: CG gains a factor ≥ 3 per iteration (≈ 27
    iterations for 1e-13).  No factorisation, no fill: 0.1 s per solve at 603k vertices.
    If the PCG stalls (zero-area faces: zero lumped mass) the matrix is factorised
    instead (:func:`factorize`).

    Parameters
    ----------
    M : (n, n) sparse SPD, the consistent mass
    lumped_inv : (n,) float64, ``1 / rowsum(M)``
    rtol : float, relative residual per column
    """
    M = _canonical_csr(M)
    fallback = []

    def solve(b):
        b = np.asarray(b, dtype=np.float64)
        if fallback:
            return fallback[0](np.ascontiguousarray(b))
        X, _, status, _ = pcg(M.indptr, M.indices, M.data, b.reshape(len(b), -1),
                              rtol=rtol, maxiter=500, dinv=lumped_inv)
        if status != 0 or not np.isfinite(X).all():
            fallback.append(factorize(M))
            return fallback[0](np.ascontiguousarray(b))
        return X.reshape(b.shape)

    return solve


def pcg(indptr, indices, data, R, *, rtol, maxiter, M=None, dinv=None, probe_iter=0,
        max_predicted=np.inf, subdomain=None, subdomain_solve=None, subdomain_ldl=None,
        overwrite_R=False, coupled=False):
    """Compiled block PCG on all columns of ``R`` (n, k), in groups of 16.

    Returns ``(X, iterations, status, relres)`` (see :func:`igl_hhj.kernels.block_pcg`;
    iterations / status are the worst over the groups).  ``overwrite_R`` (k ≤ 16 only):
    R (C-contiguous float64) is used as the residual buffer and holds the final
    residual afterwards.  ``coupled`` (k ≤ 16 only): one CG on all columns
    (:func:`igl_hhj.kernels.block_pcg`)."""
    if R.shape[1] <= 16:
        return kernels.block_pcg(indptr, indices, data, R, rtol=rtol, maxiter=maxiter, M=M, dinv=dinv,
                                 probe_iter=probe_iter, max_predicted=max_predicted,
                                 subdomain=subdomain, subdomain_solve=subdomain_solve,
                                 subdomain_ldl=subdomain_ldl, overwrite_R=overwrite_R, coupled=coupled)
    if coupled:
        raise ValueError("coupled PCG takes at most 16 right-hand sides")
    R = np.ascontiguousarray(R, dtype=np.float64)
    X = np.empty_like(R)
    its, statuses, relres = [0], [0], []
    for j in range(0, R.shape[1], 16):
        X[:, j:j + 16], it, st, rr = kernels.block_pcg(
            indptr, indices, data, R[:, j:j + 16], rtol=rtol, maxiter=maxiter, M=M, dinv=dinv,
            probe_iter=probe_iter, max_predicted=max_predicted, subdomain=subdomain,
            subdomain_solve=subdomain_solve, subdomain_ldl=subdomain_ldl)
        its.append(it)
        statuses.append(st)
        relres += list(rr)
        if st != 0:
            break
    return X, max(its), max(statuses), relres


def solve_spd(A, R, *, method="auto", rtol=1e-10, maxiter=None, preconditioner=None):
    """Solve ``A X = R`` for an SPD sparse A and all columns of R at once.

    Parameters
    ----------
    A : (n, n) scipy.sparse SPD matrix
    R : (n,) or (n, k) right-hand sides
    method : {"auto", "cg", "direct"}
        "cg": the compiled fused block PCG (:func:`igl_hhj.kernels.block_pcg`)
        over the k columns, preconditioned by ``preconditioner`` (a sparse SPD
        approximation of A⁻¹, e.g. :func:`face_schwarz_preconditioner`) or,
        without one, Jacobi.
        "direct": one sparse factorisation (:func:`igl_hhj.solvers.cholesky_solve`:
        QDLDL up to 200k unknowns, CHOLMOD via cholespy above, pivoted SuperLU when the
        residual check fails).
        "auto": direct up to ``SPD_AUTO_DIRECT_MAX`` (50 000) unknowns; above,
        PCG, switching to the direct solver as soon as the measured
        convergence rate predicts more than ``maxiter`` (default
        ``SPD_AUTO_CG_MAXITER`` = 600) further iterations (checked every 20 iterations).
    rtol : float
        CG stops when ``‖r_j‖ ≤ rtol ‖R_j‖`` for every column j.  The default
        1e-10 leaves a solver error far below every discretisation error in
        the convergence tables (tests compare CG with the direct solve).
    maxiter : int, optional
        CG iteration cap (default 2000 for "cg", 600 for "auto").
    preconditioner : (n, n) scipy.sparse matrix, optional
        Applied as ``z = M r``.  Anything else with ``@`` (e.g. a
        ``LinearOperator``) runs the numpy reference PCG :func:`_block_pcg`.

    Raises
    ------
    SolverDidNotConverge
        method="cg" and CG did not reach ``rtol`` within ``maxiter`` iterations.
    """
    R = np.asarray(R, dtype=np.float64)
    vec = R.ndim == 1
    if vec:
        R = R[:, None]
    n = A.shape[0]
    if method not in ("auto", "cg", "direct"):
        raise ValueError(f"unknown solver method {method!r}; use 'auto', 'cg' or 'direct'")
    if method == "auto" and n <= SPD_AUTO_DIRECT_MAX:
        method = "direct"
    X = None
    if maxiter is None:
        maxiter = SPD_AUTO_CG_MAXITER if method == "auto" else 2000
    if method in ("cg", "auto") and n > 0:
        if preconditioner is not None and not sp.issparse(preconditioner):
            try:
                X = _block_pcg(sp.csr_matrix(A), R, rtol, maxiter, preconditioner)
            except SolverDidNotConverge:
                if method == "cg":
                    raise
        else:
            Ac = sp.csr_matrix(A)
            Mc = None
            dinv = None
            if preconditioner is None:
                dinv = 1.0 / Ac.diagonal()
            else:
                Mc = sp.csr_matrix(preconditioner)
                Mc = (Mc.indptr, Mc.indices, Mc.data)
            Xc, it, status, relres = pcg(
                Ac.indptr, Ac.indices, Ac.data, R, rtol=rtol, maxiter=maxiter, M=Mc, dinv=dinv,
                probe_iter=20 if method == "auto" else 0, max_predicted=maxiter)
            if status == 0:
                X = Xc
            elif method == "cg":
                raise SolverDidNotConverge(
                    f"preconditioned CG did not converge in {it} iterations "
                    f"(relative residual {max(relres):.2e} > {rtol:.1e}); the mesh may contain "
                    f"near-degenerate triangles. Use solver='direct' or solver='auto'.")
    if X is None:
        X = np.zeros_like(R) if n == 0 else cholesky_solve(A, R)
    return X[:, 0] if vec else X


def _block_pcg(A, R, rtol, maxiter, M=None):
    """The numpy reference of the compiled block PCG: CG on the columns of R at once (independent recurrences,
    shared sparse products).  Buffers are reused: at 10⁵–10⁶ unknowns each
    iteration is memory-bound."""
    n, k = R.shape
    if maxiter is None:
        maxiter = 2000
    if M is None:
        dinv = (1.0 / A.diagonal())[:, None]
        def apply(r):  # noqa: E306
            return dinv * r
    else:
        def apply(r):  # noqa: E306
            return M @ r
    tmp = np.empty((n, k))
    ones = np.ones(n)

    def coldot(a, b):  # column-wise dot products; `ones @` is a BLAS gemv, 50x faster than .sum(0)
        np.multiply(a, b, out=tmp)
        return ones @ tmp

    X = np.zeros((n, k))
    r = R.copy()
    bb = coldot(R, R)
    tol2 = (rtol ** 2) * bb
    rr = bb
    active = rr > tol2
    if not active.any():
        return X
    z = apply(r)
    p = z.copy()
    rz = coldot(r, z)
    for _ in range(maxiter):
        q = A @ p
        pq = coldot(p, q)
        alpha = np.where(active, rz / np.where(active, pq, 1.0), 0.0)
        np.multiply(p, alpha, out=tmp)
        X += tmp
        np.multiply(q, alpha, out=tmp)
        r -= tmp
        rr = coldot(r, r)
        active = rr > tol2
        if not active.any():
            return X
        z = apply(r)
        rz_new = coldot(r, z)
        beta = np.where(active, rz_new / np.where(active, rz, 1.0), 0.0)
        rz = rz_new
        p *= beta
        p += z
    worst = float(np.max(np.sqrt(rr / np.where(bb > 0, bb, 1.0))))
    raise SolverDidNotConverge(
        f"preconditioned CG did not converge in {maxiter} iterations "
        f"(relative residual {worst:.2e} > {rtol:.1e}); the mesh may contain "
        f"near-degenerate triangles. Use solver='direct' or solver='auto'.")



class HHJSystem:
    """The assembled HHJ matrix A of one mesh (compiled), ready to solve.

    ``A[e, e'] = Σ_T |T| φ_e : φ_e'`` (Walker eq. 5.14) in a fixed-width row
    format (5 slots per edge, :func:`igl_hhj.kernels.hhj_system`), with the
    face-Schwarz preconditioner in the same format.  Fixed (simply supported)
    DOFs become identity rows with zero right-hand side, so one square system
    of size #E is solved whatever the boundary partition.

    Parameters
    ----------
    mesh : TriangleMesh
    fixed : (#E,) bool, optional
        Fixed DOFs (their values are passed to :meth:`solve`).
    """

    def __init__(self, mesh, fixed=None):
        self.mesh = mesh
        n = mesh.n_edges
        # Internally the edges are renumbered along a Morton curve (memory locality of
        # the sparse sweeps: 5-10x faster PCG iterations than the lexicographic order).
        # int32 permutations where #E allows (memory: 12 B/face less at the solve)
        idx = np.int32 if n < 2**31 else np.int64
        self.perm = kernels.edge_morton_order(mesh).astype(idx)          # new -> old
        iperm = np.empty_like(self.perm)
        iperm[self.perm] = np.arange(n, dtype=idx)
        self._iperm = iperm
        # np.take: 4-6x faster than fancy indexing for these row gathers
        topo = (np.take(iperm, mesh.face_edges), np.take(mesh.edge_faces, self.perm, axis=0),
                np.take(mesh.edge_local_index, self.perm, axis=0))
        fixed = None if fixed is None or not np.any(fixed) else np.asarray(fixed, dtype=bool)
        self.fixed = None if fixed is None else fixed[self.perm]
        self.cols, self.A_full, self.M, self.n_jacobi_faces, self.sin_min_angle = kernels.hhj_system(
            mesh, self.fixed, True, topology=topo)
        if self.fixed is not None:
            A = self.A_full.copy()
            A[self.fixed] = 0.0
            A[self.fixed, 0] = 1.0
            A[self.fixed[self.cols] & ~self.fixed[:, None]] = 0.0
            self.M[self.fixed, 0] = 1.0   # r stays 0 on fixed rows, so z does too
            self.A = A
        else:
            self.A = self.A_full
        self.indptr = kernels.ell_indptr(n)
        self._cols_flat = self.cols.ravel()              # int32 (memory-bound sweeps)

    @property
    def n(self):
        return self.A.shape[0]

    def sliver_dofs(self, angle=None):
        """(m,) int64, internal numbering: free DOFs of the faces whose smallest angle is
        below ``angle`` degrees (default :data:`SLIVER_ANGLE`;
        ``sin α_min = 2|T| l_min / (l_0 l_1 l_2)``)."""
        if angle is None:
            angle = SLIVER_ANGLE
        m = self.mesh
        bad = self.sin_min_angle < np.sin(np.radians(angle))
        S = np.zeros(self.n, dtype=bool)
        S[self._iperm[m.face_edges[bad]].ravel()] = True
        if self.fixed is not None:
            S &= ~self.fixed
        return np.flatnonzero(S)

    def _two_level(self, S):
        """Exact sparse solve on the sliver DOFs S: the keyword arguments of :func:`pcg` for it
        (``subdomain_ldl`` for a QDLDL factor, solved inside the compiled PCG; else
        ``subdomain_solve``), or None when A_SS cannot be factorised (numerically singular
        faces: face-Schwarz alone)."""
        A = self.submatrix(S)
        # QDLDL (CHOLMOD above LDL_MAX): on the sliver subdomains of the --factor-study meshes
        # its factorisation is 2-4x faster than CHOLMOD's and SuperLU's; its factor is solved
        # in the compiled core on the k columns at once (camelhead: 0.05 ms per PCG iteration
        # against 0.45 ms for qdldl's own one-column solves called from Python).  Pivoted LU
        # where A_SS is numerically semi-definite.
        if A.shape[0] <= LDL_MAX:
            f = _qdldl_factor(A)
            if f is not None:
                L, d, perm = f.factors()
                if np.all(d > 0):        # else not numerically SPD: pivoted LU below
                    L = sp.csc_matrix(L)
                    return {"subdomain_ldl": (L.indptr, L.indices, L.data, d, perm)}
        chol = _cholmod(A) if A.shape[0] > LDL_MAX else None
        if chol is not None:
            return {"subdomain_solve": lambda r, z: chol(r, out=z)}
        try:
            lu = _splu(A)
        except SolverError:
            return None

        def solve(r, z):
            z[...] = lu(r)
        return {"subdomain_solve": solve}

    def submatrix(self, S):
        """``A[S][:, S]`` (scipy CSR, duplicates summed, explicit zeros dropped) for sorted
        unique internal DOFs ``S``, from the fixed-width rows of S alone: 3 ms for the
        jittered ellipsoid's 23.7k sliver DOFs against 47 ms through :meth:`csr`."""
        S = np.asarray(S, dtype=np.int64)
        local = np.full(self.n, -1, dtype=np.int64)
        local[S] = np.arange(len(S))
        cols = local[np.take(self.cols, S, axis=0)]           # (m, 5); -1: outside S
        vals = np.take(self.A, S, axis=0)
        keep = (cols >= 0) & (vals != 0)
        rows = np.broadcast_to(np.arange(len(S))[:, None], cols.shape)
        B = sp.coo_matrix((vals[keep], (rows[keep], cols[keep])), shape=(len(S), len(S))).tocsr()
        B.sum_duplicates()
        return B

    def csr(self):
        """The (masked) system matrix in the internal (Morton) numbering, scipy CSR."""
        # copies: sum_duplicates works in place and must not touch the row arrays
        A = sp.csr_matrix((self.A.ravel().copy(), self._cols_flat.copy(), self.indptr.copy()),
                          shape=(self.n, self.n))
        A.sum_duplicates()
        A.eliminate_zeros()
        return A

    def fixed_coupling(self, values):
        """``A[:, fixed] @ values[fixed]`` (#E, k) in the mesh's edge order: the load
        that the fixed DOFs put on the free rows."""
        v = np.where(self.fixed[:, None], values[self.perm], 0.0)
        out = np.empty_like(v)
        out[self.perm] = np.einsum("es,esk->ek", self.A_full, v[self.cols])
        return out

    def _pcg(self, rhs, solver, rtol, S, info, coupled=False):
        n, k = rhs.shape
        M = (self.indptr, self._cols_flat, self.M.ravel())
        sub = {}
        level = self._two_level(S) if len(S) else None
        if level is not None:
            sub = {"subdomain": S, **level}
        else:
            info["sliver_dofs"] = 0
        if solver == "cg":
            X, it, status, relres = pcg(self.indptr, self._cols_flat, self.A.ravel(), rhs,
                                        rtol=rtol, maxiter=CG_MAXITER, M=M,
                                        overwrite_R=rhs.shape[1] <= 16, coupled=coupled, **sub)
            info.update(iterations=it, solver="cg")
            if status != 0:
                raise SolverDidNotConverge(
                    f"preconditioned CG did not converge in {it} iterations (relative residual "
                    f"{max(relres):.2e} > {rtol:.1e}); the mesh may contain near-degenerate "
                    f"triangles. Use solver='direct' or solver='auto'.")
            return X, info
        budget = np.inf
        if n <= DIRECT_MAX:
            per_iter = _pcg_iter_seconds(n, k) * (1.0 + 2.0 * len(S) / n)
            budget = _direct_seconds(n) / per_iter      # PCG iterations still worth doing
        # rhs is this solve's private (permuted) copy: PCG uses it as its residual buffer
        overwrite = rhs.shape[1] <= 16 and rhs.flags.c_contiguous and rhs.dtype == np.float64
        X, it, status, relres = pcg(self.indptr, self._cols_flat, self.A.ravel(), rhs,
                                    rtol=rtol, maxiter=CG_MAXITER, M=M, probe_iter=PROBE_ITER,
                                    max_predicted=budget, overwrite_R=overwrite, coupled=coupled, **sub)
        info.update(iterations=it, solver="cg")
        if status != 0:
            if n > DIRECT_MAX:
                raise SolverDidNotConverge(
                    f"preconditioned CG did not converge in {it} iterations (relative residual "
                    f"{max(relres):.2e} > {rtol:.1e}) and the system ({n} unknowns) is too large "
                    f"for the direct solver")
            if overwrite:
                # rhs now holds the final residual r = rhs - A X: rebuild rhs = r + A X
                # (rounding ≤ eps ‖A X‖, and ‖A X‖ ≤ 1e4 ‖rhs‖ by the breakdown test)
                rhs += np.einsum("es,esk->ek", self.A, X[self.cols])
            X = self._direct(rhs)
            info.update(switched=True, solver="direct")
        return X, info

    def _direct(self, rhs):
        """``A⁻¹ rhs`` (internal numbering) by a direct solve: the compiled envelope LDLᵀ
        up to :data:`ENVELOPE_MAX` unknowns (falling back when it meets a tiny pivot or a
        large residual), else :func:`cholesky_solve`."""
        if self.n <= ENVELOPE_MAX:
            X, status = kernels.envelope_ldl_solve(self.indptr, self._cols_flat, self.A.ravel(), rhs,
                                                   DIRECT_RESIDUAL_RTOL)
            if status == 0:
                return X
        return cholesky_solve(self.csr(), rhs)

    def solve(self, rhs, solver="auto", rtol=DEFAULT_RTOL, overwrite_rhs=False, coupled=False):
        """Solve ``A X = rhs`` (#E, k, the mesh's edge order) with the strategy in the module docstring.

        Returns
        -------
        X : (#E, k) float64
        info : SolveInfo

        ``overwrite_rhs=True`` (a C-contiguous float64 ``rhs``) lets the solve use the
        memory of ``rhs`` (its contents are destroyed): one #E × k array less.
        ``coupled=True``: the PCG runs one recurrence on all k columns
        (:func:`igl_hhj.kernels.block_pcg`), so that rotating the coordinates of the
        right-hand sides rotates the solution exactly (the shape operator's solve).
        """
        if solver not in ("auto", "cg", "direct"):
            raise ValueError(f"unknown solver {solver!r}; use 'auto', 'cg' or 'direct'")
        if overwrite_rhs and isinstance(rhs, np.ndarray) and rhs.dtype == np.float64 \
                and rhs.flags.c_contiguous and rhs.flags.writeable and rhs.ndim == 2:
            rhs[:] = np.take(rhs, self.perm, axis=0)     # permuted in place (one transient copy)
        else:
            rhs = np.ascontiguousarray(np.take(np.asarray(rhs, dtype=np.float64), self.perm, axis=0))
        n, k = rhs.shape
        t0 = time.perf_counter()
        info = SolveInfo(solver=solver, iterations=0, switched=False)
        if solver == "auto" and n <= AUTO_DIRECT_MAX:
            solver = "direct"
        if solver == "direct":
            X = self._direct(rhs)
            info["solver"] = "direct"
        else:
            S = self.sliver_dofs()
            info["sliver_dofs"] = len(S)
            if solver == "auto" and len(S) > SLIVER_MAX_FRACTION * n and n <= DIRECT_MAX:
                X = self._direct(rhs)
                info["solver"] = "direct"
            else:
                X, info = self._pcg(rhs, solver, rtol, S, info, coupled=coupled)
        if not np.isfinite(X).all():
            raise SolverError("the HHJ solve produced non-finite values")
        out = np.take(X, self._iperm, axis=0)     # = scatter out[perm] = X, as a gather
        del X
        info["seconds"] = time.perf_counter() - t0
        return out, info
