"""Data-free boundary conditions for the HHJ shape operator: O(h²) boundary normals.

Walker's clamped boundary condition (Walker 2023, eq. 5.19, the Σ_c term
``∫_∂Γ n·ξ``) needs the true surface normal ν~ along the boundary; his
Theorem 5.3 gives O(h) for S_h when ν~ is accurate to O(h²) (the nodal
interpolant of the exact normal).  Without data, the *plain assembly* (face
normal in place of ν~) and libigl's per-vertex normals are only O(h)
accurate, and the error within two rings of the boundary stops converging.

:func:`estimate_boundary_normals` fits, at each boundary vertex x_v, a height
function ``z = g_1 x + g_2 y + ½(a x² + 2b xy + c y²)`` through x_v in the tangent
frame of a first normal over the vertices of its ``rings``-ring (3 by default) (weighted
least squares, one 5×5 system per boundary vertex, assembled with bincount),
and returns ``(n - g_1 e_1 - g_2 e_2)/|·|``.  The fit is exact for quadrics, so
the normal is O(h²) accurate on smooth surfaces; one re-fit in the new frame
removes the dependence on the first normal.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .constants import BOUNDARY_TREATMENTS, FIT_RINGS, SIDE_DOT_MIN
from .mesh import TriangleMesh

__all__ = ["estimate_boundary_normals", "boundary_normal_fits_reference", "BOUNDARY_TREATMENTS"]



def _dot3(a, b):
    """Row dot products of (m, 3) arrays, summed (a0 b0 + a1 b1) + a2 b2 on every machine."""
    d = a[:, 0] * b[:, 0]
    d += a[:, 1] * b[:, 1]
    d += a[:, 2] * b[:, 2]
    return d


def _ring_pairs(mesh: TriangleMesh, verts, rings):
    """(row, col) pairs: row indexes ``verts``, col a vertex of its ``rings``-ring (itself excluded)."""
    E = mesh.edges                       # unique edges: the vertex graph without duplicates
    nV = mesh.n_vertices
    ref = np.arange(nV)
    i = np.concatenate([E[:, 0], E[:, 1], ref])
    j = np.concatenate([E[:, 1], E[:, 0], ref])
    A = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(nV, nV))
    R = sp.csr_matrix((np.ones(len(verts)), (np.arange(len(verts)), verts)), shape=(len(verts), nV))
    for _ in range(rings):
        R = R @ A
        R.data[:] = 1.0
    R = R.tocoo()
    keep = R.col != verts[R.row]
    return R.row[keep], R.col[keep]


def _frames(N):
    ax = np.eye(3)[np.argmin(np.abs(N), axis=1)]
    e1 = np.cross(N, ax)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(N, e1)


def _fit_normals(X, verts, row, col, N0, scale):
    """One weighted quadric height fit per vertex of ``verts`` in the frame of N0."""
    e1, e2 = _frames(N0)
    d = (X[col] - X[verts[row]]) / scale[row, None]
    x = np.einsum("ma,ma->m", d, e1[row])
    y = np.einsum("ma,ma->m", d, e2[row])
    z = np.einsum("ma,ma->m", d, N0[row])
    w = 1.0 / (1.0 + x * x + y * y)          # nearer vertices count more (the fit stays exact for quadrics)
    phi = np.stack([x, y, 0.5 * x * x, x * y, 0.5 * y * y], axis=1)   # (m, 5)
    n = len(verts)
    G = np.empty((n, 5, 5))
    r = np.empty((n, 5))
    for a in range(5):
        r[:, a] = np.bincount(row, weights=w * phi[:, a] * z, minlength=n)
        for b in range(a, 5):
            G[:, a, b] = G[:, b, a] = np.bincount(row, weights=w * phi[:, a] * phi[:, b], minlength=n)
    count = np.bincount(row, minlength=n)
    cond = np.full(n, np.inf)
    finite = np.isfinite(G).all(axis=(1, 2)) & np.isfinite(r).all(axis=1)
    if finite.any():         # NaN where N0 is (a vertex without a tangent plane: folded sheets)
        # G is a weighted Gram matrix (symmetric PSD): its 2-norm condition number is
        # λ_max / λ_min (eigvalsh: 3x cheaper than the SVD of np.linalg.cond)
        lam = np.linalg.eigvalsh(G[finite])
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            cond[finite] = np.where(lam[:, 0] > 0, lam[:, -1] / lam[:, 0], np.inf)
    ok = (count >= 6) & np.isfinite(cond) & (cond < 1e10)
    g = np.zeros((n, 5))
    if ok.any():
        g[ok] = np.linalg.solve(G[ok], r[ok][:, :, None])[:, :, 0]
    Nn = N0 - g[:, 0, None] * e1 - g[:, 1, None] * e2
    Nn /= np.linalg.norm(Nn, axis=1, keepdims=True)
    return Nn, ok


def boundary_normal_fits_reference(mesh: TriangleMesh, verts, rings, N0):
    """The two quadric fits of :func:`estimate_boundary_normals` (numpy reference of
    :func:`igl_hhj.kernels.boundary_normal_fits`): at each vertex of ``verts`` (n,) over
    its ``rings``-ring (one ring more where that has fewer than 10 vertices), the first
    in the frame of N0 (n, 3), the second in the frame of the first's normal.  Returns
    (n, 3): the second normal where both fits are well posed, else N0."""
    X = mesh.V
    # spacing of each fit: mean edge length at the vertex, for conditioning only
    e = mesh.edges
    s = np.bincount(e.ravel(), weights=np.repeat(mesh.unique_edge_lengths, 2), minlength=mesh.n_vertices)
    c = np.bincount(e.ravel(), minlength=mesh.n_vertices)
    scale = (s / np.maximum(c, 1))[verts]
    row, col = _ring_pairs(mesh, verts, rings)
    # corners and other vertices with a thin neighbourhood: one more ring
    thin = np.flatnonzero(np.bincount(row, minlength=len(verts)) < 10)
    if thin.size:
        r3, c3 = _ring_pairs(mesh, verts[thin], rings + 1)
        keep = ~np.isin(row, thin)
        row = np.concatenate([row[keep], thin[r3]])
        col = np.concatenate([col[keep], c3])
    N1, ok = _fit_normals(X, verts, row, col, N0, scale)
    N1 = np.where(ok[:, None], N1, N0)
    N2, ok2 = _fit_normals(X, verts, row, col, N1, scale)
    return np.where((ok & ok2)[:, None], N2, N0)


def estimate_boundary_normals(mesh: TriangleMesh, rings=FIT_RINGS, *, reference=False):
    """O(h²) unit normals at the boundary vertices from local quadric fits.

    Parameters
    ----------
    mesh : TriangleMesh (open: with boundary edges)
    rings : int, default 3
        Fit neighbourhood in rings; vertices with fewer than 10 neighbours there
        (corners) use one ring more.  Wider fits pass less normal noise into
        the clamped data and cost a larger constant on clean meshes; all keep
        the O(h²) rate (``tests/vertex_stage/test_recovery.py``).
    reference : bool, default False
        Fit with the numpy reference :func:`boundary_normal_fits_reference` instead of
        the compiled :func:`igl_hhj.kernels.boundary_normal_fits` (the same to round-off).

    Returns
    -------
    N : (#V, 3) float64
        Unit normals on the boundary vertices (oriented like F), NaN elsewhere.
        Where the fit is ill-posed (fewer than 6 neighbours, degenerate
        configuration) or would point away from an incident boundary face, the
        normal falls back to the mean normal of the vertex's boundary faces; where
        that too points away from one of them (a vertex without a tangent plane:
        folded sheets, bow-ties with opposite wings) the row is NaN and
        ``boundary="estimate"`` keeps the plain assembly on its boundary edges.

    Notes
    -----
    Used as clamped data ν~ in Walker eq. 5.19 by ``boundary="estimate"``.
    """
    nV = mesh.n_vertices
    out = np.full((nV, 3), np.nan)
    verts = np.flatnonzero(mesh.boundary_vertices)
    if verts.size == 0:
        return out
    N0 = mesh.vertex_normals[verts]
    if reference:
        N = boundary_normal_fits_reference(mesh, verts, rings, N0)
    else:
        from . import kernels
        N = kernels.boundary_normal_fits(mesh, verts, rings, N0)
    e = mesh.edges
    # fallback: mean normal of the faces of the vertex's boundary edges
    be = np.flatnonzero(mesh.boundary_edges)
    f = mesh.edge_faces[be, 0]
    f = np.where(f >= 0, f, mesh.edge_faces[be, 1])
    fn = mesh.face_normals[f]
    # Σ of the faces' normals per vertex, summed in the order of np.add.at over column 0
    # then column 1 of the edges (one bincount per coordinate: the same sums, faster)
    idx = np.concatenate([e[be, 0], e[be, 1]])
    Nf = np.empty((len(verts), 3))
    for k in range(3):
        Nf[:, k] = np.bincount(idx, np.concatenate([fn[:, k], fn[:, k]]), nV)[verts]
    with np.errstate(invalid="ignore", divide="ignore"):   # cancelling normals: NaN, unusable
        Nf /= np.linalg.norm(Nf, axis=1, keepdims=True)
    out[verts] = N
    # every boundary face must see its vertices' normals on its own side
    for col_ in (0, 1):
        v = e[be, col_]
        bad = ~(_dot3(out[v], fn) > SIDE_DOT_MIN)
        if bad.any():
            vb = np.unique(v[bad])
            pos = np.searchsorted(verts, vb)
            out[vb] = Nf[pos]
    # where not even that normal sees every boundary face on its side (a bow-tie with
    # opposite wings, a folded sheet): no normal, the caller keeps those edges plain
    for col_ in (0, 1):
        v = e[be, col_]
        out[np.unique(v[~(_dot3(out[v], fn) > SIDE_DOT_MIN)])] = np.nan
    return out
