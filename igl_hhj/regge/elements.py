"""Regge and Lagrange finite elements of degree k on planar triangulations.

Every element ``T`` is the affine image ``x = x_0 + J_T ξ`` of the reference
triangle ``T̂ = {ξ, η ≥ 0, ξ + η ≤ 1}`` with corners ``v̂_0 = (0, 0)``,
``v̂_1 = (1, 0)``, ``v̂_2 = (0, 1)``; the barycentric coordinates of a point are
``(1 - ξ - η, ξ, η)``.  Local edge ``i`` is opposite corner ``i`` and runs from
corner ``i+1`` to corner ``i+2`` (libigl's order, as in :mod:`igl_hhj.mesh`).

Regge space (Gopalakrishnan et al. 2024, eq. 2.3).  A Regge function is stored element by
element through its *pull-back* ``ĝ = J_Tᵀ g J_T`` to ``T̂``: ``ĝ_ij ∈ P^k(T̂)``
iff ``g_ij ∈ P^k(T)``, and all curvature quantities (Gauss curvature, geodesic
curvature of edges, angles, volume forms) are coordinate invariant, so they
are computed on ``T̂``.  The canonical interpolant (eq. 3.1) is local: the
``3(k+1)(k+2)/2`` moments ``∫_E g(t,t) q, q ∈ P^k(E)`` and
``∫_T g : ρ, ρ ∈ P^{k-1}(T; S)`` determine ``g_h|_T`` uniquely, and both
neighbours of an edge share its moments, which gives the tangential–tangential
continuity of ``Reg_h^k``.  Because the moment conditions are invariant under
the affine pull-back, a single reference matrix is inverted once and applied
to all elements.

Lagrange space ``V_h^p``: nodal basis at the equispaced points of each element;
global DOFs are numbered vertices first (``0..#V-1``), then ``p-1`` nodes per
unique edge (ordered along ``edges[e, 0] → edges[e, 1]``), then the
``(p-1)(p-2)/2`` interior nodes per face.
"""
from __future__ import annotations

from functools import cached_property, lru_cache

import numpy as np

from ..mesh import TriangleMesh, _as_array
from .quadrature import gauss_legendre, triangle_rule

__all__ = ["PlanarTriangulation", "LagrangeSpace", "ReggeMetric", "interpolate",
           "REF_VERTICES", "regge_basis", "REF_EDGE_TANGENTS", "REF_EDGE_NORMALS", "monomials"]

REF_VERTICES = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
#: tangent of reference edge i: from corner i+1 to corner i+2
REF_EDGE_TANGENTS = REF_VERTICES[[2, 0, 1]] - REF_VERTICES[[1, 2, 0]]
#: outward (Euclidean) normal covector of reference edge i (not normalised)
REF_EDGE_NORMALS = np.array([[1.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])


MAX_DEGREE = 12
"""Largest polynomial degree (Regge k, Lagrange p) accepted: the local systems grow like
p⁴ and the Bernstein/monomial bases lose all accuracy in float64 well before p = 20."""

MAX_QUAD_DEGREE = 64
"""Largest quadrature degree accepted ((degree//2 + 1)² points per triangle)."""


def _check_int(value, name, minimum, maximum=None, why=""):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}{why}, got {value}")
    if maximum is not None and value > maximum:
        raise ValueError(f"{name} must be <= {maximum} (the work grows like degree⁴ and float64 "
                         f"cannot resolve higher degrees), got {value}")
    return int(value)


# --------------------------------------------------------------------- monomials
@lru_cache(maxsize=None)
def _exponents(p):
    return tuple((a, d - a) for d in range(p + 1) for a in range(d, -1, -1))


def monomials(points, p):
    """Monomials ``ξ^a η^b`` (``a + b ≤ p``) and their derivatives up to order 2.

    Parameters
    ----------
    points : (n, 2) reference coordinates
    p : int, maximal total degree

    Returns
    -------
    dict with keys ``"v", "x", "y", "xx", "xy", "yy"``, each ``(n, nm)`` with
    ``nm = (p+1)(p+2)/2`` (``x = ∂_ξ``, ``y = ∂_η``).
    """
    pts = np.asarray(points, dtype=np.float64)
    xi, eta = pts[:, 0:1], pts[:, 1:2]
    ex = np.array(_exponents(p)).reshape(1, -1, 2)
    a, b = ex[..., 0], ex[..., 1]

    def pw(x, e):
        # x**e with x**(negative) -> 0 (the coefficient vanishes anyway)
        return np.where(e >= 0, x ** np.maximum(e, 0), 0.0)

    out = {
        "v": pw(xi, a) * pw(eta, b),
        "x": a * pw(xi, a - 1) * pw(eta, b),
        "y": b * pw(xi, a) * pw(eta, b - 1),
        "xx": a * (a - 1) * pw(xi, a - 2) * pw(eta, b),
        "xy": a * b * pw(xi, a - 1) * pw(eta, b - 1),
        "yy": b * (b - 1) * pw(xi, a) * pw(eta, b - 2),
    }
    return out


# -------------------------------------------------------------- triangulation
class PlanarTriangulation:
    """A validated planar triangulation ``P (#V, 2)``, ``F (#F, 3)`` with
    counter-clockwise faces, and its affine element maps.

    Attributes
    ----------
    P : (#V, 2) float64
    F : (#F, 3) int64
    mesh : :class:`igl_hhj.mesh.TriangleMesh` of ``[P, 0]`` (edges, edge/face maps)
    J : (#F, 2, 2) float64, columns ``x_1 - x_0`` and ``x_2 - x_0``
    detJ : (#F,) float64 > 0 (twice the area)
    """

    def __init__(self, P, F):
        P = _as_array(P, "P")
        if P.dtype == object or not (np.issubdtype(P.dtype, np.floating)
                                     or np.issubdtype(P.dtype, np.integer)):
            raise TypeError(f"P must hold real numbers, got dtype {P.dtype}")
        if P.ndim != 2 or P.shape[1] != 2:
            raise ValueError(f"P must have shape (#V, 2) (a planar triangulation), got shape {P.shape}")
        P = np.ascontiguousarray(P, dtype=np.float64)
        V3 = np.concatenate([P, np.zeros((P.shape[0], 1))], axis=1) if P.shape[0] else P
        self.mesh = TriangleMesh(V3, F)
        self.P = self.mesh.V[:, :2].copy()
        self.F = self.mesh.F
        X = self.P[self.F]
        self.J = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]], axis=2)
        self.detJ = self.J[:, 0, 0] * self.J[:, 1, 1] - self.J[:, 0, 1] * self.J[:, 1, 0]
        bad = self.detJ <= 0
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError("F must be oriented counter-clockwise in the plane (positive signed "
                             f"area); first clockwise face {i}: {self.F[i]}")
        if not self.mesh.referenced_vertices.all():
            i = int(np.flatnonzero(~self.mesh.referenced_vertices)[0])
            raise ValueError(f"P has unreferenced vertices; first is vertex {i}")

    @property
    def n_faces(self):
        return self.F.shape[0]

    @property
    def n_vertices(self):
        return self.P.shape[0]

    @cached_property
    def h(self):
        """Maximal edge length ``max_T h_T``."""
        return float(self.mesh.edge_lengths.max())

    def to_physical(self, points):
        """Map reference points ``(n, 2)`` to physical points ``(#F, n, 2)``."""
        pts = np.asarray(points, dtype=np.float64)
        return self.P[self.F[:, 0]][:, None, :] + np.einsum("fij,nj->fni", self.J, pts)

    @classmethod
    def coerce(cls, P, F=None):
        if isinstance(P, cls) and F is None:
            return P
        if F is None:
            raise TypeError("F is required unless P is a PlanarTriangulation")
        return cls(P, F)


# ------------------------------------------------------------------ Lagrange
@lru_cache(maxsize=None)
def _lagrange_reference(p):
    """Nodes (n, 2) in local DOF order and the monomial→nodal coefficient matrix."""
    nodes = [REF_VERTICES[c] for c in range(3)]
    for i in range(3):
        a, b = REF_VERTICES[(i + 1) % 3], REF_VERTICES[(i + 2) % 3]
        for j in range(1, p):
            nodes.append(a + (b - a) * j / p)
    interior = [(a, b) for a in range(1, p) for b in range(1, p) if a + b <= p - 1]
    for a, b in interior:
        nodes.append(np.array([a / p, b / p]))
    nodes = np.array(nodes, dtype=np.float64).reshape(-1, 2)
    Vdm = monomials(nodes, p)["v"]          # (n_nodes, nm), square
    C = np.linalg.inv(Vdm)                  # φ_a = Σ_m C[m, a] mono_m
    nodes.setflags(write=False)
    C.setflags(write=False)
    return nodes, C


class LagrangeSpace:
    """Continuous Lagrange space ``V_h^p`` (p ≥ 1) on a planar triangulation.

    Attributes
    ----------
    tri : PlanarTriangulation
    degree : int
    n_local : int, ``(p+1)(p+2)/2``
    cell_dofs : (#F, n_local) int64 local → global DOF map
    n_dofs : int
    nodes : (n_dofs, 2) float64 physical node coordinates
    """

    def __init__(self, tri, degree):
        self.tri = tri
        p = self.degree = _check_int(degree, "Lagrange degree", 1, MAX_DEGREE)
        self.ref_nodes, self.coef = _lagrange_reference(p)
        self.n_local = self.ref_nodes.shape[0]
        m, F = tri.mesh, tri.F
        nV, nE, nF = tri.n_vertices, m.n_edges, tri.n_faces
        ne, ni = p - 1, (p - 1) * (p - 2) // 2
        cols = [F]
        j = np.arange(ne)
        for i in range(3):
            e = m.face_edges[:, i].astype(np.int64)      # int32 map: nV + e ne in int64
            fwd = m.face_edge_sign[:, i] > 0
            jj = np.where(fwd[:, None], j[None, :], ne - 1 - j[None, :])
            cols.append(nV + e[:, None] * ne + jj)
        cols.append(nV + nE * ne + np.arange(nF)[:, None] * ni + np.arange(ni)[None, :])
        self.cell_dofs = np.ascontiguousarray(np.concatenate(cols, axis=1), dtype=np.int64)
        self.n_dofs = nV + nE * ne + nF * ni
        nodes = np.zeros((self.n_dofs, 2))
        nodes[self.cell_dofs] = tri.to_physical(self.ref_nodes)
        self.nodes = nodes

    def basis(self, points, derivatives=False):
        """Reference basis values ``(n, n_local)``; with ``derivatives`` also
        the reference gradients ``(n, n_local, 2)``."""
        mono = monomials(points, self.degree)
        phi = mono["v"] @ self.coef
        if not derivatives:
            return phi
        grad = np.stack([mono["x"] @ self.coef, mono["y"] @ self.coef], axis=2)
        return phi, grad

    def edge_dofs(self, edge_mask):
        """Global DOFs (vertices and edge nodes) lying on the edges in ``edge_mask (#E,)``."""
        m = self.tri.mesh
        ne = self.degree - 1
        e = np.flatnonzero(edge_mask)
        d = [m.edges[e].ravel(),
             (self.tri.n_vertices + e[:, None] * ne + np.arange(ne)[None, :]).ravel()]
        return np.unique(np.concatenate(d))

    def assemble_matrix(self, local):
        """Assemble ``(#F, n_local, n_local)`` element matrices to a CSR matrix."""
        import scipy.sparse as sp
        cd = self.cell_dofs
        rows = np.broadcast_to(cd[:, :, None], local.shape).ravel()
        cols = np.broadcast_to(cd[:, None, :], local.shape).ravel()
        return sp.coo_matrix((local.ravel(), (rows, cols)),
                             shape=(self.n_dofs, self.n_dofs)).tocsr()

    def assemble_vector(self, local):
        """Assemble ``(#F, n_local)`` element vectors."""
        return np.bincount(self.cell_dofs.ravel(), weights=local.ravel(), minlength=self.n_dofs)

    def mass_matrix(self, quad_degree=None):
        """Euclidean mass matrix ``∫ φ_a φ_b dx``."""
        pts, w = triangle_rule(quad_degree or 2 * self.degree)
        phi = self.basis(pts)
        loc = np.einsum("q,qa,qb->ab", w, phi, phi)
        return self.assemble_matrix(self.tri.detJ[:, None, None] * loc[None])

    def stiffness_matrix(self, quad_degree=None):
        """Euclidean stiffness matrix ``∫ ∇φ_a · ∇φ_b dx``."""
        pts, w = triangle_rule(quad_degree or max(2 * self.degree - 2, 0))
        _, g = self.basis(pts, derivatives=True)
        Jinv = np.linalg.inv(self.tri.J)                       # (F, 2, 2)
        # physical gradient = J^{-T} ∇̂φ
        G = np.einsum("fki,qak->fqai", Jinv, g)
        loc = np.einsum("q,fqai,fqbi->fab", w, G, G) * self.tri.detJ[:, None, None]
        return self.assemble_matrix(loc)

    def evaluate(self, dofs, faces, bary):
        """Evaluate a finite element function at ``(face index, barycentric)`` points."""
        faces, bary = _check_points(self.tri, faces, bary)
        mono = monomials(bary[:, 1:], self.degree)["v"]         # (n, nm)
        phi = np.einsum("nm,ma->na", mono, self.coef)
        return np.einsum("na,na->n", phi, np.asarray(dofs)[self.cell_dofs[faces]])

    def interpolate(self, func):
        """Nodal interpolant of ``func: (N, 2) -> (N,)``."""
        return _call_scalar(func, self.nodes, "function")


def _call_scalar(func, X, name):
    vals = np.asarray(func(X), dtype=np.float64)
    if vals.shape != (X.shape[0],):
        raise ValueError(f"{name} must map (N, 2) points to shape (N,), got {vals.shape}")
    _check_finite_values(vals, X, name)
    return vals


def _check_finite_values(vals, X, name):
    """A user callable's values must be finite (NaN would spread through the solve)."""
    bad = ~np.isfinite(vals)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name} returned NaN or inf; first at point {np.asarray(X)[i].tolist()}: "
                         f"{vals[i]}")


def _check_points(tri, faces, bary):
    faces = _as_array(faces, "faces")
    if not np.issubdtype(faces.dtype, np.integer):
        raise TypeError(f"faces must be integer face indices, got dtype {faces.dtype}")
    faces = faces.reshape(-1).astype(np.int64)
    bary = np.asarray(bary, dtype=np.float64).reshape(-1, 3) if np.size(bary) else np.zeros((0, 3))
    if bary.shape[0] != faces.shape[0]:
        raise ValueError(f"bary must have shape ({faces.shape[0]}, 3), got {np.shape(bary)}")
    if faces.size and (faces.min() < 0 or faces.max() >= tri.n_faces):
        i = int(np.flatnonzero((faces < 0) | (faces >= tri.n_faces))[0])
        raise ValueError(f"face index out of range (#F = {tri.n_faces}); first at point {i}: {faces[i]}")
    return faces, bary


# ------------------------------------------------------------------- Regge
def _call_metric(metric, X):
    G = np.asarray(metric(X), dtype=np.float64)
    if G.shape != (X.shape[0], 2, 2):
        raise ValueError(f"metric must map (N, 2) points to (N, 2, 2) tensors, got shape {G.shape}")
    if not np.isfinite(G).all():
        raise ValueError("metric returned NaN or inf values")
    if not np.allclose(G, np.swapaxes(G, 1, 2), rtol=1e-12, atol=0):
        i = int(np.flatnonzero(np.abs(G[:, 0, 1] - G[:, 1, 0]) > 1e-12 * np.abs(G).max())[0])
        raise ValueError(f"metric is not symmetric; first at point {X[i]}")
    bad = (G[:, 0, 0] <= 0) | (G[:, 0, 0] * G[:, 1, 1] - G[:, 0, 1] * G[:, 1, 0] <= 0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"metric is not positive definite; first at point {X[i]}: {G[i].tolist()}")
    return G


def regge_basis(points, k):
    """Scaled Bernstein basis ``λ_0^a λ_1^b λ_2^c k!/(a! b! c!)`` (``a+b+c = k``) of
    ``P^k(T̂)`` with derivatives up to order 2 (keys as :func:`monomials`).

    Regge coefficients are stored in this basis: it is evaluated without
    cancellation (all terms positive) and, with equilibrated rows, the
    reference moment matrix at k = 3 has a small condition number; plain
    monomials (condition ≈ 2.5e5) leave a round-off floor of ≈ 3e-8 in the
    k = 3 curvature error at l = 6."""
    from math import factorial
    pts = np.asarray(points, dtype=np.float64)
    L = [1.0 - pts[:, 0] - pts[:, 1], pts[:, 0], pts[:, 1]]
    abc = [(a, b, k - a - b) for a in range(k, -1, -1) for b in range(k - a, -1, -1)]

    def pw(x, e):
        return x ** e if e >= 0 else np.zeros_like(x)

    def term(ea, eb, ec):
        return pw(L[0], ea) * pw(L[1], eb) * pw(L[2], ec)

    out = {key: [] for key in ("v", "x", "y", "xx", "xy", "yy")}
    for a, b, c in abc:
        m = factorial(k) / (factorial(a) * factorial(b) * factorial(c))
        out["v"].append(m * term(a, b, c))
        out["x"].append(m * (-a * term(a - 1, b, c) + b * term(a, b - 1, c)))
        out["y"].append(m * (-a * term(a - 1, b, c) + c * term(a, b, c - 1)))
        out["xx"].append(m * (a * (a - 1) * term(a - 2, b, c) - 2 * a * b * term(a - 1, b - 1, c)
                              + b * (b - 1) * term(a, b - 2, c)))
        out["xy"].append(m * (a * (a - 1) * term(a - 2, b, c) - a * c * term(a - 1, b, c - 1)
                              - a * b * term(a - 1, b - 1, c) + b * c * term(a, b - 1, c - 1)))
        out["yy"].append(m * (a * (a - 1) * term(a - 2, b, c) - 2 * a * c * term(a - 1, b, c - 1)
                              + c * (c - 1) * term(a, b, c - 2)))
    return {key: np.stack(val, axis=1) for key, val in out.items()}


@lru_cache(maxsize=None)
def _regge_reference(k, quad_degree):
    """Quadrature data and the inverse moment matrix of the reference element.

    Unknowns: coefficients of ``ĝ_11, ĝ_12, ĝ_22`` in the Bernstein basis of
    degree ``k`` (component-major).  Rows: edge moments against Legendre polynomials
    ``q_j(s)``, ``j ≤ k``, then cell moments against ``e_c ⊗ ξ^a η^b``,
    ``a + b ≤ k - 1``.
    """
    nm = (k + 1) * (k + 2) // 2
    s, ws = gauss_legendre(quad_degree)
    q = np.stack([np.polynomial.legendre.Legendre.basis(j)(2 * s - 1) for j in range(k + 1)], axis=1)
    # edge points (3, ns, 2)
    epts = REF_VERTICES[[1, 2, 0]][:, None, :] + s[None, :, None] * REF_EDGE_TANGENTS[:, None, :]
    tpts, wt = triangle_rule(quad_degree)
    nmc = k * (k + 1) // 2
    rows = []
    for i in range(3):
        t = REF_EDGE_TANGENTS[i]
        mv = regge_basis(epts[i], k)["v"]               # (ns, nm)
        tt = np.array([t[0] * t[0], 2 * t[0] * t[1], t[1] * t[1]])
        for j in range(k + 1):
            r = np.einsum("s,s,sm->m", ws, q[:, j], mv)
            rows.append(np.concatenate([tt[c] * r for c in range(3)]))
    if nmc:
        mt = regge_basis(tpts, k)["v"]
        mc = monomials(tpts, k - 1)["v"][:, :nmc]
        for c in range(3):
            for j in range(nmc):
                r = np.zeros(3 * nm)
                r[c * nm:(c + 1) * nm] = np.einsum("q,q,qm->m", wt, mc[:, j], mt)
                rows.append(r)
    A = np.array(rows)
    D = 1.0 / np.linalg.norm(A, axis=1)                                  # row equilibration
    Ainv = np.linalg.inv(D[:, None] * A) * D[None, :]
    return dict(s=s, ws=ws, q=q, epts=epts, tpts=tpts, wt=wt,
                mc=(monomials(tpts, k - 1)["v"] if nmc else np.zeros((len(wt), 0))),
                Ainv=Ainv, nm=nm, cond=np.linalg.cond(D[:, None] * A))


class ReggeMetric:
    """A Regge metric ``g_h ∈ Reg_h^k`` on a planar triangulation.

    Attributes
    ----------
    tri : PlanarTriangulation
    degree : int k
    coef : (#F, 3, nm) float64, coefficients of the pulled-back components
        ``ĝ_11, ĝ_12, ĝ_22`` on each element in the Bernstein basis
        :func:`regge_basis` of ``P^k(T̂)``
    metric : callable or None, the metric it interpolates (used as default
        Neumann data by :func:`lift_gauss_curvature`)
    """

    def __init__(self, tri, degree, coef, metric=None):
        self.tri = tri
        self.degree = degree
        self.coef = coef
        self.metric = metric

    def reference_values(self, points, derivatives=0):
        """Pulled-back metric on every element at reference ``points (n, 2)``.

        Returns
        -------
        g : (#F, n, 2, 2)
        dg : (#F, n, 2, 2, 2) with ``dg[..., a, i, j] = ∂_a ĝ_ij`` (if derivatives ≥ 1)
        ddg : (#F, n, 2, 2, 2, 2) with ``ddg[..., a, b, i, j] = ∂_a ∂_b ĝ_ij`` (if ≥ 2)
        """
        mono = regge_basis(points, self.degree)

        def sym(key):
            c = np.einsum("fcm,nm->fnc", self.coef, mono[key])
            return np.stack([np.stack([c[..., 0], c[..., 1]], -1),
                             np.stack([c[..., 1], c[..., 2]], -1)], -2)
        g = sym("v")
        if derivatives == 0:
            return g
        gx, gy = sym("x"), sym("y")
        dg = np.stack([gx, gy], axis=2)
        if derivatives == 1:
            return g, dg
        gxx, gxy, gyy = sym("xx"), sym("xy"), sym("yy")
        ddg = np.stack([np.stack([gxx, gxy], 2), np.stack([gxy, gyy], 2)], 2)
        return g, dg, ddg

    def __call__(self, faces, bary):
        """Physical metric tensors ``(n, 2, 2)`` at ``(face index, barycentric)`` points."""
        faces, bary = _check_points(self.tri, faces, bary)
        mono = regge_basis(bary[:, 1:], self.degree)["v"]
        c = np.einsum("ncm,nm->nc", self.coef[faces], mono)
        gh = np.stack([np.stack([c[:, 0], c[:, 1]], -1), np.stack([c[:, 1], c[:, 2]], -1)], -2)
        Jinv = np.linalg.inv(self.tri.J[faces])
        return np.einsum("nki,nkl,nlj->nij", Jinv, gh, Jinv)

    def tt_jump(self, n_points=5):
        """Largest relative jump of ``g_h(t, t)`` across interior edges (0 up to round-off
        for a Regge function)."""
        m = self.tri.mesh
        inner = np.flatnonzero(m.edge_face_count == 2)
        if inner.size == 0:
            return 0.0
        s = np.linspace(0, 1, n_points)
        vals = []
        for side in range(2):
            f = m.edge_faces[inner, side]
            i = m.edge_local_index[inner, side]
            sign = m.face_edge_sign[f, i]
            ss = np.where(sign[:, None] > 0, s[None, :], 1 - s[None, :])    # common parameter
            a = REF_VERTICES[(i + 1) % 3]
            t = REF_EDGE_TANGENTS[i]
            pts = a[:, None, :] + ss[..., None] * t[:, None, :]
            mono = regge_basis(pts.reshape(-1, 2), self.degree)["v"].reshape(len(f), n_points, -1)
            c = np.einsum("ecm,enm->enc", self.coef[f], mono)
            tt = c[..., 0] * t[:, None, 0] ** 2 + 2 * c[..., 1] * (t[:, 0] * t[:, 1])[:, None] \
                + c[..., 2] * t[:, None, 1] ** 2
            L2 = (m.edge_lengths[f, i] ** 2)[:, None]
            vals.append(tt / L2)          # g(τ, τ) with the Euclidean unit tangent
        return float(np.max(np.abs(vals[0] - vals[1])) / max(np.max(np.abs(vals[0])), 1e-300))


def interpolate(P, F, metric, k, quad_degree=None):
    """Canonical Regge interpolant ``g_h = T_h^{Reg,k} ḡ`` (Gopalakrishnan et al. 2024, eq. 3.1).

    Solves, element by element, the moment equations

    ``∫_E (g_h)(t, t) q ds = ∫_E ḡ(t, t) q ds`` for all ``q ∈ P^k(E)``, ``E ⊂ ∂T``, and
    ``∫_T g_h : ρ dx = ∫_T ḡ : ρ dx`` for all ``ρ ∈ P^{k-1}(T; S)``,

    with Gauss rules exact to degree ``quad_degree`` (default ``2k + 16``, i.e.
    exact moments for polynomial metrics of degree ≤ k + 16).  The local
    ``3(k+1)(k+2)/2`` systems share one reference matrix (the conditions are
    invariant under the affine pull-back ``ĝ = Jᵀ ḡ J``); to keep round-off
    out of the curvature (which amplifies metric errors by ~1/h²) the moments
    of ``ĝ - ĝ(centroid)`` are solved for and the constant added back.

    Parameters
    ----------
    P : (#V, 2) array_like, vertex positions of a planar triangulation
        (or a :class:`PlanarTriangulation`, then ``F`` may be ``None``)
    F : (#F, 3) array_like of int, counter-clockwise triangles
    metric : callable ``(N, 2) -> (N, 2, 2)``, a symmetric positive definite metric
    k : int, Regge degree (0, 1, 2, 3, ...)
    quad_degree : int, optional

    Returns
    -------
    ReggeMetric
    """
    tri = PlanarTriangulation.coerce(P, F)
    k = _check_int(k, "Regge degree k", 0, MAX_DEGREE)
    if not callable(metric):
        raise TypeError(f"metric must be a callable (N, 2) -> (N, 2, 2), got {type(metric).__name__}")
    qd = 2 * k + 16 if quad_degree is None else _check_int(
        quad_degree, "quad_degree", 2 * k, MAX_QUAD_DEGREE,
        f" = 2k (the moment equations need exact products of degree-{k} polynomials)")
    ref = _regge_reference(k, qd)
    nF = tri.n_faces
    J = tri.J
    x0 = tri.P[tri.F[:, 0]]
    # Round-off control: curvature sees relative metric errors amplified by
    # ~1/h², so the moment solve works on the deviation ĝ - ĝ(centroid) (of size
    # O(h)) and adds the constant ĝ(centroid), which every Reg^k reproduces
    # exactly, back to all Bernstein coefficients.
    G0 = _call_metric(metric, x0 + J @ np.array([1.0, 1.0]) / 3.0)
    G0h = np.einsum("fki,fkl,flj->fij", J, G0, J)
    # edge moments ∫_E (ĝ - ĝ_0)(t̂, t̂) q_j
    ne = ref["s"].size
    X = x0[:, None, None, :] + np.einsum("fij,enj->feni", J, ref["epts"])       # (F, 3, ns, 2)
    G = _call_metric(metric, X.reshape(-1, 2)).reshape(nF, 3, ne, 2, 2)
    Gh = np.einsum("fki,fenkl,flj->fenij", J, G, J) - G0h[:, None, None]
    gtt = np.einsum("ei,fenij,ej->fen", REF_EDGE_TANGENTS, Gh, REF_EDGE_TANGENTS)
    b_edge = np.einsum("n,nj,fen->fej", ref["ws"], ref["q"], gtt).reshape(nF, -1)
    parts = [b_edge]
    if k >= 1:
        tp = tri.to_physical(ref["tpts"])                                         # (F, nq, 2)
        Gt = _call_metric(metric, tp.reshape(-1, 2)).reshape(nF, -1, 2, 2)
        Gh = np.einsum("fki,fnkl,flj->fnij", J, Gt, J) - G0h[:, None]             # pulled back
        comps = np.stack([Gh[..., 0, 0], Gh[..., 0, 1], Gh[..., 1, 1]], axis=1)   # (F, 3, nq)
        nmc = k * (k + 1) // 2
        b_cell = np.einsum("q,qj,fcq->fcj", ref["wt"], ref["mc"][:, :nmc], comps).reshape(nF, -1)
        parts.append(b_cell)
    b = np.concatenate(parts, axis=1)
    coef = (b @ ref["Ainv"].T).reshape(nF, 3, ref["nm"])
    coef += np.stack([G0h[:, 0, 0], G0h[:, 0, 1], G0h[:, 1, 1]], axis=1)[:, :, None]
    return ReggeMetric(tri, k, coef, metric)
