"""Solver strategy for the HHJ system ``A s^k = -B X^k + g^k`` (and generic SPD systems).

Three ways to solve, chosen per call:

* ``"direct"``: sparse Cholesky (CHOLMOD through ``cholespy``; SuperLU when
  cholespy is not importable), one factorisation for all right-hand sides.
* ``"cg"``: the compiled fused block PCG (:func:`igl_hhj.kernels.block_pcg`),
  preconditioned by the face-Schwarz preconditioner (exact inverses of every
  face's 3×3 block of A).
* ``"auto"`` (default): direct for small systems; otherwise PCG that checks
  its convergence rate every :data:`PROBE_ITER` iterations and, when the
  extrapolated iteration count would cost more than the estimated direct
  solve, stops and factorises instead (sliver meshes).  Above
  :data:`DIRECT_MAX` unknowns (memory) PCG always runs to the end.

Tolerance
---------
``rtol`` is the relative residual ``‖r_j‖ ≤ rtol ‖R_j‖`` per right-hand side.
The default :data:`DEFAULT_RTOL` = 1e-8 for the public curvature functions is
tied to the discretisation error: the method's error is O(h) (≥ 1e-4 relative
on every mesh up to millions of faces), and the solver error this tolerance
leaves in the vertex curvatures is below 1e-4 of it (measured by
``python -m igl_hhj.benchmarks.speed --rtol-study``; see README "Speed").
"""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from . import kernels
from .errors import SolverDidNotConverge, SolverError

__all__ = ["DEFAULT_RTOL", "HHJSystem", "cholesky_solve", "pcg", "SolveInfo"]

DEFAULT_RTOL = 1e-8
# "auto": always factorise up to this many unknowns (measured: Cholesky beats PCG here on every mesh)
AUTO_DIRECT_MAX = 30_000
# "auto": never factorise above this many unknowns (fill and memory), PCG runs to convergence
DIRECT_MAX = 700_000
# "auto": PCG checks its rate this often
PROBE_ITER = 20
# iteration cap of "cg"
CG_MAXITER = 5000


class SolveInfo(dict):
    """What a solve did: ``solver`` ("direct"/"cg"), ``iterations``, ``seconds``, ``switched``."""


def _direct_seconds(n):
    """Estimated time of one sparse Cholesky factorisation + solve of the HHJ matrix (n unknowns).

    Power-law fit of measured CHOLMOD times on this matrix family (nested dissection
    fill grows like n^1.3..1.5), deliberately on the pessimistic side."""
    return 6e-6 * n ** 1.2


def _pcg_iter_seconds(n, k):
    """Estimated time of one fused PCG iteration (n unknowns, k right-hand sides)."""
    return 2.0e-8 * n * (1 + k)


def _splu_solve(A, R):
    import scipy.sparse.linalg as spla
    try:
        return spla.splu(sp.csc_matrix(A)).solve(R)
    except RuntimeError as exc:
        raise SolverError(f"sparse LU failed: {exc}") from None


def cholesky_solve(A, R, *, prefer_lu=False):
    """Solve ``A X = R`` for SPD sparse A by one sparse factorisation.

    Sparse Cholesky (CHOLMOD via cholespy); SuperLU (``scipy.sparse.linalg.splu``,
    LU with partial pivoting) when cholespy is not available, when
    ``prefer_lu`` is set (matrices known to be numerically semi-definite, e.g.
    with faces of relative area ~1e-9) or when CHOLMOD finds the matrix not
    numerically positive definite.  ``R`` (n,) or (n, k).  Raises
    :class:`SolverError` when the factorisation fails or the solution is not finite."""
    R = np.ascontiguousarray(R, dtype=np.float64)
    n = A.shape[0]
    if n == 0:
        return np.zeros_like(R)
    A = sp.csr_matrix(A)
    A.sum_duplicates()
    try:
        from cholespy import CholeskySolverD, MatrixType
    except ImportError:  # pragma: no cover - cholespy is a dependency
        prefer_lu = True
    X = None
    if not prefer_lu:
        try:
            solver = CholeskySolverD(n, A.indptr.astype(np.int32), A.indices.astype(np.int32),
                                     np.ascontiguousarray(A.data), MatrixType.CSR)
        except (ValueError, RuntimeError):
            X = None          # not numerically positive definite: LU below
        else:
            X = np.empty_like(R)
            solver.solve(R, X)
    if X is None:
        X = _splu_solve(A, R)
    if not np.isfinite(X).all():
        raise SolverError("the sparse direct solve produced non-finite values (matrix numerically singular)")
    return X


def pcg(indptr, indices, data, R, *, rtol, maxiter, M=None, dinv=None, probe_iter=0,
        max_predicted=np.inf):
    """Compiled block PCG on all columns of ``R`` (n, k), in groups of 16.

    Returns ``(X, iterations, status, relres)`` (see :func:`igl_hhj.kernels.block_pcg`;
    iterations / status are the worst over the groups)."""
    R = np.ascontiguousarray(R, dtype=np.float64)
    if R.shape[1] <= 16:
        return kernels.block_pcg(indptr, indices, data, R, rtol=rtol, maxiter=maxiter, M=M, dinv=dinv,
                                 probe_iter=probe_iter, max_predicted=max_predicted)
    X = np.empty_like(R)
    its, statuses, relres = [0], [0], []
    for j in range(0, R.shape[1], 16):
        X[:, j:j + 16], it, st, rr = kernels.block_pcg(
            indptr, indices, data, R[:, j:j + 16], rtol=rtol, maxiter=maxiter, M=M, dinv=dinv,
            probe_iter=probe_iter, max_predicted=max_predicted)
        its.append(it)
        statuses.append(st)
        relres += list(rr)
        if st != 0:
            break
    return X, max(its), max(statuses), relres


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
        self.perm = kernels.edge_morton_order(mesh)          # new -> old
        iperm = np.empty_like(self.perm)
        iperm[self.perm] = np.arange(n)
        topo = (iperm[mesh.face_edges], mesh.edge_faces[self.perm], mesh.edge_local_index[self.perm])
        fixed = None if fixed is None or not np.any(fixed) else np.asarray(fixed, dtype=bool)
        self.fixed = None if fixed is None else fixed[self.perm]
        self.cols, self.A_full, self.M, self.n_jacobi_faces = kernels.hhj_system(
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
        self._cols_flat = self.cols.ravel().astype(np.int32)

    @property
    def n(self):
        return self.A.shape[0]

    def csr(self):
        """The (masked) system matrix in the internal (Morton) numbering, scipy CSR."""
        A = sp.csr_matrix((self.A.ravel(), self._cols_flat, self.indptr), shape=(self.n, self.n))
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

    def solve(self, rhs, solver="auto", rtol=DEFAULT_RTOL):
        """Solve ``A X = rhs`` (#E, k, the mesh's edge order) with the strategy in the module docstring.

        Returns
        -------
        X : (#E, k) float64
        info : SolveInfo
        """
        if solver not in ("auto", "cg", "direct"):
            raise ValueError(f"unknown solver {solver!r}; use 'auto', 'cg' or 'direct'")
        rhs = np.ascontiguousarray(np.asarray(rhs, dtype=np.float64)[self.perm])
        n, k = rhs.shape
        t0 = time.perf_counter()
        info = SolveInfo(solver=solver, iterations=0, switched=False)
        if solver == "auto" and n <= AUTO_DIRECT_MAX:
            solver = "direct"
        # faces whose 3x3 block is numerically singular make A numerically semi-definite:
        # LU with pivoting instead of Cholesky there
        prefer_lu = self.n_jacobi_faces > 0
        if solver == "direct":
            X = cholesky_solve(self.csr(), rhs, prefer_lu=prefer_lu)
            info["solver"] = "direct"
        else:
            M = (self.indptr, self._cols_flat, self.M.ravel())
            if solver == "cg":
                X, it, status, relres = pcg(self.indptr, self._cols_flat, self.A.ravel(), rhs,
                                            rtol=rtol, maxiter=CG_MAXITER, M=M)
                if status != 0:
                    raise SolverDidNotConverge(
                        f"preconditioned CG did not converge in {it} iterations (relative residual "
                        f"{max(relres):.2e} > {rtol:.1e}); the mesh may contain near-degenerate "
                        f"triangles. Use solver='direct' or solver='auto'.")
            else:
                budget = _direct_seconds(n) / _pcg_iter_seconds(n, k) if n <= DIRECT_MAX else np.inf
                X, it, status, relres = pcg(self.indptr, self._cols_flat, self.A.ravel(), rhs,
                                            rtol=rtol, maxiter=CG_MAXITER, M=M,
                                            probe_iter=PROBE_ITER, max_predicted=budget)
                info["iterations"] = it
                if status != 0:
                    if n > DIRECT_MAX:
                        raise SolverDidNotConverge(
                            f"preconditioned CG did not converge in {it} iterations (relative residual "
                            f"{max(relres):.2e} > {rtol:.1e}) and the system ({n} unknowns) is too large "
                            f"for the direct solver")
                    X = cholesky_solve(self.csr(), rhs, prefer_lu=prefer_lu)
                    info["switched"] = True
                    info["solver"] = "direct"
                else:
                    info["solver"] = "cg"
            info["iterations"] = it
        if not np.isfinite(X).all():
            raise SolverError("the HHJ solve produced non-finite values")
        out = np.empty_like(X)
        out[self.perm] = X
        info["seconds"] = time.perf_counter() - t0
        return out, info
