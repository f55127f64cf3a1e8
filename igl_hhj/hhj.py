"""The lowest-order surface Hellan–Herrmann–Johnson (HHJ) layer: one DOF per
unique edge, over libigl's mesh topology.

Source: S. W. Walker, *Approximating the shape operator with the surface HHJ
element* (Walker 2023), §3–§5, made concrete in ``shared/design/hhj_lowest_order.md``.

The space ``V_h`` holds piecewise-constant symmetric tangential 3×3 tensors whose
normal–normal component ``nᵀσn`` is single valued across every edge (each face
uses its own outward conormal).  The DOF of edge ``e`` is that value ``σ^nn_e``.
The local basis on face ``T`` dual to its three edge DOFs is

    φ_j = sym(t_a ⊗ t_b) / ((n_j·t_a)(n_j·t_b)),   {a, b} = the other two edges,

so that ``n_iᵀ φ_j n_i = δ_ij``.  With it,

* ``A[e, e'] = Σ_T |T| φ_e : φ_e'`` (the bilinear form ``a(·,·)``, eq. 3.8/4.7),
* ``B[e, v] = Σ_{T∋e} l_e n_{e,T}·∇λ_v|_T`` (``b_h(φ_e, λ_v)`` on flat P1
  triangles: the element Hessian vanishes and only the conormal-derivative
  jump across ``e`` survives; a boundary edge keeps its one-sided value),

and the HHJ projection of the surface Hessian of a P1 function ``w`` solves
``A s = -B w + g`` (eq. 4.9 / 5.19), where ``g`` carries clamped boundary data
and fixed (simply supported) DOFs are moved to the right-hand side.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .boundary import clamped_load  # the boundary load, named here as before
from .constants import SPD_AUTO_DIRECT_MAX
from .errors import SolverDidNotConverge
from .mesh import TriangleMesh
from .solvers import solve_spd  # the generic SPD solve, named here as before

__all__ = [
    "local_basis", "mass_matrix", "jump_matrix", "face_tensors", "nn_moments",
    "clamped_load", "HHJProjection", "solve_spd", "face_schwarz_preconditioner",
    "SolverDidNotConverge",
]




def _sym_outer(u, v):
    """sym(u ⊗ v) = (u vᵀ + v uᵀ)/2 for stacked vectors (..., 3) → (..., 3, 3)."""
    uv = u[..., :, None] * v[..., None, :]
    return 0.5 * (uv + np.swapaxes(uv, -1, -2))


def local_basis(mesh: TriangleMesh):
    """Local HHJ basis tensors of every face.

    Returns
    -------
    phi : (#F, 3, 3, 3) float64
        ``phi[f, j]`` is the 3×3 tensor φ_j on face f dual to edge j
        (the edge opposite corner j): ``n_iᵀ φ_j n_i = δ_ij``, symmetric and
        tangential (``φ_j ν_T = 0``).
    """
    t = mesh.edge_tangents      # (#F, 3, 3)
    n = mesh.conormals          # (#F, 3, 3)
    a = [1, 2, 0]
    b = [2, 0, 1]
    ta, tb = t[:, a], t[:, b]
    denom = np.einsum("fjk,fjk->fj", n, ta) * np.einsum("fjk,fjk->fj", n, tb)
    return _sym_outer(ta, tb) / denom[:, :, None, None]


def _assemble(rows, cols, vals, shape):
    return sp.coo_matrix((vals.ravel(), (rows.ravel(), cols.ravel())), shape=shape).tocsr()


def mass_matrix(mesh: TriangleMesh, phi=None):
    """The HHJ "mass" matrix A (#E × #E, SPD, ≤ 5 nonzeros per row).

    ``A[e, e'] = Σ_T |T| φ_e : φ_e'`` (Frobenius product), Walker eq. (5.14)."""
    if phi is None:
        phi = local_basis(mesh)
    Aloc = np.einsum("fiab,fjab->fij", phi, phi) * mesh.face_areas[:, None, None]
    FE = mesh.face_edges
    rows = np.broadcast_to(FE[:, :, None], Aloc.shape)
    cols = np.broadcast_to(FE[:, None, :], Aloc.shape)
    return _assemble(rows, cols, Aloc, (mesh.n_edges, mesh.n_edges))


def jump_matrix(mesh: TriangleMesh):
    """The matrix B (#E × #V) of ``b_h(φ_e, λ_v)`` for P1 hat functions λ_v.

    ``B[e, v] = Σ_{T∋e} l_e n_{e,T}·∇λ_v|_T``: row e is the jump of the
    conormal derivative across e times l_e (one-sided on boundary edges)."""
    l = mesh.edge_lengths
    n = mesh.conormals
    Bloc = -(l[:, :, None] * l[:, None, :]) * np.einsum("fia,fca->fic", n, n) \
        / mesh.face_double_areas[:, None, None]
    rows = np.broadcast_to(mesh.face_edges[:, :, None], Bloc.shape)
    cols = np.broadcast_to(mesh.F[:, None, :], Bloc.shape)
    return _assemble(rows, cols, Bloc, (mesh.n_edges, mesh.n_vertices))


def face_tensors(mesh: TriangleMesh, coeffs, phi=None):
    """Evaluate HHJ functions face by face.

    Parameters
    ----------
    coeffs : (#E,) or (#E, k) edge DOFs σ^nn.

    Returns
    -------
    sigma : (#F, 3, 3) or (#F, k, 3, 3) float64, ``Σ_j coeffs[e(f, j)] φ_j``.
    """
    if phi is None:
        phi = local_basis(mesh)
    c = np.asarray(coeffs)[mesh.face_edges]  # (#F, 3) or (#F, 3, k)
    if c.ndim == 2:
        return np.einsum("fj,fjab->fab", c, phi)
    return np.einsum("fjk,fjab->fkab", c, phi)


def nn_moments(mesh: TriangleMesh, sigma):
    """Normal–normal trace ``n_iᵀ σ_f n_i`` of face tensors on each face's edges.

    Parameters
    ----------
    sigma : (#F, 3, 3) face tensors

    Returns
    -------
    (#F, 3) float64: entry (f, i) is the nn-component on edge i of face f.
    For a member of V_h the two faces of an interior edge agree."""
    n = mesh.conormals
    return np.einsum("fia,fab,fib->fi", n, sigma, n)


def face_schwarz_preconditioner(mesh: TriangleMesh, A, phi=None, free=None):
    """Additive Schwarz preconditioner over faces for the HHJ matrix A.

    ``M = Σ_T R_Tᵀ (R_T A R_Tᵀ)⁻¹ R_T``: the exact inverse of each face's 3×3
    principal block of the *assembled* A (its diagonal assembled, its
    off-diagonal entries the face's own), summed over faces.  SPD; one sparse
    mat-vec to apply.  The ill-conditioning of A is local to badly shaped
    triangles (its extreme eigenvectors live on ~10 DOFs), where two edge DOFs
    of a thin face are nearly the same functional; Jacobi scaling cannot see
    that, the face block can.

    Parameters
    ----------
    A : (#E, #E) assembled HHJ matrix
    free : (#E,) bool, optional: restrict to the free DOFs (fixed ones removed).

    Returns
    -------
    M : (#free, #free) scipy.sparse.csr_matrix

    Notes
    -----
    Near-degenerate faces (accepted down to ``mesh.DEGENERATE_AREA_RTOL``) can make
    a face block numerically singular; such a block is replaced by its
    diagonal (:func:`_robust_block_inverse`), so this never raises.
    """
    if phi is None:
        phi = local_basis(mesh)
    FE = mesh.face_edges
    blk = np.einsum("fiab,fjab->fij", phi, phi) * mesh.face_areas[:, None, None]
    idx = np.arange(3)
    blk[:, idx, idx] = A.diagonal()[FE]
    fixed_loc = None
    if free is not None and not np.all(free):
        fixed_loc = ~free[FE]                              # (#F, 3)
        blk[fixed_loc[:, :, None] | fixed_loc[:, None, :]] = 0.0
        fl = np.flatnonzero(fixed_loc.ravel())
        blk.reshape(-1, 3)[fl, np.tile(idx, len(FE))[fl]] = 1.0
    inv = _robust_block_inverse(blk)
    if fixed_loc is not None:
        inv[fixed_loc[:, :, None] | fixed_loc[:, None, :]] = 0.0
        new_index = np.cumsum(free) - 1
        FE = np.where(free[FE], new_index[FE], 0)
        n = int(free.sum())
    else:
        n = mesh.n_edges
    rows = np.broadcast_to(FE[:, :, None], inv.shape)
    cols = np.broadcast_to(FE[:, None, :], inv.shape)
    return _assemble(rows, cols, inv, (n, n))


# A face block whose unit-diagonal scaling has a Cholesky pivot below this is
# treated as numerically singular (a near-degenerate triangle).
SCHWARZ_PIVOT_MIN = 1e-8


def _robust_block_inverse(blk):
    """Inverses of SPD 3×3 blocks (#F, 3, 3), robust to near-singular ones.

    Each block is scaled to unit diagonal, ``C = D blk D`` with
    ``D = diag(blk)^-1/2``; where a Cholesky pivot of C (``1 - c01²`` or
    ``1 - c02² - l21²``) is below :data:`SCHWARZ_PIVOT_MIN` the block is replaced
    by its diagonal (Jacobi on that face), so the sum over faces stays SPD.  The
    compiled twin is ``face_schwarz`` in ``igl_hhj/_core/hhj_kernels.cpp``."""
    d = 1.0 / np.sqrt(np.einsum("fii->fi", blk))
    C = blk * d[:, :, None] * d[:, None, :]
    c01, c02, c12 = C[:, 0, 1], C[:, 0, 2], C[:, 1, 2]
    p2 = 1.0 - c01 ** 2
    l21 = np.where(p2 > 0, (c12 - c02 * c01) / np.sqrt(np.where(p2 > 0, p2, 1.0)), 0.0)
    p3 = 1.0 - c02 ** 2 - l21 ** 2
    ok = (p2 >= SCHWARZ_PIVOT_MIN) & (p3 >= SCHWARZ_PIVOT_MIN)
    det = np.where(ok, p2 * p3, 1.0)
    ci = np.empty_like(C)
    ci[:, 0, 0] = 1.0 - c12 ** 2
    ci[:, 1, 1] = 1.0 - c02 ** 2
    ci[:, 2, 2] = p2
    ci[:, 0, 1] = ci[:, 1, 0] = c02 * c12 - c01
    ci[:, 0, 2] = ci[:, 2, 0] = c01 * c12 - c02
    ci[:, 1, 2] = ci[:, 2, 1] = c01 * c02 - c12
    ci /= det[:, None, None]
    ci[~ok] = np.eye(3)
    return ci * d[:, :, None] * d[:, None, :]


class HHJProjection:
    """HHJ projection of surface Hessians of P1 functions on one mesh.

    Holds A, B and the boundary partition so that several right-hand sides
    (e.g. the three coordinate functions) share one assembly.

    Parameters
    ----------
    mesh : TriangleMesh
    fixed_edges : (#E,) bool, optional
        Simply supported boundary edges: their DOFs are prescribed
        (eq. 5.18/5.19) and not solved for.
    solver : {"auto", "cg", "direct"}
        See :func:`solve_spd`; CG is preconditioned by
        :func:`face_schwarz_preconditioner`.

    Notes
    -----
    Clamped boundary edges (eq. 5.19's Σ_c term) are handled through the load
    ``g`` passed to :meth:`solve`.  A boundary edge without data is treated as
    clamped with the discrete gradient as data, ``ξ = ∇_T w``, so its load
    cancels B's one-sided term exactly: the "plain assembly", which still
    converges but only like O(h^1/2) near the boundary (Walker §5.3.2).
    """

    def __init__(self, mesh: TriangleMesh, fixed_edges=None, solver="auto"):
        self.mesh = mesh
        self.solver = solver
        self.phi = local_basis(mesh)
        self.A = mass_matrix(mesh, self.phi)
        self.B = jump_matrix(mesh)
        if fixed_edges is None:
            fixed_edges = np.zeros(mesh.n_edges, dtype=bool)
        self.fixed = np.asarray(fixed_edges, dtype=bool)
        self.free = ~self.fixed
        self._A_ff = self.A[self.free][:, self.free] if self.fixed.any() else self.A
        self._A_fs = self.A[self.free][:, self.fixed] if self.fixed.any() else None

    def plain_boundary_load(self, w):
        """Load that cancels B's one-sided term on boundary edges: ``g_e = l_e n·∇_T w``.

        ``w`` : (#V, k). Returns (#E, k)."""
        m = self.mesh
        g = np.zeros((m.n_edges, w.shape[1]))
        e = np.flatnonzero(m.boundary_edges)
        if e.size:
            g[e] = (self.B[e] @ w)
        return g

    def solve(self, w, load=None, fixed_values=None):
        """Edge DOFs of the HHJ projection of ∇_Γ∇_Γ w.

        Parameters
        ----------
        w : (#V, k) P1 vertex values of k functions.
        load : (#E, k), optional
            Boundary load g (eq. 5.19, Σ_c term); default: plain assembly.
        fixed_values : (#E, k), optional
            Values of the fixed (simply supported) DOFs; rows of free edges ignored.

        Returns
        -------
        s : (#E, k) float64 edge DOFs σ^nn.
        """
        w = np.asarray(w, dtype=np.float64)
        rhs = -(self.B @ w)
        rhs += self.plain_boundary_load(w) if load is None else load
        s = np.zeros_like(rhs)
        if self.fixed.any():
            if fixed_values is None:
                raise ValueError("fixed (simply supported) edges need fixed_values")
            s[self.fixed] = fixed_values[self.fixed]
            rhs_f = rhs[self.free] - self._A_fs @ s[self.fixed]
        else:
            rhs_f = rhs
        M = None
        if self.solver == "cg" or (self.solver == "auto" and self._A_ff.shape[0] > SPD_AUTO_DIRECT_MAX):
            M = face_schwarz_preconditioner(self.mesh, self.A, self.phi,
                                            self.free if self.fixed.any() else None)
        s[self.free] = solve_spd(self._A_ff, rhs_f, method=self.solver, preconditioner=M)
        return s
