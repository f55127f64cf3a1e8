"""Walker's HHJ surface Hessian of a scalar function on a curved Lagrange surface
(Walker 2023, §4.3–§4.5, eq. 4.7, 4.9 and Theorem 4.1).

Given the nodal values of ŵ_h ∈ W_h^m on Γ^m of order m (for a function w on Γ:
Walker's interpolant 𝓘_h^{1,m}(w ∘ F_T), :func:`~igl_hhj.curved.modified_interpolant`,
Remark 4.2), the HHJ projection σ̂_h ∈ V_h^m (degree r, default m − 1) of
∇_Γ∇_Γ w solves

    a^m(σ̂_h, φ̂_h) = -b_h^m(φ̂_h, ŵ_h) + (φ̂_h^nn, n̂ · ξ̃)_{Σ_c^m}   ∀ φ̂_h ∈ V_h^m   (eq. 4.9),

i.e. ``A s = -B w + g`` with A, B of :class:`~igl_hhj.curved.CurvedHHJ`.
Theorem 4.1: for w ∈ H^{r+3}(Γ) and m ≥ r + 1,
``‖σ − σ̂_h ∘ (Ψ^m)⁻¹‖ = O(h^{r+1})``.  The shape operator
(:func:`~igl_hhj.curved.shape_operator`) is the special case w = id^k.
"""
from __future__ import annotations

import numpy as np

from .hhj import CurvedHHJ
from .reference import lagrange_basis
from .surface import LagrangeSurface

__all__ = ["surface_hessian", "HessianField"]


class HessianField:
    """The discrete surface Hessian σ̂_h ∈ V_h^m of k functions.

    ``field(faces, bary) -> (n, k, 3, 3)`` (``(n, 3, 3)`` for a single function):
    the Piola tensors σ̂_h = J Σ̂ Jᵀ / det G (eq. 3.14) at the points with
    barycentric coordinates ``bary`` (n, 3) of faces ``faces`` (n,); symmetric
    and tangential to :meth:`LagrangeSurface.normals`.

    Attributes
    ----------
    space : CurvedHHJ
    coefficients : (n_dofs, k) HHJ DOFs
    """

    def __init__(self, space, coefficients, single):
        self.space = space
        self.surface = space.surface
        self.coefficients = coefficients
        self.single = single

    def __call__(self, faces, bary):
        faces, bary = self.surface._check_points(faces, bary)
        sig = self.space.tensors(self.coefficients, faces, bary)
        sig = 0.5 * (sig + np.swapaxes(sig, -1, -2))
        return sig[:, 0] if self.single else sig


def _nodal(surface, values, name, tail):
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a numeric array: {exc}") from None
    if arr.shape[:1] != (surface.n_nodes,) or arr.shape[1:] != tail:
        raise ValueError(f"{name} must have shape {(surface.n_nodes,) + tail} (one row per node), got {arr.shape}")
    return arr


def conormal_load(space, edges, w=None, gradient=None):
    """Boundary load ``g = (φ̂^nn, n̂ · ξ)_E`` of eq. 4.9 on boundary edges ``edges``.

    Parameters
    ----------
    space : CurvedHHJ
    edges : (#e,) int boundary edge ids.
    w : (#N, k), optional
        Nodal values of ŵ_h: ξ = ∇_{Γ^m} ŵ_h, the element's own gradient, whose
        load cancels B's one-sided boundary term (the "plain assembly").
    gradient : (#N, 3, k), optional
        Nodal data of ξ̃ = ∇_Γ w (clamped edges, Σ_c), interpolated along the
        edge by the degree-m Lagrange basis (Walker's I_h^m ξ̃, Remark 4.2).

    Returns
    -------
    (n_dofs, k) float64.
    """
    surf = space.surface
    k = (w if gradient is None else gradient).shape[-1]
    Bm = lagrange_basis(space.m)

    def n_dot_xi(j, fj, exi, ge, n):
        if gradient is None:
            grad = np.einsum("fgkd,fgde,gae,fac->fgkc", ge.J, ge.Ginv, ge.dN, w[surf.elements[fj]])
        else:
            grad = np.einsum("ga,fakc->fgkc", Bm.values(exi), gradient[surf.elements[fj]])
        return np.einsum("fgk,fgkc->fgc", n, grad)                    # n̂ · ξ   (f, g, k)
    return space.boundary_edge_load(edges, k, n_dot_xi)


def surface_hessian(surface, w, *, boundary_gradient=None, degree=None, solver="auto", condense=True):
    """HHJ projection σ̂_h of the surface Hessian ∇_Γ∇_Γ w on a curved surface Γ^m
    (Walker eq. 4.9, Theorem 4.1).

    Parameters
    ----------
    surface : LagrangeSurface (order m)
    w : (#N,) or (#N, k) array_like
        Nodal values of ŵ_h ∈ W_h^m.  For a function given on Γ use
        :func:`~igl_hhj.curved.modified_interpolant` (Walker's 𝓘_h^{1,m} of
        w ∘ F_T, the rule that placed the nodes): Remark 4.2's interpolant
        must keep the Fortin property (4.6) at m = r + 1; the plain nodal
        values w(Ψ^m(x_a)) lose one order (measured EOC 2.0 instead of 3.0
        at m = 3 on the torus).
    boundary_gradient : (#N, 3) or (#N, k, 3) array_like, optional
        ξ̃ = ∇_Γ w at (at least) the boundary nodes: every boundary edge is
        clamped (Σ_c of eq. 4.9) with ξ interpolated by I_h^m.  Without it the
        plain assembly (the discrete gradient stands in; the rate drops near the
        boundary, as for flat meshes).  Simply supported data (ρ̂_h of eq. 4.10)
        is implemented only for the shape operator (:func:`shape_operator`).
    degree : int, optional
        HHJ degree r (default m − 1; Theorem 4.1 needs m ≥ r + 1).
    solver : {"auto", "direct", "cg"}
        Passed to :func:`igl_hhj.hhj.solve_spd`.
    condense : bool
        Eliminate the face-interior DOFs first (:meth:`CurvedHHJ.solve`).

    Returns
    -------
    HessianField
        ``field(faces, bary)`` → (n, 3, 3), or (n, k, 3, 3) for ``w`` of shape (#N, k).

    Raises
    ------
    TypeError
        ``surface`` not a LagrangeSurface, non-numeric data.
    ValueError
        Wrong shapes, NaN/inf values, ``degree`` with m < r + 1 or outside 0..2.

    Examples
    --------
    >>> import numpy as np
    >>> from igl_hhj.curved import LagrangeSurface, surface_hessian
    >>> from igl_hhj.surfaces import Sphere, icosphere
    >>> V, F = icosphere(2)
    >>> surf = LagrangeSurface.from_projection(V, F, 2, Sphere().project)
    >>> H = surface_hessian(surf, surf.nodes[:, 2])        # z: hess_Γ z = -z P on the unit sphere
    >>> H(np.arange(3), np.full((3, 3), 1 / 3)).shape
    (3, 3, 3)
    """
    if not isinstance(surface, LagrangeSurface):
        raise TypeError(f"surface must be a LagrangeSurface, got {type(surface).__name__}")
    W = np.asarray(w, dtype=np.float64) if not isinstance(w, np.ndarray) else w.astype(np.float64)
    single = W.ndim == 1
    if single:
        W = W[:, None]
    if W.ndim != 2:
        raise ValueError(f"w must have shape (#N,) or (#N, k), got {np.shape(w)}")
    W = _nodal(surface, W, "w", (W.shape[1],))
    if not np.isfinite(W).all():
        raise ValueError(f"w has NaN or inf at node {int(np.flatnonzero(~np.isfinite(W).all(1))[0])}")
    if degree is not None and int(degree) > surface.order - 1:
        raise ValueError(f"HHJ degree r = {int(degree)} needs geometry order m >= r + 1 (Theorem 4.1), "
                         f"the surface has m = {surface.order}")
    space = CurvedHHJ(surface, degree)
    A, B = space.matrices
    rhs = -(B @ W)
    bnd = np.flatnonzero(surface.mesh.boundary_edges)
    if bnd.size:
        if boundary_gradient is None:
            rhs += conormal_load(space, bnd, w=W)
        else:
            G = np.asarray(boundary_gradient, dtype=np.float64)
            G = G[:, None] if single and G.ndim == 2 else G
            G = _nodal(surface, G, "boundary_gradient", (W.shape[1], 3))
            need = surface.boundary_nodes
            if not np.isfinite(G[need]).all():
                raise ValueError("boundary_gradient is NaN or inf at a boundary node")
            G = np.where(np.isfinite(G), G, 0.0)             # off the boundary: unused (basis is 0 there)
            rhs += conormal_load(space, bnd, gradient=np.swapaxes(G, 1, 2))
    s = space.solve(rhs, solver=solver, condense=condense)
    return HessianField(space, s, single)
