"""Mixed piecewise-linear (Ciarlet–Raviart) biharmonic solver on triangle meshes.

Source: O. Stein, E. Grinspun, A. Jacobson, M. Wardetzky, *A mixed finite
element method with piecewise linear elements for the biharmonic equation on
surfaces* (Stein et al. 2022), eq. (1.3), (1.5), §5.3 and §6 (eq. 6.1–6.5).

We solve ``Δ²u = f`` on a triangle mesh Γ_h with two P1 unknowns,
``u1 ≈ u`` and ``u2 ≈ -Δu`` (the sign of Stein et al. 2022: ``(∇u1, ∇η) = (u2, η)``),

    (∇u2, ∇ξ) = (f, ξ)              for all ξ ∈ S_h,0,
    (∇u1, ∇η) = (u2, η) + ∫_∂ q η   for all η ∈ S_h         (eq. 1.5)

which in the P1 hat basis is the symmetric indefinite saddle-point system

    [ 0     K_IA ] [u1_I]   [ (M_c f)_I              ]
    [ K_AI  -M   ] [u2  ] = [ N q - K_AB g_B          ]        (eq. 6.1)

with ``K = -igl.cotmatrix`` the P1 stiffness matrix (eq. 6.3; libigl's cotangent
matrix is the *negative* semi-definite one), ``M`` the P1 mass matrix (eq. 6.4),
``M_c`` the consistent mass used for the load ``∫ φ_i I_h f`` (eq. 6.5),
``N`` the P1 mass matrix of the boundary curve, ``I`` the interior and ``A`` all
(referenced) vertices, ``B`` the boundary vertices.

Boundary conditions (``bc``)
----------------------------
``"clamped"``
    ``u = g``, ``∂u/∂n = q`` (Stein et al.'s case, ``g = q = 0`` by default):
    ``u1`` in S_h,0 (+ g), ``u2`` free: the saddle system above.
``"navier"``
    ``u = g``, ``-Δu = w`` (simply supported; ``g = w = 0`` by default): both
    unknowns in S_h,0 (+ data); the system decouples into two Dirichlet
    Poisson problems with the same matrix ``K_II`` (Stein et al. 2022, §5.3, remark).
``"closed"``
    no boundary (§5.3): ``u1``, ``u2`` have zero mean on every connected
    component, and ``f`` must have zero mean, ``∫_Γh I_h f = 0`` (checked, or
    removed with ``project_mean=True``).

Mass matrix (``mass``)
----------------------
``"full"``
    consistent P1 mass (``igl.MASSMATRIX_TYPE_FULL``): the method of the paper.
``"lumped"``
    barycentric lumping (``MASSMATRIX_TYPE_BARYCENTRIC``, row sums of the full
    mass).  ``"voronoi"``: libigl's Voronoi-hybrid lumping
    (``MASSMATRIX_TYPE_VORONOI``, the default of ``igl.harmonic``).  These are
    the common geometry-processing variant ``K M⁻¹ K`` (Jacobson et al. 2010);
    with ``bc="clamped"`` and ``mass="voronoi"`` the solution of ``f = 0``
    equals ``igl.harmonic(V, F, b, g, k=2)`` with ``b`` = boundary vertices.
    The mass option changes ``M`` in (6.1) only; the load always uses the
    consistent mass (eq. 6.5).

Solvers
-------
The matrices are factorised once per (mesh, bc, mass) in
:class:`BiharmonicSolver`; :func:`biharmonic_solve` is the one-shot wrapper.
Nothing ever forms a dense ``M⁻¹``:

SPD matrices are factorised by SuperLU in symmetric mode (minimum-degree ordering)
up to :data:`CHOLMOD_MIN_UNKNOWNS` unknowns and by CHOLMOD (cholespy) above.

* clamped, lumped mass: the Schur complement ``K_IA M⁻¹ K_AI`` is sparse (two-ring
  stencil) and SPD; one sparse factorisation.
* clamped, full mass: ``solver="saddle"`` factorises the indefinite system (6.1)
  with SuperLU (COLAMD, partial pivoting); ``solver="schur"`` runs conjugate
  gradients on the Schur complement ``K_IA M⁻¹ K_AI`` preconditioned by the
  factorised lumped Schur complement; since ``M_L/4 ≤ M ≤ M_L`` for P1 triangles the
  preconditioned spectrum lies in [1, 4] and CG needs ~15–25 iterations at any ``h``.
  ``M⁻¹`` is applied by the compiled PCG preconditioned with the lumped mass
  (:func:`igl_hhj.solvers.mass_solver`, spectrum in [1/4, 1]; no factorisation of M).
  ``"auto"`` picks ``"saddle"`` up to :data:`AUTO_SADDLE_MAX_VERTICES` vertices and
  ``"schur"`` above (faster and less memory; the saddle LU is faster for repeated solves).
* navier / closed: one sparse factorisation of ``K_II`` (closed: one pinned vertex
  per component), used for both Poisson solves.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from . import kernels
from .hhj import SolverDidNotConverge
from .mesh import as_mesh
from .solvers import _cholmod, mass_solver

__all__ = ["BiharmonicSolver", "biharmonic_solve", "stiffness_matrix", "mass_matrix",
           "boundary_mass_matrix"]

BOUNDARY_CONDITIONS = ("clamped", "navier", "closed")
MASS_TYPES = ("full", "lumped", "voronoi")
SOLVERS = ("auto", "saddle", "schur")

# "auto" switches the clamped full-mass solve from the saddle-point LU to
# Schur-complement PCG above this many vertices, where the lumped Schur complement
# is factorised by CHOLMOD (CHOLMOD_MIN_UNKNOWNS) and M⁻¹ is the compiled PCG.  Measured on the
# clamped hemisphere (2 shared cores, setup + one solve): 38k vertices saddle 1.25 s,
# Schur 1.46 s; 151k saddle 11.0 s, Schur 7.2 s; 603k Schur 55 s (one CHOLMOD
# factorisation of the lumped K M⁻¹ K alone: 43 s).
AUTO_SADDLE_MAX_VERTICES = 80_000

# SPD factorisations above this many unknowns use CHOLMOD (cholespy), below SuperLU
# (symmetric mode, RCM + minimum degree): CHOLMOD factorises the lumped K M⁻¹ K of the
# 151k-vertex hemisphere in 5.0 s, SuperLU in 6.6 s; below ~40k they are even.
CHOLMOD_MIN_UNKNOWNS = 80_000

# Relative tolerance of the zero-mean check of f for bc="closed":
# |∫ I_h f| <= ZERO_MEAN_RTOL * ∫ |I_h f| on every connected component.
ZERO_MEAN_RTOL = 1e-10


# ---------------------------------------------------------------- matrices
def stiffness_matrix(mesh):
    """P1 stiffness matrix ``K_ij = ∫ ∇φ_i · ∇φ_j`` (Stein et al. 2022, eq. 6.3).

    ``K = -igl.cotmatrix(V, F)``: libigl's cotangent matrix is negative
    semi-definite, ``K`` is positive semi-definite.

    Returns
    -------
    K : (#V, #V) scipy.sparse.csr_matrix
    """
    import igl
    return _finite_operator(mesh, _pad(-igl.cotmatrix(mesh.V, mesh.F), mesh.n_vertices),
                            "the stiffness matrix (igl.cotmatrix)")


def mass_matrix(mesh, kind="full"):
    """P1 mass matrix ``M_ij = ∫ φ_i φ_j`` (eq. 6.4) or a lumped variant.

    Parameters
    ----------
    kind : {"full", "lumped", "voronoi"}
        ``igl.massmatrix`` type FULL, BARYCENTRIC or VORONOI.

    Returns
    -------
    M : (#V, #V) scipy.sparse.csr_matrix
    """
    import igl
    types = {"full": igl.MASSMATRIX_TYPE_FULL, "lumped": igl.MASSMATRIX_TYPE_BARYCENTRIC,
             "voronoi": igl.MASSMATRIX_TYPE_VORONOI}
    if kind not in types:
        raise ValueError(f"mass must be one of {MASS_TYPES}, got {kind!r}")
    return _finite_operator(mesh, _pad(igl.massmatrix(mesh.V, mesh.F, types[kind]), mesh.n_vertices),
                            "the mass matrix (igl.massmatrix)")


def _pad(A, n):
    """csr copy of A padded with zero rows/columns to n × n (libigl sizes some
    matrices by ``max(F) + 1``, dropping trailing unreferenced vertices)."""
    A = sp.csr_matrix(A)
    if A.shape != (n, n):
        A = sp.csr_matrix((A.data, A.indices, np.concatenate(
            [A.indptr, np.full(n - A.shape[0], A.indptr[-1])])), shape=(n, n))
    return A


def boundary_mass_matrix(mesh):
    """P1 mass matrix of the boundary curve, ``N_ij = ∫_∂Γh φ_i φ_j ds``.

    Each boundary edge of length l contributes ``l/6 [[2, 1], [1, 2]]``.

    Returns
    -------
    N : (#V, #V) scipy.sparse.csr_matrix (zero rows off the boundary)
    """
    E = mesh.edges[mesh.boundary_edges]
    L = mesh.unique_edge_lengths[mesh.boundary_edges]
    n = mesh.n_vertices
    rows = np.concatenate([E[:, 0], E[:, 1], E[:, 0], E[:, 1]])
    cols = np.concatenate([E[:, 0], E[:, 1], E[:, 1], E[:, 0]])
    vals = np.concatenate([L / 3, L / 3, L / 6, L / 6])
    return sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()


# ---------------------------------------------------------------- factorisations
def _factorize_spd(A):
    """One sparse factorisation of an SPD matrix and its ``solve`` callable.

    Above :data:`CHOLMOD_MIN_UNKNOWNS` unknowns CHOLMOD's supernodal Cholesky
    (cholespy).  Below, and when CHOLMOD finds the matrix not
    numerically positive definite, SuperLU in symmetric mode (no pivoting): the matrix
    is first permuted by reverse Cuthill–McKee, then SuperLU orders it by minimum
    degree on ``Aᵀ + A``; on refined meshes this is ~100× faster than minimum degree
    on the raw vertex order (whose ordering step alone took 25 s for a 41k-vertex
    sphere) and has ~2× less fill than COLAMD.
    """
    from scipy.sparse.csgraph import reverse_cuthill_mckee
    A = sp.csr_matrix(A)
    if A.shape[0] == 0:
        return lambda b: np.zeros_like(b)
    _check_finite_matrix(A)
    if A.shape[0] > CHOLMOD_MIN_UNKNOWNS:
        A.sum_duplicates()
        chol = _cholmod(A)
        if chol is not None:
            return chol
    p = reverse_cuthill_mckee(A, symmetric_mode=True)
    try:
        lu = spla.splu(sp.csc_matrix(A[p][:, p]), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:            # a zero pivot without pivoting: retry with partial pivoting
        lu = _splu_or_solver_error(sp.csc_matrix(A[p][:, p]), "COLAMD")

    def solve(b):
        x = np.empty_like(b)
        x[p] = lu.solve(b[p])
        return x

    return solve


def _factorize_general(A):
    """Sparse LU with partial pivoting (COLAMD); for the indefinite system (6.1)."""
    _check_finite_matrix(A)
    return _splu_or_solver_error(sp.csc_matrix(A), "COLAMD").solve


def _check_finite_matrix(A):
    if not np.isfinite(sp.csr_matrix(A).data).all():
        from .errors import SolverError
        raise SolverError("the biharmonic system has NaN/inf entries: libigl's cotangent/mass "
                          "matrices could not represent a face of this mesh; remove "
                          "near-degenerate faces or rescale the mesh")


def _finite_operator(mesh, A, what):
    """Raise SolverError naming the faces where a libigl operator is not finite."""
    A = sp.csr_matrix(A)
    bad = ~np.isfinite(A.data)
    if bad.any():
        from .errors import SolverError
        rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))[bad]
        vmask = np.zeros(mesh.n_vertices, dtype=bool)
        vmask[rows[rows < mesh.n_vertices]] = True
        faces = np.flatnonzero(vmask[mesh.F].all(axis=1))
        raise SolverError(f"{what} has NaN/inf entries around faces {faces[:5].tolist()}: libigl "
                          f"computes it from edge lengths and cannot represent those faces; "
                          f"remove near-degenerate faces or rescale the mesh", faces=faces)
    return A


def _splu_or_solver_error(A, permc):
    from .errors import SolverError
    try:
        return spla.splu(A, permc_spec=permc)
    except RuntimeError as exc:
        raise SolverError(f"the biharmonic system is singular in float64 ({exc}): the mesh has a "
                          "face or component the P1 matrices cannot represent (near-degenerate "
                          "faces, or a component without boundary for bc='clamped'/'navier')") from None


# ---------------------------------------------------------------- input checks
def _check_choice(value, name, choices):
    if not isinstance(value, str) or value not in choices:
        raise ValueError(f"{name} must be one of {choices}, got {value!r}")
    return value


def _vertex_function(mesh, x, name, allow_none=True):
    """A per-vertex (#V,) float64 array from an array or a callable on (#V, 3) points."""
    if x is None:
        if allow_none:
            return None
        raise TypeError(f"{name} is required")
    if callable(x):
        try:
            vals = x(mesh.V.copy())
        except Exception as exc:
            raise TypeError(f"{name} is callable but failed on the (#V, 3) vertex array: {exc}") from exc
        vals = np.asarray(vals)
        src = f"{name}(V)"
    else:
        if np.isscalar(x) and not isinstance(x, (str, bytes)):
            x = np.full(mesh.n_vertices, x, dtype=np.float64)
        try:
            vals = np.asarray(x)
        except Exception as exc:
            raise TypeError(f"{name} must be array-like or callable: {exc}") from None
        src = name
    if vals.dtype == object or not (np.issubdtype(vals.dtype, np.floating)
                                    or np.issubdtype(vals.dtype, np.integer)):
        raise TypeError(f"{src} must hold real numbers, got dtype {vals.dtype}")
    if vals.shape != (mesh.n_vertices,):
        raise ValueError(f"{src} must have shape (#V,) = ({mesh.n_vertices},), got {vals.shape}")
    vals = np.ascontiguousarray(vals, dtype=np.float64)
    bad = ~np.isfinite(vals) & mesh.referenced_vertices
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{src} has NaN or inf values; first at vertex {i}")
    return np.where(mesh.referenced_vertices, vals, 0.0)


# ---------------------------------------------------------------- solver
class BiharmonicSolver:
    """Factorise the mixed P1 biharmonic system of a mesh once, solve many times.

    Parameters
    ----------
    V : (#V, 3) array_like float
        Vertex positions (or a :class:`~igl_hhj.mesh.TriangleMesh` with ``F=None``).
    F : (#F, 3) array_like int
        Triangles (consistently oriented, edge-manifold).
    bc : {"clamped", "navier", "closed"}
        Boundary condition (see the module docstring).  "clamped" and "navier"
        need a boundary on every connected component; "closed" needs a mesh
        without boundary.
    mass : {"full", "lumped", "voronoi"}
        Mass matrix M of (6.1): consistent (the paper's method) or lumped
        (geometry-processing variant).
    solver : {"auto", "saddle", "schur"}
        Only matters for ``bc="clamped"``, ``mass="full"`` (see module
        docstring); ``"saddle"`` is not available with a lumped mass (the exact
        Schur complement is used instead).
    rtol : float
        Relative residual tolerance of the Schur-complement PCG.

    Attributes
    ----------
    mesh : TriangleMesh
    K, M, M_load : (#V, #V) csr_matrix
        Stiffness (eq. 6.3), mass of (6.1) and consistent load mass (eq. 6.5).
    interior : (#V,) bool
        Vertices carrying a ``u1`` unknown (referenced, not on the boundary).
    method : str
        Linear-algebra path in use: "saddle", "schur" (PCG), "lumped" (exact
        sparse Schur complement), or the bc name for "navier"/"closed".
    last_iterations : int or None
        PCG iterations of the last solve (``None`` for direct solves).

    Raises
    ------
    ValueError
        Bad mesh (see :class:`TriangleMesh`), unknown ``bc``/``mass``/``solver``,
        or a mesh whose boundary does not match ``bc``.
    SolverError
        libigl's matrices are not finite for a face, or a factorisation is singular
        in float64 (``.faces`` names the faces when known).

    References
    ----------
    Stein, Grinspun, Jacobson, Wardetzky (2022), eq. (1.5), (6.1)–(6.5).
    """

    def __init__(self, V: Any, F: ArrayLike | None = None, *, bc: str = "clamped", mass: str = "full",
                 solver: str = "auto", rtol: float = 1e-10) -> None:
        self.mesh = as_mesh(V, F)
        self.bc = _check_choice(bc, "bc", BOUNDARY_CONDITIONS)
        self.mass = _check_choice(mass, "mass", MASS_TYPES)
        self.solver = _check_choice(solver, "solver", SOLVERS)
        if isinstance(rtol, bool) or not (isinstance(rtol, (float, int)) and 0 < rtol < 1):
            raise ValueError(f"rtol must be a number in (0, 1), got {rtol!r}")
        self.rtol = float(rtol)
        mesh = self.mesh
        self.active = mesh.referenced_vertices
        self.components = self._components()
        self._check_boundary()
        self.K = stiffness_matrix(mesh)
        self.M_load = mass_matrix(mesh, "full")
        self.M = self.M_load if mass == "full" else mass_matrix(mesh, mass)
        self.interior = self.active & ~mesh.boundary_vertices
        self.last_iterations = None
        self._I = np.flatnonzero(self.interior)
        self._A = np.flatnonzero(self.active)
        self._B = np.flatnonzero(self.active & mesh.boundary_vertices)
        self.method = self.bc
        if self.bc == "clamped":
            self._setup_clamped()
        elif self.bc == "navier":
            self._solve_KII = _factorize_spd(self.K[self._I][:, self._I])
        else:
            self._setup_closed()

    # ------------------------------------------------------------ setup
    def _components(self):
        import igl
        C = np.asarray(igl.vertex_components(self.mesh.F), dtype=np.int64)
        lab = np.full(self.mesh.n_vertices, -1, dtype=np.int64)
        lab[: len(C)] = C
        lab[~self.active] = -1
        # relabel 0..n_comp-1 over referenced vertices
        uniq, inv = np.unique(lab[self.active], return_inverse=True)
        lab[self.active] = inv
        self.n_components = len(uniq)
        return lab

    def _check_boundary(self):
        mesh = self.mesh
        if self.bc == "closed":
            if mesh.has_boundary:
                nb = int(mesh.boundary_edges.sum())
                e = int(np.flatnonzero(mesh.boundary_edges)[0])
                raise ValueError(
                    f"bc='closed' needs a mesh without boundary, but it has {nb} boundary edges "
                    f"(first: edge {e}, vertices {mesh.edges[e].tolist()}); use bc='clamped' or 'navier'")
            return
        has_b = np.zeros(self.n_components, dtype=bool)
        has_b[self.components[self.active & mesh.boundary_vertices]] = True
        if not has_b.all():
            c = int(np.flatnonzero(~has_b)[0])
            v = int(np.flatnonzero(self.components == c)[0])
            what = "the mesh has no boundary" if not mesh.has_boundary else \
                f"connected component {c} (containing vertex {v}) has no boundary"
            raise ValueError(
                f"bc={self.bc!r} needs a boundary on every connected component, but {what}; "
                f"use bc='closed' for closed surfaces")

    def _setup_clamped(self):
        I, A = self._I, self._A
        self._Bmat = self.K[I][:, A].tocsr()           # K_IA: rows ξ ∈ S_h,0, cols u2 ∈ S_h
        M_AA = self.M[A][:, A].tocsr()
        self.method = self.solver
        if self.mass != "full":
            if self.solver == "saddle":
                raise ValueError("solver='saddle' is only used with mass='full'; a lumped mass "
                                 "is solved exactly through its sparse Schur complement")
            self.method = "lumped"
            self._minv = 1.0 / M_AA.diagonal()
            Q = self._Bmat @ sp.diags(self._minv) @ self._Bmat.T
            self._solve_Q = _factorize_spd(Q)
        else:
            if self.method == "auto":
                self.method = "saddle" if len(A) <= AUTO_SADDLE_MAX_VERTICES else "schur"
            if self.method == "saddle":
                S = sp.bmat([[None, self._Bmat], [self._Bmat.T, -M_AA]], format="csc")
                self._solve_saddle = _factorize_general(S)
            else:
                ml = np.asarray(M_AA.sum(axis=1)).ravel()   # barycentric lumping
                self._minv = 1.0 / ml
                self._solve_M = mass_solver(M_AA, self._minv, max(1e-3 * self.rtol, 1e-14))
                Q = self._Bmat @ sp.diags(self._minv) @ self._Bmat.T
                self._solve_Q = _factorize_spd(Q)

    def _setup_closed(self):
        # pin the first vertex of every component: K restricted to the rest is SPD
        A = self._A
        comp = self.components[A]
        first = np.unique(comp, return_index=True)[1]
        pinned = np.zeros(len(A), dtype=bool)
        pinned[first] = True
        self._free = A[~pinned]
        self._solve_Kf = _factorize_spd(self.K[self._free][:, self._free])
        # per-component ∫ φ_i rows of M (for means)
        self._comp_A = comp
        self._Mrow = np.asarray(self.M[A][:, A].sum(axis=0)).ravel()
        self._Mload_row = np.asarray(self.M_load[A][:, A].sum(axis=0)).ravel()

    # ------------------------------------------------------------ solve
    def solve(self, f: Any, *, g: Any = None, q: Any = None, w: Any = None,
              project_mean: bool = False) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Solve ``Δ²u = f`` with the factorised system.

        Parameters
        ----------
        f : (#V,) array_like, scalar, or callable ``f(X: (#V, 3)) -> (#V,)``
            Right-hand side at the vertices (P1 interpolant ``I_h f``; the load
            is ``∫ φ_i I_h f``, eq. 6.5).
        g : (#V,) array_like or callable, optional
            Dirichlet data ``u = g`` (bc "clamped"/"navier"); only the values at
            boundary vertices are used.
        q : (#V,) array_like or callable, optional
            Neumann data ``∂u/∂n = q`` along the outward conormal of the
            boundary (bc "clamped" only); enters as ``∫_∂ q η ds`` with
            ``q`` linear on every boundary edge.
        w : (#V,) array_like or callable, optional
            ``-Δu = w`` on the boundary (bc "navier" only).
        project_mean : bool
            bc "closed" only: subtract the mean of ``I_h f`` on every connected
            component instead of raising when it is not zero.

        Returns
        -------
        u1 : (#V,) float64
            P1 approximation of ``u`` (NaN at unreferenced vertices).
        u2 : (#V,) float64
            P1 approximation of ``-Δu`` (NaN at unreferenced vertices).

        Raises
        ------
        ValueError / TypeError
            Bad data shapes or values, data not allowed for this ``bc``,
            ``f`` without zero mean for ``bc="closed"``.
        SolverError
            The solution is not finite (the mesh's scale overflows float64).
        """
        mesh = self.mesh
        fv = _vertex_function(mesh, f, "f", allow_none=False)
        allowed = {"clamped": ("g", "q"), "navier": ("g", "w"), "closed": ()}[self.bc]
        for name, val in (("g", g), ("q", q), ("w", w)):
            if val is not None and name not in allowed:
                raise ValueError(f"boundary data {name!r} is not used by bc={self.bc!r} "
                                 f"(it accepts {allowed if allowed else 'no boundary data'})")
        if project_mean and self.bc != "closed":
            raise ValueError("project_mean=True only applies to bc='closed'")
        g = _vertex_function(mesh, g, "g")
        q = _vertex_function(mesh, q, "q")
        w = _vertex_function(mesh, w, "w")
        self.last_iterations = None
        u1 = np.full(mesh.n_vertices, np.nan)
        u2 = np.full(mesh.n_vertices, np.nan)
        if self.bc == "clamped":
            self._solve_clamped(fv, g, q, u1, u2)
        elif self.bc == "navier":
            self._solve_navier(fv, g, w, u1, u2)
        else:
            self._solve_closed(fv, project_mean, u1, u2)
        ref = mesh.referenced_vertices
        if not (np.isfinite(u1[ref]).all() and np.isfinite(u2[ref]).all()):
            from .errors import SolverError
            raise SolverError(f"the biharmonic solve overflowed float64 (longest edge "
                              f"{mesh.max_edge_length:.3g}; u grows like length⁴ × f): rescale "
                              f"the mesh and the data")
        return u1, u2

    def _solve_clamped(self, fv, g, q, u1, u2):
        I, A, Bv = self._I, self._A, self._B
        b = (self.M_load @ fv)[I]
        n = self.mesh.n_vertices
        r = np.zeros(n)
        if q is not None:
            r += boundary_mass_matrix(self.mesh) @ q
        if g is not None:
            gB = np.zeros(n)
            gB[Bv] = g[Bv]
            r -= self.K @ gB
        r = r[A]
        Bm = self._Bmat
        if self.method == "saddle":
            x = self._solve_saddle(np.concatenate([b, r]))
            x1, x2 = x[: len(I)], x[len(I):]
        elif self.method == "lumped":
            x1 = self._solve_Q(b + Bm @ (self._minv * r))
            x2 = self._minv * (Bm.T @ x1 - r)
        else:
            x1, x2 = self._schur_pcg(b, r)
        u1[A] = 0.0
        if g is not None:
            u1[Bv] = g[Bv]
        u1[I] = x1
        u2[A] = x2

    def _schur_pcg(self, b, r):
        """CG on ``K_IA M⁻¹ K_AI u1 = b + K_IA M⁻¹ r`` preconditioned by the
        factorised lumped Schur complement; then ``u2 = M⁻¹ (K_AI u1 - r)``."""
        Bm, solve_M, solve_Q = self._Bmat, self._solve_M, self._solve_Q
        n = Bm.shape[0]
        S = spla.LinearOperator((n, n), matvec=lambda x: Bm @ solve_M(Bm.T @ x), dtype=np.float64)
        P = spla.LinearOperator((n, n), matvec=solve_Q, dtype=np.float64)
        rhs = b + Bm @ solve_M(r)
        it = [0]

        def count(_):
            it[0] += 1

        x0 = solve_Q(rhs)
        maxiter = 200
        x1, info = spla.cg(S, rhs, x0=x0, rtol=self.rtol, atol=0.0, M=P, maxiter=maxiter,
                           callback=count)
        if info != 0:
            res = np.linalg.norm(S @ x1 - rhs) / max(np.linalg.norm(rhs), 1e-300)
            raise SolverDidNotConverge(
                f"Schur-complement PCG did not reach rtol={self.rtol:g} in {maxiter} iterations "
                f"(relative residual {res:.3g}); try solver='saddle'")
        self.last_iterations = it[0]
        return x1, solve_M(Bm.T @ x1 - r)

    def _solve_navier(self, fv, g, w, u1, u2):
        I, A, Bv = self._I, self._A, self._B
        n = self.mesh.n_vertices
        x2 = np.zeros(n)
        if w is not None:
            x2[Bv] = w[Bv]
        rhs2 = self.M_load @ fv - self.K @ x2
        x2[I] = self._solve_KII(rhs2[I])
        x1 = np.zeros(n)
        if g is not None:
            x1[Bv] = g[Bv]
        rhs1 = self.M @ x2 - self.K @ x1
        x1[I] = self._solve_KII(rhs1[I])
        u1[A] = x1[A]
        u2[A] = x2[A]

    def _component_sums(self, x):
        return np.bincount(self._comp_A, weights=x, minlength=self.n_components)

    def _solve_closed(self, fv, project_mean, u1, u2):
        A = self._A
        fa = fv[A]
        area = self._component_sums(self._Mload_row)
        mean_f = self._component_sums(self._Mload_row * fa) / area
        if project_mean:
            fa = fa - mean_f[self._comp_A]
        else:
            scale = self._component_sums(self._Mload_row * np.abs(fa)) / area
            bad = np.abs(mean_f) > ZERO_MEAN_RTOL * np.maximum(scale, np.finfo(float).tiny)
            if bad.any():
                c = int(np.flatnonzero(bad)[0])
                raise ValueError(
                    f"bc='closed' needs f with zero mean on every connected component "
                    f"(∫ I_h f = 0), but component {c} has mean {mean_f[c]:.6g} "
                    f"(mean |f| = {scale[c]:.6g}); pass project_mean=True to subtract it")
        MA = self.M_load[A][:, A]
        x2 = self._poisson_closed(MA @ fa)
        # zero mean w.r.t. the mass of (6.1), so that K u1 = M u2 is compatible
        areaM = self._component_sums(self._Mrow)
        x2 -= (self._component_sums(self._Mrow * x2) / areaM)[self._comp_A]
        x1 = self._poisson_closed(self.M[A][:, A] @ x2)
        x1 -= (self._component_sums(self._Mrow * x1) / areaM)[self._comp_A]
        u1[A] = x1
        u2[A] = x2

    def _poisson_closed(self, rhs_A):
        """Solve K x = rhs (compatible) on the active vertices with the pinned factorisation."""
        n = self.mesh.n_vertices
        rhs = np.zeros(n)
        rhs[self._A] = rhs_A
        x = np.zeros(n)
        x[self._free] = self._solve_Kf(rhs[self._free])
        return x[self._A]


@kernels.with_large_call_heap
def biharmonic_solve(V: Any, F: ArrayLike | None, f: Any, *, bc: str = "clamped", mass: str = "full",
                     g: Any = None, q: Any = None, w: Any = None, project_mean: bool = False,
                     solver: str = "auto", rtol: float = 1e-10) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Solve ``Δ²u = f`` on a triangle mesh with the mixed P1 method (Stein et al. 2022).

    One-shot wrapper around :class:`BiharmonicSolver`; use the class to reuse
    the factorisation for several right-hand sides.

    Parameters
    ----------
    V : (#V, 3) array_like float
    F : (#F, 3) array_like int
    f : (#V,) array_like, scalar, or callable ``f(X: (#V, 3)) -> (#V,)``
        Right-hand side sampled at the vertices; load ``∫ φ_i I_h f`` (eq. 6.5).
    bc : {"clamped", "navier", "closed"}
        ``u = ∂u/∂n = 0`` (Stein et al. 2022), ``u = Δu = 0``, or no boundary with
        zero-mean ``u1``, ``u2`` (§5.3).
    mass : {"full", "lumped", "voronoi"}
        Consistent mass (the paper) or lumped (geometry-processing ``K M⁻¹ K``).
    g, q, w : optional inhomogeneous boundary data, see
        :meth:`BiharmonicSolver.solve` (``u = g``; ``∂u/∂n = q`` for clamped;
        ``-Δu = w`` for navier).
    project_mean : bool
        bc "closed": subtract the mean of ``f`` instead of raising.
    solver, rtol : see :class:`BiharmonicSolver`.

    Returns
    -------
    u1 : (#V,) float64
        ≈ u at the vertices.
    u2 : (#V,) float64
        ≈ -Δu at the vertices (the sign of Stein et al. 2022).

    Examples
    --------
    >>> import numpy as np, igl
    >>> from igl_hhj.biharmonic import biharmonic_solve
    >>> V, F = igl.icosahedron()
    >>> V, F = igl.upsample(V / np.linalg.norm(V, axis=1)[:, None], F)
    >>> u1, u2 = biharmonic_solve(V, F, V[:, 2], bc="closed", project_mean=True)
    >>> u1.shape, bool(np.isfinite(u2).all())
    ((42,), True)
    """
    solver_ = BiharmonicSolver(V, F, bc=bc, mass=mass, solver=solver, rtol=rtol)
    return solver_.solve(f, g=g, q=q, w=w, project_mean=project_mean)
