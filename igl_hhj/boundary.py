"""Boundary treatment of the HHJ system: which boundary edges get which condition, the checks of
the caller's boundary data, and the loads (Walker 2023, §5.3, eq. 5.18/5.19).

An open mesh's boundary edges are, for :func:`igl_hhj.shape_operator` and the drop-in:

* **clamped** with the caller's ``boundary_normals`` or, without data (``boundary=
  "estimate"``), with the O(h²) normals of
  :func:`igl_hhj.boundary_estimation.estimate_boundary_normals`: Walker's load
  ``g_e = ∫_e n·ξ ds`` (:func:`clamped_load`, the Σ_c term of eq. 5.19);
* **simply supported** with the caller's ``boundary_shape_operator``: the DOFs are fixed to
  ``-ν_T^k nᵀS~n`` (:func:`simply_supported_values`, eq. 5.18);
* **plain** (``boundary="plain"``, or an estimated normal that is unusable): the face normal
  stands in for the true one, the row of ``-B X + g`` is 0 (:func:`boundary_rhs`).

:func:`resolve_boundary` picks the treatment, :func:`boundary_partition` the edges,
:func:`normalised_boundary_normals` checks and scales the data.  The compiled small-mesh
path (``_core/small_mesh.cpp``, section "boundary=estimate") repeats the estimated case with
the same operations.
"""
from __future__ import annotations

import numpy as np

from .boundary_estimation import estimate_boundary_normals
from .constants import BOUNDARY_TREATMENTS, COORDINATE_MAX
from .mesh import TriangleMesh, _as_array, per_vertex_array

__all__ = [
    "check_boundary", "resolve_boundary", "simply_supported_mask", "boundary_partition", "data_rows",
    "check_magnitude", "boundary_face_and_conormal", "normalised_boundary_normals",
    "simply_supported_values", "clamped_load", "boundary_rhs",
]


def check_boundary(boundary):
    """Refuse a ``boundary=`` argument that is not one of :data:`BOUNDARY_TREATMENTS`."""
    if not isinstance(boundary, str) or boundary not in BOUNDARY_TREATMENTS:
        raise ValueError(f"boundary must be one of {BOUNDARY_TREATMENTS}, got {boundary!r}")


def resolve_boundary(mesh, boundary, boundary_normals, boundary_shape_operator):
    """Boundary data to use: the caller's, or (``boundary="estimate"``, an open mesh and
    no data) the O(h²) normals of :func:`igl_hhj.boundary_estimation.estimate_boundary_normals`
    as clamped data.  Returns ``(boundary_normals, treatment)``, treatment one of
    "none" (closed), "data", "estimate", "plain"."""
    check_boundary(boundary)
    if not mesh.has_boundary:
        return boundary_normals, "none"
    if boundary_normals is not None or boundary_shape_operator is not None:
        return boundary_normals, "data"
    if boundary == "plain":
        return None, "plain"
    return estimate_boundary_normals(mesh), "estimate"


def simply_supported_mask(edges, n_points, boundary_normals, boundary_shape_operator,
                           simply_supported, points="#V"):
    """(len(edges),) bool: which boundary ``edges`` (pairs of point indices) are simply
    supported, from the boundary arguments of :func:`shape_operator` (also used by
    :func:`igl_hhj.curved.shape_operator`, whose points are the ``#N`` nodes)."""
    if simply_supported is not None:
        if boundary_shape_operator is None:
            raise ValueError("simply_supported needs boundary_shape_operator (the data on those edges)")
        flag = _as_array(simply_supported, "simply_supported")   # a mask is refused, not dropped
        if flag.shape != (n_points,):
            raise ValueError(f"simply_supported must have shape ({n_points},), got {flag.shape}")
        if flag.dtype != bool:
            raise TypeError(f"simply_supported must be a boolean array, got dtype {flag.dtype}")
        return flag[edges[:, 0]] & flag[edges[:, 1]]
    if boundary_shape_operator is not None:
        if boundary_normals is not None:
            raise ValueError("both boundary_normals and boundary_shape_operator given: pass "
                             f"simply_supported ({points} bool) to say which boundary edges are simply supported")
        return np.ones(len(edges), dtype=bool)
    return np.zeros(len(edges), dtype=bool)


def boundary_partition(mesh, boundary_normals, boundary_shape_operator, simply_supported,
                        estimated=False):
    """Return (clamped_with_data (#E,) bool, simply_supported_edges (#E,) bool).

    ``estimated``: the normals come from :func:`estimate_boundary_normals`, whose NaN
    rows mark vertices without a usable normal; their edges keep the plain assembly."""
    bnd = mesh.boundary_edges
    ss_edges = bnd & simply_supported_mask(mesh.edges, mesh.n_vertices, boundary_normals,
                                            boundary_shape_operator, simply_supported)
    clamped = bnd & ~ss_edges if boundary_normals is not None else np.zeros_like(bnd)
    if estimated:
        usable = np.isfinite(boundary_normals).all(axis=1)
        clamped &= usable[mesh.edges[:, 0]] & usable[mesh.edges[:, 1]]
    return clamped, ss_edges


def data_rows(mesh, A, edge_mask, name):
    """Check that per-vertex data is finite on the endpoints of the masked edges."""
    verts = np.unique(mesh.edges[edge_mask].ravel())
    bad = ~np.isfinite(A[verts].reshape(len(verts), -1)).all(axis=1)
    if bad.any():
        raise ValueError(f"{name} is NaN or inf at boundary vertex {int(verts[bad][0])}, "
                         "where it is needed")
    check_magnitude(A[verts], verts, name)
    return verts


def check_magnitude(A, rows, name):
    """Data beyond COORDINATE_MAX would overflow the solver's squared norms (silent NaN)."""
    big = (np.abs(A.reshape(len(A), -1)) > COORDINATE_MAX).any(axis=1)
    if big.any():
        raise ValueError(f"{name} has values beyond {COORDINATE_MAX:g} (they would overflow "
                         f"float64 in the solver); first at vertex {int(rows[big][0])}: rescale")


def boundary_face_and_conormal(mesh, e):
    f = mesh.edge_faces[e, 0]
    i = mesh.edge_local_index[e, 0]
    neg = f < 0
    f = np.where(neg, mesh.edge_faces[e, 1], f)
    i = np.where(neg, mesh.edge_local_index[e, 1], i)
    return f, mesh.conormals_at(f, i)


def normalised_boundary_normals(mesh, boundary_normals, clamped, estimated=False):
    """The boundary normals on the clamped edges' vertices scaled to unit length, after the
    checks of the caller's data (finite, bounded, non-zero, on the side of F's normals).
    ``estimated``: the normals of :func:`estimate_boundary_normals`, which pass every
    check by construction (unit, NaN rows dropped by :func:`boundary_partition`, at
    least ``SIDE_DOT_MIN`` with every boundary face): only scaled."""
    if estimated:            # every finite row (a superset of the clamped edges' vertices)
        N = np.array(boundary_normals, dtype=np.float64)
        verts = np.flatnonzero(np.isfinite(N).all(axis=1))
        N[verts] /= np.linalg.norm(N[verts], axis=1)[:, None]
        return N
    N = per_vertex_array(mesh, boundary_normals, "boundary_normals", (3,))
    verts = data_rows(mesh, N, clamped, "boundary_normals")
    norm = np.linalg.norm(N[verts], axis=1)
    if (norm < 1e-12).any():
        raise ValueError(f"boundary_normals has a zero vector at vertex {int(verts[norm < 1e-12][0])}")
    N = N.copy()
    N[verts] /= norm[:, None]
    # Orientation check: the data must point to the same side as the faces.
    e = np.flatnonzero(clamped)
    f, _ = boundary_face_and_conormal(mesh, e)
    for col in (0, 1):
        v = mesh.edges[e, col]
        dots = np.einsum("ma,ma->m", N[v], mesh.face_normals[f])
        if (dots <= 0).any():
            j = int(np.flatnonzero(dots <= 0)[0])
            raise ValueError(
                f"boundary_normals at vertex {int(v[j])} points away from the normal of its "
                f"boundary face {int(f[j])} (dot {dots[j]:.3f}): normals must agree with F's orientation")
    return N


def simply_supported_values(mesh, boundary_shape_operator, ss_edges):
    """ρ_e^k = -ν_T^k · mean_e(nᵀ S~ n), eq. (5.18) with P1-interpolated S~. Returns (#E, 3)."""
    S = per_vertex_array(mesh, boundary_shape_operator, "boundary_shape_operator", (3, 3))
    v = data_rows(mesh, S, ss_edges, "boundary_shape_operator")
    asym = np.abs(S[v] - S[v].transpose(0, 2, 1)).max(axis=(1, 2)) > 1e-8 * (1 + np.abs(S[v]).max(axis=(1, 2)))
    if asym.any():                  # a shape operator is symmetric; only nᵀ S n would be used
        raise ValueError(f"boundary_shape_operator is not symmetric at boundary vertex {int(v[asym][0])}")
    rho = np.zeros((mesh.n_edges, 3))
    e = np.flatnonzero(ss_edges)
    f, n = boundary_face_and_conormal(mesh, e)
    Sm = 0.5 * (S[mesh.edges[e, 0]] + S[mesh.edges[e, 1]])
    kn = np.einsum("ma,mab,mb->m", n, Sm, n)
    rho[e] = -mesh.face_normals[f] * kn[:, None]
    return rho


def clamped_load(mesh: TriangleMesh, edge_mask, gradient):
    """Clamped boundary load ``g_e = ∫_e n·ξ ds`` for P1-interpolated data ξ.

    Parameters
    ----------
    edge_mask : (#E,) bool, edges receiving data (boundary edges).
    gradient : (#V, k, 3) surface gradients ξ of k functions at the vertices
        (rows of vertices not on a masked edge are ignored).

    Returns
    -------
    g : (#E, k) float64, zero off the mask.  Exact for linear ξ along the edge.
    """
    k = gradient.shape[1]
    g = np.zeros((mesh.n_edges, k))
    e = np.flatnonzero(edge_mask)
    if e.size == 0:
        return g
    f = mesh.edge_faces[e, 0]
    f = np.where(f >= 0, f, mesh.edge_faces[e, 1])
    i = np.where(mesh.edge_faces[e, 0] >= 0, mesh.edge_local_index[e, 0], mesh.edge_local_index[e, 1])
    n = mesh.conormals_at(f, i)                   # (m, 3)
    va, vb = mesh.edges[e, 0], mesh.edges[e, 1]
    xi = 0.5 * (gradient[va] + gradient[vb])      # (m, k, 3) mean over the edge
    # n·ξ summed (n0 ξ0 + n1 ξ1) + n2 ξ2 in this order on every machine (einsum's order
    # depends on the SIMD width), as the compiled small-mesh path (igl_hhj.small_mesh)
    s = n[:, None, 0] * xi[:, :, 0]
    s += n[:, None, 1] * xi[:, :, 1]
    s += n[:, None, 2] * xi[:, :, 2]
    g[e] = mesh.unique_edge_lengths[e, None] * s
    return g


def boundary_rhs(mesh, rhs, clamped, N):
    """Boundary rows of ``-B X + g`` in place: plain assembly on boundary edges without
    data (``g_e = l_e n·∇_T X`` cancels B's one-sided term, so the row is 0) and
    Walker's clamped load (eq. 5.19's Σ_c term) on the clamped ones, with the
    normalised boundary normals ``N`` (#V, 3)."""
    bnd = mesh.boundary_edges
    if not bnd.any():
        return rhs
    rhs[bnd & ~clamped] = 0.0
    if clamped.any():
        # ξ^k = ∇_Γ id^k = P e_k, P = I - ν~ ⊗ ν~: gradients of the 3 coordinates; only the
        # clamped edges' vertices are read (N is finite there), rows without N are zero
        with np.errstate(over="ignore", invalid="ignore"):    # unread rows may be anything
            P = np.eye(3)[None] - N[:, :, None] * N[:, None, :]  # (#V, 3, 3): row k = ξ^k
        P[~np.isfinite(P)] = 0.0
        rhs[clamped] += clamped_load(mesh, clamped, P)[clamped]
    return rhs
