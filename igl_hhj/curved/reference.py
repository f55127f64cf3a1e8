"""The reference triangle: Lagrange bases of degree 1–3 in gmsh node order and
quadrature rules.

Reference triangle ``T̂ = {(ξ1, ξ2): ξ1, ξ2 ≥ 0, ξ1 + ξ2 ≤ 1}`` with corners
0 = (0, 0), 1 = (1, 0), 2 = (0, 1); barycentric coordinates
``(λ0, λ1, λ2) = (1 - ξ1 - ξ2, ξ1, ξ2)``.  Nodes follow gmsh's triangle3/6/10
order: the corners, then the nodes of edge 0→1, 1→2, 2→0 (each in that
direction), then the interior node (order 3: the centroid).

Local edge ``j`` is the edge opposite corner ``j`` (libigl's convention), from
corner ``j+1`` to corner ``j+2``.
"""
from __future__ import annotations

import functools

import numpy as np

__all__ = ["lagrange_nodes", "LagrangeBasis", "lagrange_basis", "triangle_quadrature",
           "line_quadrature", "EDGE_TANGENTS", "EDGE_OUTWARD", "CORNERS", "n_nodes",
           "edge_node_slots"]

CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
# reference edge vectors t̂_j = X̂_{j+2} - X̂_{j+1} (not normalised) and the
# outward normals t̂_j^⊥ = (t̂_y, -t̂_x) of the counter-clockwise triangle
EDGE_TANGENTS = np.array([CORNERS[(j + 2) % 3] - CORNERS[(j + 1) % 3] for j in range(3)])
EDGE_OUTWARD = np.stack([EDGE_TANGENTS[:, 1], -EDGE_TANGENTS[:, 0]], axis=1)


def n_nodes(order):
    """(m+1)(m+2)/2 nodes of a degree-m triangle."""
    return (order + 1) * (order + 2) // 2


def lagrange_nodes(order):
    """(n, 2) reference coordinates of the degree-``order`` nodes, gmsh order (order 0: centroid)."""
    if order == 0:
        return np.array([[1.0 / 3.0, 1.0 / 3.0]])
    pts = [c for c in CORNERS]
    for a, b in ((0, 1), (1, 2), (2, 0)):
        for k in range(1, order):
            t = k / order
            pts.append((1 - t) * CORNERS[a] + t * CORNERS[b])
    if order == 3:
        pts.append(np.array([1.0 / 3.0, 1.0 / 3.0]))
    elif order == 4:                     # gmsh triangle15: the inner triangle's corners
        pts += [np.array([0.25, 0.25]), np.array([0.5, 0.25]), np.array([0.25, 0.5])]
    elif order > 4:
        raise ValueError(f"orders up to 4 are supported, got {order}")
    return np.array(pts)


def edge_node_slots(order):
    """Local node indices of the interior nodes of local edge j (opposite corner j),
    listed from corner j+1 to corner j+2: list of 3 lists of length order-1."""
    # gmsh edges: e01 (nodes 3..), e12, e20; local edge j = corners (j+1, j+2)
    gm = {(0, 1): 0, (1, 2): 1, (2, 0): 2}
    out = []
    for j in range(3):
        a, b = (j + 1) % 3, (j + 2) % 3
        g = gm[(a, b)]
        out.append([3 + g * (order - 1) + k for k in range(order - 1)])
    return out


def _monomial_exponents(order):
    return [(i, d - i) for d in range(order + 1) for i in range(d, -1, -1)]


class LagrangeBasis:
    """Nodal Lagrange basis of degree ``order`` on T̂ (nodes :func:`lagrange_nodes`).

    Methods return, for reference points ``xi`` (n, 2): values (n, nb), first
    derivatives (n, nb, 2), second derivatives (n, nb, 2, 2)."""

    def __init__(self, order):
        self.order = int(order)
        self.nodes = lagrange_nodes(self.order)
        self.exps = _monomial_exponents(self.order)
        V = self._mono(self.nodes, (0, 0))
        self.C = np.linalg.inv(V)          # N = mono @ C
        self.n = len(self.nodes)

    def _mono(self, xi, d):
        x, y = xi[:, 0], xi[:, 1]
        cols = []
        for (a, b) in self.exps:
            ca, cb = a, b
            fa = 1.0
            for k in range(d[0]):
                fa *= (a - k)
            for k in range(d[1]):
                fa *= (b - k)
            ea, eb = a - d[0], b - d[1]
            if fa == 0 or ea < 0 or eb < 0:
                cols.append(np.zeros_like(x))
            else:
                cols.append(fa * x ** ea * y ** eb)
            del ca, cb
        return np.stack(cols, axis=1)

    def values(self, xi):
        return self._mono(np.asarray(xi, float), (0, 0)) @ self.C

    def gradients(self, xi):
        xi = np.asarray(xi, float)
        return np.stack([self._mono(xi, (1, 0)) @ self.C, self._mono(xi, (0, 1)) @ self.C], axis=2)

    def hessians(self, xi):
        xi = np.asarray(xi, float)
        hxx = self._mono(xi, (2, 0)) @ self.C
        hxy = self._mono(xi, (1, 1)) @ self.C
        hyy = self._mono(xi, (0, 2)) @ self.C
        return np.stack([np.stack([hxx, hxy], -1), np.stack([hxy, hyy], -1)], -2)


@functools.cache
def lagrange_basis(order):
    """Cached :class:`LagrangeBasis` of degree ``order``."""
    return LagrangeBasis(order)


@functools.cache
def triangle_quadrature(degree):
    """Collapsed Gauss–Jacobi (Stroud conical product) rule on T̂, exact for
    polynomials of total degree ``degree``.

    Returns
    -------
    xi : (n, 2) points, w : (n,) weights summing to |T̂| = 1/2.
    """
    from scipy.special import roots_jacobi, roots_legendre
    n = max(1, int(np.ceil((degree + 1) / 2)))
    tj, wj = roots_jacobi(n, 1.0, 0.0)      # weight (1 - t) on [-1, 1]
    tl, wl = roots_legendre(n)
    u = 0.5 * (1 + tj)
    v = 0.5 * (1 + tl)
    U, Vv = np.meshgrid(u, v, indexing="ij")
    W = np.outer(wj / 4.0, wl / 2.0)
    xi = np.stack([U.ravel(), (Vv * (1 - U)).ravel()], axis=1)
    # (ξ1, ξ2) = (u, v(1-u)) covers T̂; Jacobian (1-u) is in the Jacobi weight
    return xi, W.ravel()


@functools.cache
def line_quadrature(n):
    """Gauss–Legendre on [0, 1]: points (n,), weights (n,) (exact to degree 2n-1)."""
    from scipy.special import roots_legendre
    t, w = roots_legendre(int(n))
    return 0.5 * (1 + t), 0.5 * w
