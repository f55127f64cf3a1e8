"""Distributional densitized Gauss curvature of a Regge metric and its lifting
to Lagrange elements (Gopalakrishnan et al. 2024, Definition 2.1, Definition 2.3, Remark 3.3).

Sign conventions (design note ``regge.md``; the round sphere has ``K = +1``):

* element:  ``K(g)|_T = R_1212 / det g`` with
  ``R_1212 = -½(g_11,22 + g_22,11 - 2 g_12,12) + g^{pq}(Γ_{12,p}Γ_{12,q} - Γ_{11,p}Γ_{22,q})``,
  ``Γ_{ij,l} = ½(∂_i g_jl + ∂_j g_il - ∂_l g_ij)``;
* edge: ``κ_in = -Γ_{ij,l} t^i t^j (G⁻¹n)^l / (g_tt √(nᵀG⁻¹n))``, the geodesic
  curvature of the straight edge in ``g_h|_T`` w.r.t. the g-unit normal pointing
  into ``T`` (``n`` = Euclidean outward normal); each element integrates its
  own side, so an interior edge receives the jump ``[[κ]] = κ^{T+} + κ^{T-}``;
* vertex: ``Θ_V = 2π - Σ_T θ_V^T`` at *every* vertex, boundary included;
* Neumann data (``κ̄^N``): ``-∫_{Γ_N} κ̄ u ω̄_E - Σ_{V ∈ Γ_N} ā_V u(V)`` with
  ``ā_V = 2π - (interior angle of ∂Ω at V in ḡ)``.

Everything is computed on the reference element with the pulled-back metric
``ĝ = Jᵀ g J`` (all quantities are coordinate invariant) and vectorised over
elements; loops run over local edges/corners only.
"""
from __future__ import annotations

import numpy as np

from .elements import (REF_EDGE_NORMALS, REF_EDGE_TANGENTS, REF_VERTICES, LagrangeSpace,
                       MAX_DEGREE, MAX_QUAD_DEGREE, ReggeMetric, _call_metric, _call_scalar,
                       _check_finite_values, _check_int, monomials)
from .quadrature import gauss_legendre, triangle_rule

__all__ = ["metric_gauss_curvature", "edge_geodesic_curvature", "corner_angles",
           "gauss_curvature_functional", "lift_gauss_curvature", "LiftedCurvature",
           "triangle_gauss_bonnet"]

TWO_PI = 2.0 * np.pi


# ----------------------------------------------------------- pointwise formulas
def _christoffel_explicit(dg):
    G = np.empty(dg.shape[:-3] + (2, 2, 2))
    for i in range(2):
        for j in range(2):
            for l in range(2):
                G[..., i, j, l] = 0.5 * (dg[..., i, j, l] + dg[..., j, i, l] - dg[..., l, i, j])
    return G


def metric_gauss_curvature(g, dg, ddg):
    """Gauss curvature of a smooth metric from its value and derivatives.

    Parameters
    ----------
    g : (..., 2, 2) metric
    dg : (..., 2, 2, 2) with ``dg[..., a, i, j] = ∂_a g_ij``
    ddg : (..., 2, 2, 2, 2) with ``ddg[..., a, b, i, j] = ∂_a ∂_b g_ij``

    Returns
    -------
    K : (...) ``R_1212 / det g`` (Brioschi; round sphere → +1)
    """
    det = g[..., 0, 0] * g[..., 1, 1] - g[..., 0, 1] ** 2
    ginv = np.stack([np.stack([g[..., 1, 1], -g[..., 0, 1]], -1),
                     np.stack([-g[..., 1, 0], g[..., 0, 0]], -1)], -2) / det[..., None, None]
    Gam = _christoffel_explicit(dg)
    second = -0.5 * (ddg[..., 1, 1, 0, 0] + ddg[..., 0, 0, 1, 1] - 2.0 * ddg[..., 0, 1, 0, 1])
    quad = (np.einsum("...pq,...p,...q->...", ginv, Gam[..., 0, 1, :], Gam[..., 0, 1, :])
            - np.einsum("...pq,...p,...q->...", ginv, Gam[..., 0, 0, :], Gam[..., 1, 1, :]))
    return (second + quad) / det


def edge_geodesic_curvature(g, dg, t, n):
    """Geodesic curvature of a straight segment with direction ``t`` in the metric
    ``g``, w.r.t. the g-unit normal on the side *opposite* the covector ``n``
    (``n`` = Euclidean outward normal of the element → inward curvature ``κ_in``).

    Parameters
    ----------
    g : (..., 2, 2), dg : (..., 2, 2, 2) (``dg[..., a, i, j] = ∂_a g_ij``)
    t, n : (..., 2) or (2,)

    Returns
    -------
    kappa : (...)
    """
    Gam = _christoffel_explicit(dg)
    det = g[..., 0, 0] * g[..., 1, 1] - g[..., 0, 1] ** 2
    ginv = np.stack([np.stack([g[..., 1, 1], -g[..., 0, 1]], -1),
                     np.stack([-g[..., 1, 0], g[..., 0, 0]], -1)], -2) / det[..., None, None]
    t = np.broadcast_to(t, g.shape[:-1])
    n = np.broadcast_to(n, g.shape[:-1])
    nu = np.einsum("...lk,...k->...l", ginv, n)
    nnorm = np.sqrt(np.einsum("...l,...l->...", n, nu))
    gtt = np.einsum("...i,...ij,...j->...", t, g, t)
    num = np.einsum("...ijl,...i,...j,...l->...", Gam, t, t, nu)
    return -num / (gtt * nnorm)


def corner_angles(g, t1, t2):
    """Angle between ``t1`` and ``t2`` in the metric ``g`` (in ``[0, π]``), computed
    as ``atan2(√det g |t1 × t2|, g(t1, t2))`` (accurate also for tiny angles)."""
    det = g[..., 0, 0] * g[..., 1, 1] - g[..., 0, 1] ** 2
    t1 = np.broadcast_to(t1, g.shape[:-1])
    t2 = np.broadcast_to(t2, g.shape[:-1])
    cross = np.abs(t1[..., 0] * t2[..., 1] - t1[..., 1] * t2[..., 0])
    dot = np.einsum("...i,...ij,...j->...", t1, g, t2)
    return np.arctan2(np.sqrt(det) * cross, dot)


def _signed_angle(G, a, b):
    """Counter-clockwise angle from ``a`` to ``b`` in the metric ``G`` (in ``[0, 2π)``)."""
    L = np.linalg.cholesky(G)                     # G = L Lᵀ, g(u, v) = (Lᵀu)·(Lᵀv)
    A = np.einsum("nji,nj->ni", L, a)
    B = np.einsum("nji,nj->ni", L, b)
    ang = np.arctan2(A[:, 0] * B[:, 1] - A[:, 1] * B[:, 0], (A * B).sum(1))
    return np.mod(ang, TWO_PI)


# --------------------------------------------------------------- element terms
def _default_quad(k, p):
    return 2 * max(k, p) + 10


def _element_terms(gh, space, quad_degree):
    """Local load vectors of Definition 2.1 and local g_h-mass/Euclidean-mass data.

    Returns
    -------
    load : (#F, n_local) element + edge + (-θ) corner contributions
    Mg : (#F, n_local, n_local) ``∫_T φ_a φ_b ω_h``
    """
    pts, w = triangle_rule(quad_degree)
    phi = space.basis(pts)
    g, dg, ddg = gh.reference_values(pts, derivatives=2)
    gv = gh.reference_values(REF_VERTICES, derivatives=0)
    for G in (g, gv):
        bad = ((G[..., 0, 0] <= 0) | (G[..., 0, 0] * G[..., 1, 1] - G[..., 0, 1] ** 2 <= 0)).any(axis=1)
        if bad.any():
            raise ValueError("the Regge metric g_h is not positive definite on face "
                             f"{int(np.flatnonzero(bad)[0])} (refine the mesh or raise the degree)")
    K = metric_gauss_curvature(g, dg, ddg)
    vol = np.sqrt(g[..., 0, 0] * g[..., 1, 1] - g[..., 0, 1] ** 2)
    load = np.einsum("q,fq,qa->fa", w, K * vol, phi)
    Mg = np.einsum("q,fq,qa,qb->fab", w, vol, phi, phi)
    s, ws = gauss_legendre(quad_degree)
    for i in range(3):
        a = REF_VERTICES[(i + 1) % 3]
        t = REF_EDGE_TANGENTS[i]
        epts = a[None, :] + s[:, None] * t[None, :]
        ge, dge = gh.reference_values(epts, derivatives=1)
        kap = edge_geodesic_curvature(ge, dge, t, REF_EDGE_NORMALS[i])
        ds = np.sqrt(np.einsum("i,fqij,j->fq", t, ge, t))
        load += np.einsum("q,fq,qa->fa", ws, kap * ds, space.basis(epts))
    for c in range(3):
        gv = gh.reference_values(REF_VERTICES[c:c + 1], derivatives=0)[:, 0]
        t1 = REF_VERTICES[(c + 1) % 3] - REF_VERTICES[c]
        t2 = REF_VERTICES[(c + 2) % 3] - REF_VERTICES[c]
        load[:, c] -= corner_angles(gv, t1, t2)
    return load, Mg


def triangle_gauss_bonnet(gh, quad_degree=None):
    """Per element ``∫_T K ω_T + ∮_{∂T} κ_in ω_E + Σ_corners (π - θ)``; equals ``2π``
    up to round-off for any (smooth-in-T) metric.  Returns ``(#F,)``."""
    k = gh.degree
    qd = _default_quad(k, 1) if quad_degree is None else _check_int(
        quad_degree, "quad_degree", 2 * max(k, 1), MAX_QUAD_DEGREE)
    space = LagrangeSpace(gh.tri, 1)
    load, _ = _element_terms(gh, space, qd)
    return load.sum(axis=1) + 3 * np.pi


def _boundary_halfedges(tri):
    """Boundary edges as counter-clockwise half-edges: (edge ids, face, local, start, end)."""
    m = tri.mesh
    e = np.flatnonzero(m.boundary_edges)
    f = np.where(m.edge_faces[e, 0] >= 0, m.edge_faces[e, 0], m.edge_faces[e, 1])
    i = np.where(m.edge_faces[e, 0] >= 0, m.edge_local_index[e, 0], m.edge_local_index[e, 1])
    start = tri.F[f, (i + 1) % 3]
    end = tri.F[f, (i + 2) % 3]
    return e, f, i, start, end


def _edge_mask(tri, spec, name):
    m = tri.mesh
    if spec is None:
        return np.zeros(m.n_edges, dtype=bool)
    if callable(spec):
        mid = 0.5 * (tri.P[m.edges[:, 0]] + tri.P[m.edges[:, 1]])
        b = np.flatnonzero(m.boundary_edges)
        vals = np.asarray(spec(mid[b]))
        if vals.shape != (b.size,):
            raise ValueError(f"{name} callable must map (N, 2) edge midpoints to (N,) booleans, "
                             f"got shape {vals.shape}")
        mask = np.zeros(m.n_edges, dtype=bool)
        mask[b] = vals.astype(bool)
        return mask
    mask = np.asarray(spec)
    if mask.dtype != bool:
        raise TypeError(f"{name} must be a boolean mask over the {m.n_edges} unique edges or a "
                        f"callable on edge midpoints, got dtype {mask.dtype}")
    if mask.shape != (m.n_edges,):
        raise ValueError(f"{name} mask must have shape ({m.n_edges},), got {mask.shape}")
    bad = mask & ~m.boundary_edges
    if bad.any():
        raise ValueError(f"{name} marks interior edges; first is edge {int(np.flatnonzero(bad)[0])}")
    return mask.copy()


class LiftedCurvature:
    """The lifted Gauss curvature ``K_h ∈ V_h^p`` (or, if ``densitized``, the Euclidean-mass
    lifting ``(Kω)_h``, the Euclidean L² projection of ``K_h ω_h``).

    Attributes
    ----------
    space : LagrangeSpace
    dofs : (n_dofs,) float64 nodal values
    load : (n_dofs,) right-hand side of eq. (2.6) (Definition 2.1 minus Neumann data)
    mass : sparse (n_dofs, n_dofs) mass matrix used (``ω_h``-weighted or Euclidean)
    dirichlet_dofs : (n_D,) int64
    densitized : bool
    """

    def __init__(self, space, dofs, load, mass, dirichlet_dofs, densitized, gh):
        self.space = space
        self.dofs = dofs
        self.load = load
        self.mass = mass
        self.dirichlet_dofs = dirichlet_dofs
        self.densitized = densitized
        self.metric = gh

    @property
    def degree(self):
        return self.space.degree

    def __call__(self, faces, bary):
        """Evaluate at ``faces (n,)`` with barycentric coordinates ``bary (n, 3)``."""
        return self.space.evaluate(self.dofs, faces, bary)

    def reference_values(self, points):
        """Values ``(#F, n)`` at reference points on every element."""
        phi = self.space.basis(points)
        return np.einsum("qa,fa->fq", phi, self.dofs[self.space.cell_dofs])

    def total(self):
        """``∫ K_h ω_h`` (or ``∫ K_h ω_h dx`` when densitized) = ``1ᵀ M K_h``."""
        return float(self.mass.sum(axis=0) @ self.dofs)

    def _error_at(self, exact, pts, times_omega_h, gradient=None):
        """Error ``ē - e_h`` at reference ``pts`` on every element, ``(#F, n)``, where
        ``e_h = K_h`` or ``K_h ω_h`` (``times_omega_h``); with ``gradient`` also the
        physical gradient of the error ``(#F, n, 2)``."""
        tri = self.space.tri
        if times_omega_h and self.densitized:
            raise ValueError("times_omega_h=True multiplies the pure lifting K_h by ω_h; this "
                             "lifting is already densitized (lift with densitized=False)")
        X = tri.to_physical(pts)
        ex = _call_scalar(exact, X.reshape(-1, 2), "exact").reshape(X.shape[:2])
        if gradient is None:
            phi = self.space.basis(pts)
        else:
            phi, dphi = self.space.basis(pts, derivatives=True)
        loc = self.dofs[self.space.cell_dofs]
        val = np.einsum("qa,fa->fq", phi, loc)
        Jinv = np.linalg.inv(tri.J)                                   # ∇_x = J^{-T} ∇̂
        if gradient is not None:
            grad = np.einsum("fki,qak,fa->fqi", Jinv, dphi, loc)
        if times_omega_h:
            # ω_h = √det g_h = √det ĝ / det J (ĝ = Jᵀ g_h J, affine elements)
            g, dg = self.metric.reference_values(pts, derivatives=1)
            det = g[..., 0, 0] * g[..., 1, 1] - g[..., 0, 1] ** 2
            om = np.sqrt(det) / tri.detJ[:, None]
            if gradient is not None:
                # ∂_a √det ĝ = ½ √det ĝ tr(ĝ⁻¹ ∂_a ĝ)
                ginv = np.linalg.inv(g)
                dom_ref = 0.5 * om[..., None] * np.einsum("fqij,fqaji->fqa", ginv, dg)
                grad = om[..., None] * grad + val[..., None] * np.einsum("fki,fqk->fqi", Jinv, dom_ref)
            val = val * om
        if gradient is None:
            return ex - val
        gex = np.asarray(gradient(X.reshape(-1, 2)), dtype=np.float64)
        if gex.shape != (X.shape[0] * X.shape[1], 2):
            raise ValueError(f"exact_gradient must map (N, 2) points to shape (N, 2), got {gex.shape}")
        _check_finite_values(gex, X.reshape(-1, 2), "exact_gradient")
        return ex - val, gex.reshape(X.shape[:2] + (2,)) - grad

    def l2_error(self, exact, quad_degree=None, *, times_omega_h=False):
        """Euclidean ``‖K_h - K̄‖_{L²(Ω)}`` for ``exact: (N, 2) -> (N,)``.

        ``times_omega_h=True``: the densitized error ``‖K_h ω_h - K̄ ω̄‖_{L²}`` of
        Theorem 3.1 / Corollary 3.2 (``ω_h = √det g_h``, pointwise product with the
        pure lifting; pass ``exact = K̄ ω̄``)."""
        tri = self.space.tri
        pts, w = triangle_rule(quad_degree or 2 * self.degree + 10)
        d = self._error_at(exact, pts, times_omega_h)
        return float(np.sqrt(np.einsum("q,fq,f->", w, d * d, tri.detJ)))

    def h1_error(self, exact, exact_gradient, quad_degree=None, *, times_omega_h=False):
        """Elementwise (broken) ``‖K_h - K̄‖_{H¹_h} = (Σ_T ‖K_h - K̄‖²_{H¹(T)})^{1/2}``,
        the ``r = 1`` norm of Corollary 3.9 (``times_omega_h``: of ``K_h ω_h - K̄ ω̄``,
        Corollary 3.2; rate ``k`` for ``K_h ∈ V_h^k``).

        Parameters
        ----------
        exact : callable ``(N, 2) -> (N,)``
        exact_gradient : callable ``(N, 2) -> (N, 2)``, Euclidean gradient of ``exact``
        """
        if not callable(exact_gradient):
            raise TypeError("exact_gradient must be callable (N, 2) -> (N, 2)")
        tri = self.space.tri
        pts, w = triangle_rule(quad_degree or 2 * self.degree + 10)
        d, dd = self._error_at(exact, pts, times_omega_h, gradient=exact_gradient)
        return float(np.sqrt(np.einsum("q,fq,f->", w, d * d + (dd * dd).sum(-1), tri.detJ)))

    def h_minus1_error(self, exact, degree=None, quad_degree=None, *, times_omega_h=False):
        """``‖K̄ - K_h‖_{H⁻¹} ≈ ‖w‖_{H¹}`` (full norm), ``w ∈ V_h^{p+2}`` (default) solving
        ``-Δw = K̄ - K_h``, ``w = 0`` on ``∂Ω`` (Gopalakrishnan et al. 2024, §4);
        ``times_omega_h``: of ``K̄ ω̄ - K_h ω_h`` (Theorem 3.1)."""
        import scipy.sparse.linalg as spla
        tri = self.space.tri
        P = self.degree + 2 if degree is None else _check_int(degree, "degree", 1, MAX_DEGREE)
        W = LagrangeSpace(tri, P)
        qd = quad_degree or 2 * P + 10
        pts, w = triangle_rule(qd)
        d = self._error_at(exact, pts, times_omega_h)
        b = W.assemble_vector(np.einsum("q,fq,qa,f->fa", w, d, W.basis(pts), tri.detJ))
        A = W.stiffness_matrix()
        M = W.mass_matrix()
        bd = W.edge_dofs(tri.mesh.boundary_edges)
        free = np.setdiff1d(np.arange(W.n_dofs), bd)
        sol = np.zeros(W.n_dofs)
        sol[free] = spla.splu(A[free][:, free].tocsc()).solve(b[free])
        return float(np.sqrt(sol @ (A @ sol) + sol @ (M @ sol)))


def gauss_curvature_functional(gh, degree=None, quad_degree=None):
    """Assemble ``K̃ω(g_h)(φ_a)`` (eq. 2.5, boundary terms included) for the
    Lagrange basis of degree ``degree`` (default ``max(k, 1)``).

    Returns
    -------
    space : LagrangeSpace
    load : (n_dofs,) float64
    Mg : (#F, n_local, n_local) local ``ω_h`` mass matrices
    """
    if not isinstance(gh, ReggeMetric):
        raise TypeError(f"g_h must be a ReggeMetric (see igl_hhj.regge.interpolate), "
                        f"got {type(gh).__name__}")
    p = max(gh.degree, 1) if degree is None else _check_int(degree, "degree", 1, MAX_DEGREE)
    qd = _default_quad(gh.degree, p) if quad_degree is None else _check_int(
        quad_degree, "quad_degree", 2 * max(gh.degree, p), MAX_QUAD_DEGREE,
        " = 2 max(k, p) (the element integrals must be exact for the mass matrix to be SPD)")
    space = LagrangeSpace(gh.tri, p)
    load_loc, Mg = _element_terms(gh, space, qd)
    load = space.assemble_vector(load_loc)
    load[: gh.tri.n_vertices] += TWO_PI
    return space, load, Mg


def lift_gauss_curvature(g_h, degree=None, *, dirichlet=None, dirichlet_values=None,
                         neumann_metric="auto", neumann_curvature=None, densitized=False,
                         quad_degree=None):
    """Lifted distributional Gauss curvature ``K_h ∈ V_h^p`` (Gopalakrishnan et al. 2024, Definition 2.3).

    Find ``K_h`` with ``K_h = I_D K̄`` on ``Γ_D`` and, for all ``u`` vanishing on ``Γ_D``,

    ``∫ K_h u ω_h = K̃ω(g_h)(u) - ∫_{Γ_N} κ̄ u ω̄_E - Σ_{V ∈ Γ_N} ā_V u(V)``   (eq. 2.6)

    with ``K̃ω`` of eq. (2.5) (element curvature, geodesic-curvature jumps,
    angle deficits ``2π - Σθ`` at all vertices).  ``densitized=True`` uses the
    Euclidean mass matrix instead of the ``ω_h``-weighted one: ``(Kω)_h ∈ V_h^p`` with
    ``∫ (Kω)_h u dx = K̃ω(g_h)(u)``, the Euclidean L² projection of ``K_h ω_h``.  This is
    *not* the densitized quantity of Theorem 3.1 / Corollary 3.2, which is the pointwise
    product ``K_h ω_h`` of the default lifting with ``ω_h = √det g_h``: measure that one
    with ``l2_error(K̄ω̄, times_omega_h=True)`` (also ``h_minus1_error``, ``h1_error``).

    Parameters
    ----------
    g_h : ReggeMetric (from :func:`interpolate`), degree k
    degree : int, Lagrange degree p ≥ 1 (default ``max(k, 1)``; the paper's choice is p = k)
    dirichlet : None, (#E,) bool mask over unique edges (boundary edges only), or a
        callable ``(N, 2) edge midpoints -> (N,) bool`` (evaluated on boundary edges)
    dirichlet_values : callable ``(N, 2) -> (N,)``, ``K̄`` on ``Γ_D`` (nodal interpolation)
    neumann_metric : ``"auto"`` (the metric ``g_h`` interpolates), a callable ``ḡ``,
        or ``None``.  With a metric, every Neumann vertex gets ``ā_V = 2π - ∠_ḡ(V)``
        and ``ω̄_E = √ḡ(t,t)``; with ``None`` no Neumann data is subtracted
        (pure eq. 2.5 load, e.g. for Gauss–Bonnet checks).
    neumann_curvature : callable ``(x (N, 2), t (N, 2)) -> (N,)`` giving ``κ̄`` at
        boundary points ``x`` with unit Euclidean tangent ``t`` (counter-clockwise
        traversal, normal pointing into Ω); ``None`` means ``κ̄ = 0``.
    densitized : bool
    quad_degree : int, optional (default ``2 max(k, p) + 10``)

    Returns
    -------
    LiftedCurvature
    """
    import scipy.sparse.linalg as spla

    space, load, Mg = gauss_curvature_functional(g_h, degree, quad_degree)
    tri = g_h.tri
    m = tri.mesh
    p = space.degree
    qd = _default_quad(g_h.degree, p) if quad_degree is None else quad_degree
    dmask = _edge_mask(tri, dirichlet, "dirichlet")
    nmask = m.boundary_edges & ~dmask

    gbar = g_h.metric if isinstance(neumann_metric, str) and neumann_metric == "auto" else neumann_metric
    if isinstance(neumann_metric, str) and neumann_metric != "auto":
        raise ValueError(f"neumann_metric must be 'auto', a callable or None, got {neumann_metric!r}")
    if gbar is not None and not callable(gbar):
        raise TypeError("neumann_metric must be callable (N, 2) -> (N, 2, 2)")
    if neumann_curvature is not None and not callable(neumann_curvature):
        raise TypeError("neumann_curvature must be callable (x, t) -> (N,)")
    if neumann_curvature is not None and gbar is None and nmask.any():
        raise ValueError("neumann_curvature needs a metric for ω̄_E: pass neumann_metric")

    if gbar is not None and nmask.any():
        e, f, i, start, end = _boundary_halfedges(tri)
        keep = nmask[e]
        # vertex terms ā_V = 2π - interior angle in ḡ, on vertices of Neumann edges
        nV = tri.n_vertices
        nxt = -np.ones(nV, dtype=np.int64)
        prv = -np.ones(nV, dtype=np.int64)
        cnt = np.bincount(start, minlength=nV)
        if (cnt > 1).any():
            v = int(np.flatnonzero(cnt > 1)[0])
            raise ValueError(f"boundary is not a manifold curve at vertex {v} (pinched vertex)")
        nxt[start] = end
        prv[end] = start
        nv = np.unique(np.concatenate([start[keep], end[keep]]))
        Gv = _call_metric(gbar, tri.P[nv])
        ang = _signed_angle(Gv, tri.P[nxt[nv]] - tri.P[nv], tri.P[prv[nv]] - tri.P[nv])
        load[nv] -= TWO_PI - ang
        if neumann_curvature is not None and keep.any():
            s, ws = gauss_legendre(qd)
            fk, ik = f[keep], i[keep]
            a = REF_VERTICES[(ik + 1) % 3]
            tref = REF_EDGE_TANGENTS[ik]
            rp = a[:, None, :] + s[None, :, None] * tref[:, None, :]            # (n, ns, 2)
            X = tri.P[tri.F[fk, 0]][:, None, :] + np.einsum("nij,nsj->nsi", tri.J[fk], rp)
            tph = np.einsum("nij,nj->ni", tri.J[fk], tref)                       # edge vectors
            G = _call_metric(gbar, X.reshape(-1, 2)).reshape(X.shape[:2] + (2, 2))
            ds = np.sqrt(np.einsum("ni,nsij,nj->ns", tph, G, tph))
            tu = tph / np.linalg.norm(tph, axis=1, keepdims=True)
            kap = np.asarray(neumann_curvature(X.reshape(-1, 2), np.repeat(tu, s.size, axis=0)),
                             dtype=np.float64)
            if kap.shape != (X.shape[0] * s.size,):
                raise ValueError(f"neumann_curvature must return shape (N,), got {kap.shape}")
            _check_finite_values(kap, X.reshape(-1, 2), "neumann_curvature")
            kap = kap.reshape(X.shape[:2])
            mono = monomials(rp.reshape(-1, 2), p)["v"].reshape(rp.shape[0], s.size, -1)
            phi = np.einsum("nsm,ma->nsa", mono, space.coef)
            loc = np.einsum("s,ns,nsa->na", ws, kap * ds, phi)
            load -= np.bincount(space.cell_dofs[fk].ravel(), weights=loc.ravel(),
                                minlength=space.n_dofs)

    if densitized:
        pts, w = triangle_rule(2 * p)
        phi = space.basis(pts)
        loc = np.einsum("q,qa,qb->ab", w, phi, phi)[None] * tri.detJ[:, None, None]
        M = space.assemble_matrix(loc)
    else:
        M = space.assemble_matrix(Mg)

    ddofs = space.edge_dofs(dmask) if dmask.any() else np.zeros(0, dtype=np.int64)
    K = np.zeros(space.n_dofs)
    if ddofs.size:
        if dirichlet_values is None:
            raise ValueError("dirichlet edges given but no dirichlet_values callable")
        K[ddofs] = _call_scalar(dirichlet_values, space.nodes[ddofs], "dirichlet_values")
    free = np.setdiff1d(np.arange(space.n_dofs), ddofs)
    rhs = load[free] - M[free][:, ddofs] @ K[ddofs] if ddofs.size else load[free]
    K[free] = spla.splu(M[free][:, free].tocsc()).solve(rhs)
    return LiftedCurvature(space, K, load, M, ddofs, densitized, g_h)
