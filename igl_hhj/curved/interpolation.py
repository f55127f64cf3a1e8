"""Placing the Lagrange nodes of a curved surface from a flat mesh and a map onto Γ.

Walker (2023, eq. 4.14) builds the element maps as ``F_T^m = 𝓘_h^{1,m} F_T``
with the *modified* Lagrange interpolant 𝓘_h^{1,m} of eq. (4.2): on every flat
triangle T^1 the degree-m polynomial matches F_T at the three vertices, its
moments against P_{m-2} on each edge E^1 and against P_{m-3} on T^1:

    p(x) = F(x) at vertices,  ∫_E (p - F) q ds = 0,  ∫_T (p - F) η dS = 0.

The edge conditions involve only the edge, so neighbouring elements agree on
their shared edge exactly (one computation per unique edge).  "This choice is
necessary to guarantee optimal convergence of the HHJ method when m = r + 1."
The result is stored as nodal values at gmsh's equispaced nodes (nodes then lie
O(h^{m+1}) off Γ).
"""
from __future__ import annotations

import numpy as np

from ..mesh import TriangleMesh
from .reference import edge_node_slots, lagrange_basis, lagrange_nodes, line_quadrature, triangle_quadrature

__all__ = ["projected_nodes", "mapped_nodes", "edge_moment_matrices", "modified_interpolant"]


def _lagrange_1d(order, t):
    """(len(t), order+1) 1-D Lagrange basis at equispaced nodes k/order, k = 0..order."""
    nodes = np.arange(order + 1) / order
    L = np.ones((len(t), order + 1))
    for k in range(order + 1):
        for j in range(order + 1):
            if j != k:
                L[:, k] *= (t - nodes[j]) / (nodes[k] - nodes[j])
    return L


def edge_moment_matrices(order, n_gauss=10):
    """Gauss points/weights on [0,1] and the moment system of eq. (4.2) on an edge.

    Returns t (g,), w (g,), Q (g, m-1) test functions q_p(t) = t^p (p ≤ m-2),
    L (g, m+1) the 1-D Lagrange basis, and M = ∫ q_p ℓ_k dt for interior k."""
    t, w = line_quadrature(n_gauss)
    L = _lagrange_1d(order, t)
    Q = np.stack([t ** p for p in range(order - 1)], axis=1)
    M = np.einsum("g,gp,gk->pk", w, Q, L[:, 1:order])
    return t, w, Q, L, M


def projected_nodes(V, F, order, project, interpolant="walker"):
    """Nodes and gmsh-ordered elements of Γ^m from a flat mesh and a map ``project``.

    See :meth:`igl_hhj.curved.LagrangeSurface.from_projection`."""
    if not callable(project):
        raise TypeError("project must be a callable mapping (n, 3) points onto the surface")
    mesh = TriangleMesh(V, F)
    X = mesh.V[mesh.F]

    def element_map(faces, bary):
        return project(np.einsum("nc,nck->nk", bary, X[faces]))
    return mapped_nodes(mesh, order, element_map, interpolant)


def mapped_nodes(mesh, order, element_map, interpolant="walker"):
    """Nodes and elements of Γ^m for an element map ``element_map(faces, bary) -> (n, 3)``:
    the exact map F_T of Walker §3.1 from the flat triangles of ``mesh`` onto Γ
    (continuous across edges), interpolated by 𝓘_h^{1,m} (eq. 4.14) or nodally."""
    if order not in (1, 2, 3, 4):
        raise ValueError(f"order must be 1, 2, 3 or 4, got {order!r}")
    if interpolant not in ("walker", "nodal"):
        raise ValueError(f"interpolant must be 'walker' or 'nodal', got {interpolant!r}")
    if order == 4 and interpolant == "walker":
        raise ValueError("Walker's modified interpolant (eq. 4.14) is implemented for order m <= 3; "
                         "order 4 (Heine's degree γ = 4) needs interpolant='nodal'")
    if not callable(element_map):
        raise TypeError("the element map must be callable (faces, bary) -> points")
    Ff = mesh.F

    def fmap(faces, bary):
        Y = np.asarray(element_map(faces, bary), dtype=np.float64)
        if Y.shape != (len(faces), 3):
            raise ValueError(f"project returned shape {Y.shape} for input of shape {(len(faces), 3)}")
        if not np.isfinite(Y).all():
            raise ValueError("project returned NaN or inf")
        return Y

    nV, nE, nF = mesh.n_vertices, mesh.n_edges, mesh.n_faces
    # vertices: image of each vertex through one of its faces
    vf = np.zeros(nV, dtype=np.int64)
    vc = np.zeros(nV, dtype=np.int64)
    vf[Ff.ravel()] = np.repeat(np.arange(nF), 3)
    vc[Ff.ravel()] = np.tile(np.arange(3), nF)
    ref = mesh.referenced_vertices
    Pv = np.array(mesh.V, dtype=np.float64)
    Pv[ref] = fmap(vf[ref], np.eye(3)[vc[ref]])
    if order == 1:
        return Pv, Ff.copy()
    E = mesh.edges
    ef, li = mesh.edge_faces, mesh.edge_local_index
    col = (ef[:, 0] < 0).astype(int)
    fe, je = ef[np.arange(nE), col], li[np.arange(nE), col]
    fwd = E[:, 0] == Ff[fe, (je + 1) % 3]

    def edge_bary(t):                       # (nE, len(t), 3) barycentrics of edge points va → vb
        B = np.zeros((nE, len(t), 3))
        a, b = (je + 1) % 3, (je + 2) % 3
        ta = np.where(fwd[:, None], 1 - t[None], t[None])
        r = np.arange(nE)[:, None]
        B[r, np.arange(len(t))[None], a[:, None]] = ta
        B[r, np.arange(len(t))[None], b[:, None]] = 1 - ta
        return B

    def map_edges(t):
        Bt = edge_bary(t)
        return fmap(np.repeat(fe, len(t)), Bt.reshape(-1, 3)).reshape(nE, len(t), 3)
    if interpolant == "nodal":
        edge_nodes = map_edges(np.arange(1, order) / order)
    else:
        t, w, Q, L, M = edge_moment_matrices(order)
        Fp = map_edges(t)
        rhs = np.einsum("g,gp,egk->epk", w, Q, Fp)
        rhs -= np.einsum("g,gp,g->p", w, Q, L[:, 0])[None, :, None] * Pv[E[:, 0]][:, None]
        rhs -= np.einsum("g,gp,g->p", w, Q, L[:, order])[None, :, None] * Pv[E[:, 1]][:, None]
        edge_nodes = np.einsum("kp,epc->ekc", np.linalg.inv(M), rhs)     # (nE, m-1, 3)
    nodes = [Pv, edge_nodes.reshape(-1, 3)]
    nb = (order + 1) * (order + 2) // 2
    elements = np.empty((nF, nb), dtype=np.int64)
    elements[:, :3] = Ff
    slots = edge_node_slots(order)
    FE = mesh.face_edges
    for j in range(3):                       # 3 local edges: vectorised over faces
        e = FE[:, j].astype(np.int64)        # int32 map: the node ids in int64
        fw = E[e, 0] == Ff[:, (j + 1) % 3]   # local edge j runs from corner j+1 to j+2
        ids = nV + e[:, None] * (order - 1) + np.arange(order - 1)[None]
        ids = np.where(fw[:, None], ids, ids[:, ::-1])
        elements[:, slots[j]] = ids
    if order == 4:                           # 3 interior nodes per face, nodal (gmsh triangle15)
        c0 = nV + nE * (order - 1)
        elements[:, 12:] = c0 + 3 * np.arange(nF)[:, None] + np.arange(3)[None]
        xi = lagrange_nodes(4)[12:]
        lam = np.column_stack([1 - xi.sum(1), xi])
        nodes.append(fmap(np.repeat(np.arange(nF), 3), np.tile(lam, (nF, 1))))
    if order == 3:
        c0 = nV + nE * (order - 1)
        elements[:, 9] = c0 + np.arange(nF)
        if interpolant == "nodal":
            cen = fmap(np.arange(nF), np.full((nF, 3), 1.0 / 3.0))
        else:
            xi, wq = triangle_quadrature(10)
            lam = np.column_stack([1 - xi.sum(1), xi])
            Fp = fmap(np.repeat(np.arange(nF), len(wq)), np.tile(lam, (nF, 1))).reshape(nF, len(wq), 3)
            N = lagrange_basis(3).values(xi)                           # (q, 10)
            intN = wq @ N                                              # ∫ N_a dξ
            known = np.concatenate([Pv, edge_nodes.reshape(-1, 3)])[elements[:, :9]]   # (nF, 9, 3)
            intF = np.einsum("q,fqk->fk", wq, Fp)
            cen = (intF - np.einsum("a,fak->fk", intN[:9], known)) / intN[9]
        nodes.append(cen)
    return np.concatenate(nodes), elements


def modified_interpolant(V, F, order, w, *, project=None, element_map=None, interpolant="walker"):
    """Nodal values of ŵ_h = 𝓘_h^{1,m}(w ∘ F_T), the degree-m interpolant of a function w
    given on Γ, by the same rule (eq. 4.2/4.14) that places the nodes of Γ^m.

    Walker's Remark 4.2 replaces w̃ = w ∘ Ψ^m by an interpolant; for m = r + 1 the
    interpolant must be this moment-based one (vertex values, edge moments against
    P_{m-2}, face moments against P_{m-3}), which has the Fortin property (4.6) of the
    HHJ pairing: nodal values w(Ψ^m(x_a)) lose an order of the Hessian (measured:
    EOC 2.0 instead of 3.0 at m = 3 on the torus).

    Parameters
    ----------
    V : (#V, 3), F : (#F, 3)
        The flat mesh Γ^1 the curved surface was built from.
    order : {1, 2, 3}
    w : callable (n, 3) points on Γ → (n,) or (n, k) values.
    project, element_map : callable
        Exactly one: the map F_T of :meth:`LagrangeSurface.from_projection` or
        :meth:`LagrangeSurface.from_parametrization`.
    interpolant : {"walker", "nodal"}

    Returns
    -------
    (#N,) or (#N, k) float64, numbered like the nodes of the matching LagrangeSurface.
    """
    if (project is None) == (element_map is None):
        raise TypeError("pass exactly one of project= or element_map=")
    if not callable(w):
        raise TypeError("w must be a callable mapping (n, 3) points on the surface to values")
    mesh = TriangleMesh(V, F)
    if project is not None:
        if not callable(project):
            raise TypeError("project must be a callable mapping (n, 3) points onto the surface")
        X = mesh.V[mesh.F]

        def element_map(faces, bary):                                   # noqa: F811
            return project(np.einsum("nc,nck->nk", bary, X[faces]))
    elif not callable(element_map):
        raise TypeError("the element map must be callable (faces, bary) -> points")
    probe = np.asarray(w(element_map(np.zeros(1, dtype=np.int64), np.full((1, 3), 1 / 3))), dtype=np.float64)
    single = probe.ndim == 1
    k = 1 if single else probe.shape[1]
    cols = []
    for c0 in range(0, k, 3):                                          # mapped_nodes interpolates 3 columns at once
        def values(faces, bary, c0=c0):
            Wv = np.asarray(w(element_map(faces, bary)), dtype=np.float64).reshape(len(faces), -1)
            out = np.zeros((len(faces), 3))
            out[:, :min(3, k - c0)] = Wv[:, c0:c0 + 3]
            return out
        cols.append(mapped_nodes(mesh, order, values, interpolant)[0][:, :min(3, k - c0)])
    out = np.concatenate(cols, axis=1)
    return out[:, 0] if single else out
