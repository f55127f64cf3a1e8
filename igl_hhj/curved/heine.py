"""Heine's L2-projected Weingarten map on curved surfaces, Lagrange degree γ
(Heine 2006, Def. 3.1 and 3.2).

With W_h the continuous Lagrange space of degree γ on Γ^m (parametric: basis
N_a ∘ X⁻¹ on every curved triangle) and ν_h the elementwise normal of Γ^m:

    (Y_h, ψ) = (∇_Γh id, ∇_Γh ψ)                                   (3.1)
    (Π_h^j, ψ) = -(ν_h^j, ∇_Γh · ψ) + (ν_h^j, Y_h · ψ)               (3.2)

for all ψ ∈ W_h (vector-valued for 3.2), consistent mass matrix on the left;
the sign of the last term is that of :func:`igl_hhj.baselines.heine_weingarten_map`
(whose docstring explains it).  For γ = m = 1 this is that function exactly.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..solvers import solve_spd
from .field import CurvedField
from .reference import edge_node_slots, lagrange_basis, triangle_quadrature
from .surface import ElementGeometry, LagrangeSurface

__all__ = ["LagrangeSpace", "heine_weingarten"]


class LagrangeSpace:
    """Continuous Lagrange space of degree γ ∈ {1, 2, 3, 4} on a LagrangeSurface.

    ``elements`` (#F, (γ+1)(γ+2)/2): DOFs per face in gmsh order (vertices as
    the surface's corner nodes, then γ − 1 per unique edge, then (γ−1)(γ−2)/2 per face)."""

    def __init__(self, surface, degree):
        if degree not in (1, 2, 3, 4):
            raise ValueError(f"Lagrange degree must be 1, 2, 3 or 4, got {degree!r}")
        self.surface, self.degree = surface, int(degree)
        mesh = surface.mesh
        nV, nE, nF = surface.n_nodes, mesh.n_edges, mesh.n_faces   # corner DOFs = corner node ids
        g = self.degree
        nb = (g + 1) * (g + 2) // 2
        el = np.empty((nF, nb), dtype=np.int64)
        el[:, :3] = mesh.F
        slots = edge_node_slots(g)
        for j in range(3):                     # 3 local edges, vectorised over faces
            e = mesh.face_edges[:, j].astype(np.int64)   # int32 map: the node ids in int64
            fw = mesh.edges[e, 0] == mesh.F[:, (j + 1) % 3]
            ids = nV + e[:, None] * (g - 1) + np.arange(g - 1)[None]
            el[:, slots[j]] = np.where(fw[:, None], ids, ids[:, ::-1])
        n = nV + nE * (g - 1)
        ni = (g - 1) * (g - 2) // 2                  # face-interior DOFs
        if ni:
            el[:, 3 + 3 * (g - 1):] = n + ni * np.arange(nF)[:, None] + np.arange(ni)[None]
            n += ni * nF
        used = np.zeros(n, dtype=bool)
        used[el.ravel()] = True
        self.elements, self.n_dofs, self.used = el, n, used

    def evaluate(self, coeffs, faces, bary):
        """Values Σ_a N_a(ξ) coeffs[a] at points: (n, ...) ."""
        N = lagrange_basis(self.degree).values(np.asarray(bary, float)[:, 1:])
        return np.einsum("na,na...->n...", N, np.asarray(coeffs)[self.elements[np.asarray(faces)]])


def heine_weingarten(surface, degree=None, quad_degree=None):
    """Heine's discrete Weingarten map Π_h in Lagrange degree γ (default: the surface's order).

    Parameters
    ----------
    surface : LagrangeSurface (order m)
    degree : {1, 2, 3, 4}, optional, γ.

    Returns
    -------
    CurvedField (kind "lagrange"): ``field(faces, bary)`` is P sym(Π_h) P;
    ``field.coefficients`` (#DOF, 3, 3) the nodal Π_h (``Pi[a, j, k] ≈ ∂_k ν_j``),
    ``field.raw`` dict with ``Y`` (#DOF, 3) the curvature vector and ``nu`` (#DOF, 3)
    the normalised L2-projected normal.  Unused DOF rows are NaN.

    Notes
    -----
    Heine: degree 1 does not converge; degree γ ≥ 2 converges (his Tables 5.1–5.4:
    EOC ≈ 1.1–2.4 for γ = 2).
    """
    if not isinstance(surface, LagrangeSurface):
        raise TypeError(f"surface must be a LagrangeSurface, got {type(surface).__name__}")
    g = surface.order if degree is None else degree
    space = LagrangeSpace(surface, g)
    qd = quad_degree if quad_degree is not None else 2 * max(g, surface.order) + 2
    xi, w = triangle_quadrature(qd)
    N = lagrange_basis(g).values(xi)                  # (q, nb)
    dN = lagrange_basis(g).gradients(xi)
    X = surface.nodes[surface.elements]
    geo = ElementGeometry(X, xi, surface.order)
    W = w[None] * geo.sqrt_detG                       # (f, q)
    grad = np.einsum("fqkd,fqde,qae->fqak", geo.J, geo.Ginv, dN)   # ∇_Γ N_a (f, q, nb, 3)
    el = space.elements
    nF, nb = el.shape
    Mloc = np.einsum("fq,qa,qb->fab", W, N, N)
    rows = np.broadcast_to(el[:, :, None], Mloc.shape).ravel()
    cols = np.broadcast_to(el[:, None, :], Mloc.shape).ravel()
    M = sp.coo_matrix((Mloc.ravel(), (rows, cols)), shape=(space.n_dofs,) * 2).tocsr()
    used = space.used
    Mu = M[used][:, used]

    def assemble(loc):                                 # (f, nb, c) → (n_dofs, c)
        out = np.zeros((space.n_dofs, loc.shape[2]))
        np.add.at(out, el.ravel(), loc.reshape(nF * nb, -1))
        return out

    def solve(R):
        Xs = np.full(R.shape, np.nan)
        Xs[used] = solve_spd(Mu, R[used], method="cg", rtol=1e-12)
        return Xs
    RY = assemble(np.einsum("fq,fqak->fak", W, grad))
    Y = solve(RY)
    Yq = np.einsum("qa,fak->fqk", N, np.nan_to_num(Y)[el])          # Y_h at the points
    term = -grad + Yq[:, :, None, :] * N[None, :, :, None]           # (f, q, a, k)
    RP = assemble(np.einsum("fq,fqj,fqak->fajk", W, geo.nu, term).reshape(nF, nb, 9))
    Rn = assemble(np.einsum("fq,fqj,qa->faj", W, geo.nu, N))
    sol = solve(np.concatenate([RP, Rn], axis=1))
    Pi = sol[:, :9].reshape(-1, 3, 3)
    nu = sol[:, 9:]
    with np.errstate(invalid="ignore", divide="ignore"):
        nu = nu / np.linalg.norm(nu, axis=1, keepdims=True)
    return CurvedField(space, Pi, kind="lagrange", raw={"Y": Y, "nu": nu})
