"""Walker's HHJ shape operator on curved Lagrange surfaces (Walker 2023, §5, eq. 5.11–5.19).

For k = 1, 2, 3 the HHJ projection σ_h^k ∈ V_h^m (degree r = m − 1) of the
surface Hessian of the coordinate function id^k ∈ W_h^m solves

    A s^k = -B X^k + g^k - A_fs ρ^k      (eq. 5.14 closed, 5.19 with boundary),

and S_h = -Σ_k ν̂^k σ_h^k (eq. 5.12) with ν̂ the normal of Γ^m, pointwise.
Converges like O(h^{r+1}) = O(h^m) in L2 (Theorems 5.2, 5.3).
"""
from __future__ import annotations

import numpy as np

from ..boundary import simply_supported_mask
from .field import CurvedField
from .hhj import CurvedHHJ
from .surface import LagrangeSurface

__all__ = ["shape_operator"]


def _per_node(surface, values, name, tail):
    arr = np.asarray(values, dtype=np.float64)
    if arr.shape != (surface.n_nodes,) + tail:
        raise ValueError(f"{name} must have shape {(surface.n_nodes,) + tail} (one row per node), got {arr.shape}")
    return arr


def shape_operator(surface, *, boundary_normals=None, boundary_shape_operator=None,
                   simply_supported=None, degree=None, solver="auto", condense=True):
    """HHJ shape operator S_h of a curved surface, as a :class:`CurvedField`.

    Parameters
    ----------
    surface : LagrangeSurface (order m)
    boundary_normals : (#N, 3) array_like, optional
        True unit normals at (at least) the boundary nodes; boundary edges not
        simply supported become clamped (Σ_c of eq. 5.19) with ν̃ = I_h^m ν
        (interpolated along the curved edge by the degree-m Lagrange basis).
    boundary_shape_operator : (#N, 3, 3) array_like, optional
        True shape operator at (at least) the boundary nodes; boundary edges
        become simply supported (Σ_s): their edge DOFs are fixed to the nodal
        values of ``-ν̂^k nᵀ (I_h^m S̃) n`` (eq. 5.18 by nodal interpolation of
        the nn-trace, also O(h^{r+1})).
    simply_supported : (#N,) bool, optional
        With both data arrays: boundary edges whose two end corners are flagged
        are simply supported, the others clamped (as the flat API).
    degree : int, optional
        HHJ degree r (default m − 1, Walker's choice m = r + 1).
    solver : {"auto", "direct", "cg"}
        Passed to :func:`igl_hhj.hhj.solve_spd` (Jacobi-PCG for "cg"; "auto":
        direct up to 50 000 unknowns, PCG above).  A^m's condition number grows
        with m (measured 5–23× the m = 1 value with this basis), but the
        condensed matrix (``condense=True``) stays within 2.5× of the m = 1
        condition number (measured on Walker's four surfaces), so PCG converges quickly.
    condense : bool
        Eliminate the face-interior HHJ DOFs before the solve (static
        condensation, :meth:`CurvedHHJ.solve`; same solution, fewer unknowns).

    Returns
    -------
    CurvedField
        ``field(faces, bary) -> (n, 3, 3)`` symmetric, tangential to the
        surface normals; ``field.coefficients`` (#DOF, 3) holds s^k.

    Notes
    -----
    Without boundary data boundary edges get the plain assembly (the curved
    element's own normal stands in for the true one; rate near the boundary
    drops, as for flat meshes).
    """
    if not isinstance(surface, LagrangeSurface):
        raise TypeError(f"surface must be a LagrangeSurface, got {type(surface).__name__}")
    space = CurvedHHJ(surface, degree)
    A, B = space.matrices
    mesh = surface.mesh
    bnd = np.flatnonzero(mesh.boundary_edges)
    ss = simply_supported_mask(mesh.edges[bnd], surface.n_nodes, boundary_normals,
                               boundary_shape_operator, simply_supported, points="#N")
    clamped_e, ss_e = bnd[~ss], bnd[ss]
    X = surface.nodes
    rhs = -(B @ X)
    # plain assembly on every boundary edge: cancel B's one-sided term ∫ φ^nn n^k
    Nd = None
    if boundary_normals is not None and clamped_e.size:
        Nd = _per_node(surface, boundary_normals, "boundary_normals", (3,))
        need = surface.boundary_nodes
        if not np.isfinite(Nd[need]).all():
            raise ValueError("boundary_normals is NaN or inf at a boundary node")
        if (np.linalg.norm(Nd[need], axis=1) < 1e-12).any():
            raise ValueError("boundary_normals has a zero vector at a boundary node")
        Nd = np.where(np.isfinite(Nd), Nd, 0.0)
        f_b, _ = surface.boundary_face_and_local(clamped_e)
        ends = mesh.edges[clamped_e]
        dots = np.einsum("nck,nk->nc", Nd[ends], mesh.face_normals[f_b])
        if (dots <= 0).any():
            raise ValueError("boundary_normals point away from the surface normals on a boundary face: "
                             "they must agree with the elements' orientation")
    if bnd.size:
        if clamped_e.size:
            rhs += space.boundary_edge_terms(clamped_e, Nd)
        if ss_e.size:
            rhs += space.boundary_edge_terms(ss_e, None)
    s = np.zeros((space.n_dofs, 3))
    fixed = np.zeros(space.n_dofs, dtype=bool)
    if ss_e.size:
        Sd = _per_node(surface, boundary_shape_operator, "boundary_shape_operator", (3, 3))
        if not np.isfinite(Sd[surface.boundary_nodes]).all():
            raise ValueError("boundary_shape_operator is NaN or inf at a boundary node")
        Sd = np.where(np.isfinite(Sd), Sd, 0.0)
        ids, vals = _simply_supported_values(space, ss_e, Sd)
        fixed[ids] = True
        s[ids] = vals
    s = space.solve(rhs, fixed, s, solver=solver, condense=condense)
    return CurvedField(space, s, kind="hhj")


def _simply_supported_values(space, edges, Sd):
    """Edge DOFs of simply supported edges: p = σ^nn |dX/ds|² / l², σ^{nn,k} = -ν̂^k nᵀ S̃ n."""
    from .reference import EDGE_OUTWARD, EDGE_TANGENTS, lagrange_basis
    surf = space.surface
    f, jloc, xi, ids = space.edge_dof_points(edges)
    nF, npt = xi.shape[:2]
    ff = np.repeat(f, npt)
    jj = np.repeat(jloc, npt)
    xr = xi.reshape(-1, 2)
    g = surf.geometry(ff, np.column_stack([1 - xr.sum(1), xr]))
    J, Gi = g.J[:, 0], g.Ginv[:, 0]
    tv = np.einsum("nkd,nd->nk", J, EDGE_TANGENTS[jj])
    a = np.einsum("nde,ne->nd", Gi, EDGE_OUTWARD[jj])
    n = np.einsum("nkd,nd->nk", J, a)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    N = lagrange_basis(surf.order).values(xr)
    S = np.einsum("na,naij->nij", N, Sd[surf.elements[ff]])
    kn = np.einsum("ni,nij,nj->n", n, S, n)
    l2 = surf.mesh.edge_lengths[ff, jj] ** 2
    p = -g.nu[:, 0] * (kn * np.einsum("nk,nk->n", tv, tv) / l2)[:, None]
    return ids.ravel(), p
