"""Creases: the dihedral angles of the edges, which edges are creases, the crease network, and
the mesh cut along the creases (the sharp-features path of the drop-in).

* :func:`dihedral_angles`: the signed dihedral angle θ_e of every edge (the angle between
  the two face normals, + where the edge is convex, - where concave, 0 on boundary edges).
* :func:`crease_edges`: the creases, ``|θ_e| > feature_angle`` (degrees), or the edges the
  caller names.
* :func:`crease_network`: chains (maximal runs of crease edges through vertices of crease
  degree 2), corners (≥ 3 creases meet) and end points (1 crease), the per-edge angle θ_e,
  length ℓ_e and the mean-curvature line measure θ_e ℓ_e / 2.
* :func:`cut_along`: the mesh with every vertex duplicated once per *side* (the components of
  its star connected across non-crease edges).  Faces keep their order and their corner
  order (only the indices change); the crease edges become boundary edges, so the
  open-boundary path of the shape operator clamps each side with its own O(h²) normals and
  the vertex stage never averages across a crease.  :func:`prepare_cut` checks the options
  and cuts (the pipeline's "crease cut" stage, :mod:`igl_hhj.pipeline`).

The public face of all this, with the feature-aware curvature functions, is
:mod:`igl_hhj.features` (which re-exports these names).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from . import kernels
from .mesh import TriangleMesh, _as_array

__all__ = [
    "DEFAULT_FEATURE_ANGLE", "check_feature_angle", "dihedral_angles", "dihedral_magnitudes", "crease_edges",
    "CreaseNetwork", "crease_network", "CutMesh", "cut_along", "cut_along_reference", "cut_mesh", "prepare_cut",
]

DEFAULT_FEATURE_ANGLE = 40.0
"""Default crease threshold in degrees: an edge is a crease where the normals of its two
faces differ by more than this (fandisk's creases are ≥ 50°, its smooth parts ≤ 25° at
its resolution)."""


def check_feature_angle(feature_angle):
    """Validate ``feature_angle`` (degrees, in (0, 180)); returns it as float."""
    if isinstance(feature_angle, (bool, np.bool_)) or not isinstance(
            feature_angle, (int, float, np.integer, np.floating)):
        raise TypeError(f"feature_angle must be a number of degrees, got {type(feature_angle).__name__}")
    a = float(feature_angle)
    if not 0.0 < a < 180.0:
        raise ValueError(f"feature_angle must be in (0, 180) degrees, got {a:g}")
    return a


def dihedral_angles(mesh: TriangleMesh) -> NDArray[np.float64]:
    """Signed dihedral angle θ_e of every unique edge, in radians.

    ``|θ_e|`` is the angle between the normals of the two faces of the edge (0 flat,
    π a fold onto itself), computed as ``atan2(|ν_0 × ν_1|, ν_0 · ν_1)``; the sign is +
    where the edge is convex (the far vertex of face 1 lies below the plane of face 0,
    with normals oriented by F) and - where concave.

    Returns
    -------
    theta : (#E,) float64, in mesh.edges order; 0 on boundary edges.
    """
    theta = dihedral_magnitudes(mesh)
    inner = np.flatnonzero(mesh.edge_face_count == 2)
    take = np.take
    ef = take(mesh.edge_faces, inner, axis=0)
    n0 = take(mesh.face_normals, ef[:, 0], axis=0)
    far = take(mesh.V, mesh.F[ef[:, 1], take(mesh.edge_local_index[:, 1], inner)], axis=0)  # corner opposite e in face 1
    side = np.einsum("ma,ma->m", n0, far - take(mesh.V, take(mesh.edges[:, 0], inner), axis=0))
    theta[inner] = np.where(side > 0, -theta[inner], theta[inner])
    return theta


def dihedral_magnitudes(mesh):
    """``|θ_e|`` of :func:`dihedral_angles` (#E,) (all the crease test needs), compiled:
    :func:`igl_hhj.kernels.dihedral_magnitudes` (numpy reference:
    ``tests/vertex_stage/reference_creases.py``)."""
    return kernels.dihedral_magnitudes(mesh)


def _edge_index(mesh, pairs, name):
    """Unique-edge indices of the vertex ``pairs`` (k, 2); ValueError names a pair that is no edge."""
    P = _as_array(pairs, name)
    if P.size == 0 and P.ndim == 1:             # [] is no pair, as np.zeros((0, 2))
        P = P.reshape(0, 2)
    if P.ndim != 2 or P.shape[1] != 2:
        raise ValueError(f"{name} must be a (k, 2) array of vertex pairs, got shape {P.shape}")
    if P.size and not np.issubdtype(P.dtype, np.integer):
        raise TypeError(f"{name} must hold integer vertex indices, got dtype {P.dtype}")
    nV = mesh.n_vertices
    out = (P < 0) | (P >= nV)                   # on the caller's dtype: uint64 is not wrapped to int64
    if out.any():
        j = int(np.flatnonzero(out.any(axis=1))[0])
        raise ValueError(f"{name} row {j} ({int(P[j, 0])}, {int(P[j, 1])}) is not an edge of the mesh "
                         f"(vertex index out of range, #V = {nV})")
    P = np.sort(P.astype(np.int64), axis=1)
    E = mesh.edges.astype(np.int64)                            # int32: the key needs int64
    key = E[:, 0] * nV + E[:, 1]                               # edges are sorted lexicographically
    k = P[:, 0] * nV + P[:, 1]
    pos = np.searchsorted(key, k)
    pos = np.minimum(pos, len(key) - 1)
    miss = (key[pos] != k) | (P[:, 0] < 0) | (P[:, 1] >= nV)
    if miss.any():
        j = int(np.flatnonzero(miss)[0])
        raise ValueError(f"{name} row {j} ({int(P[j, 0])}, {int(P[j, 1])}) is not an edge of the mesh")
    return pos


def crease_edges(mesh: TriangleMesh, feature_angle: float | None = DEFAULT_FEATURE_ANGLE, *,
                 edges: ArrayLike | None = None, theta: NDArray[np.float64] | None = None
                 ) -> NDArray[np.bool_]:
    """Which edges are creases.

    Parameters
    ----------
    mesh : TriangleMesh
    feature_angle : float, default :data:`DEFAULT_FEATURE_ANGLE` (40)
        Threshold in degrees on ``|θ_e|`` (:func:`dihedral_angles`); the same test as
        ``igl.sharp_edges(V, F, radians(feature_angle))``.  None: only ``edges``.
    edges : (k, 2) array_like of int, optional
        Crease edges named by their vertex pairs (either order), added to the detected
        ones.  Boundary edges are refused (they are already boundary).
    theta : (#E,) float64, optional, :func:`dihedral_angles` (or their magnitudes) if already computed.

    Returns
    -------
    crease : (#E,) bool, in mesh.edges order (never a boundary edge).
    """
    crease = np.zeros(mesh.n_edges, dtype=bool)
    if feature_angle is not None:
        a = np.radians(check_feature_angle(feature_angle))
        crease |= np.abs(dihedral_angles(mesh) if theta is None else theta) > a
    if edges is not None:
        idx = _edge_index(mesh, edges, "crease_edges")
        bnd = mesh.boundary_edges[idx]
        if bnd.any():
            e = mesh.edges[idx[bnd][0]]
            raise ValueError(f"crease_edges names the boundary edge ({int(e[0])}, {int(e[1])}): "
                             "a crease needs a face on either side")
        crease[idx] = True
    crease &= mesh.edge_face_count == 2
    return crease


@dataclass(frozen=True)
class CreaseNetwork:
    """The crease edges of a mesh as a curve network with its line measure.

    Attributes
    ----------
    edge_index : (#C,) int64, the crease edges' indices into ``mesh.edges``.
    edges : (#C, 2) int64, their vertex pairs (``mesh.edges`` rows).
    theta : (#C,) float64, signed dihedral angle θ_e in radians (+ convex).
    length : (#C,) float64, ℓ_e, the edge length.
    chain : (#C,) int64, chain label 0..n_chains-1: maximal runs of crease edges through
        vertices of crease degree 2 (closed loops included).
    corners : (k,) int64, vertices where ≥ 3 crease edges meet.
    endpoints : (k,) int64, vertices with exactly one crease edge (a crease fading out).
    """

    edge_index: NDArray[np.int64]
    edges: NDArray[np.int64]
    theta: NDArray[np.float64]
    length: NDArray[np.float64]
    chain: NDArray[np.int64]
    corners: NDArray[np.int64]
    endpoints: NDArray[np.int64]

    @property
    def n_chains(self) -> int:
        return int(self.chain.max()) + 1 if len(self.chain) else 0

    @property
    def mean_curvature_measure(self) -> NDArray[np.float64]:
        """(#C,) θ_e ℓ_e / 2: the mean curvature measure ∫ H dA carried by each crease edge."""
        return 0.5 * self.theta * self.length

    @property
    def total_angle_length(self) -> float:
        """Σ θ_e ℓ_e: converges to ∫_crease θ ds on the exact surface."""
        return float(np.sum(self.theta * self.length))

    def chain_totals(self) -> NDArray[np.float64]:
        """(n_chains,) Σ θ_e ℓ_e per chain."""
        return np.asarray(np.bincount(self.chain, weights=self.theta * self.length, minlength=self.n_chains),
                          dtype=np.float64)


def crease_network(mesh: TriangleMesh, crease: NDArray[np.bool_],
                   theta: NDArray[np.float64] | None = None) -> CreaseNetwork:
    """Chains, corners and line measure of the crease edges ``crease`` ((#E,) bool);
    ``theta``: :func:`dihedral_angles` if already computed."""
    idx = np.flatnonzero(crease)
    E = mesh.edges[idx].astype(np.int64)                       # int64 for the users (mesh.edges is int32)
    nV = mesh.n_vertices
    deg = np.bincount(E.ravel(), minlength=nV)
    # two crease edges belong to one chain where they share a vertex of crease degree 2
    v = E.ravel()                                              # incidences (vertex, edge k // 2)
    k = np.repeat(np.arange(len(idx)), 2)
    two = deg[v] == 2
    order = np.lexsort((k[two], v[two]))                       # the two incidences of a vertex adjacent
    pairs = k[two][order].reshape(-1, 2)
    n = len(idx)
    A = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    if n:
        _, chain = sp.csgraph.connected_components(A, directed=False)
    else:
        chain = np.zeros(0, dtype=np.int64)
    theta = (dihedral_angles(mesh) if theta is None else theta)[idx]
    return CreaseNetwork(edge_index=idx, edges=E, theta=theta,
                         length=mesh.unique_edge_lengths[idx], chain=chain.astype(np.int64),
                         corners=np.flatnonzero(deg >= 3), endpoints=np.flatnonzero(deg == 1))


@dataclass(frozen=True)
class CutMesh:
    """A mesh cut along its creases (:func:`cut_along`).

    Attributes
    ----------
    V : (#Vc, 3) float64, vertex positions; rows 0..#V-1 are the original vertices (each
        the copy of its side with the largest incident area: the *primary side*), the
        extra sides of crease vertices follow.
    F : (#F, 3) int64, the original faces in the original order and corner order, with
        indices into the cut vertices.
    parent : (#Vc,) int64, original vertex of each cut vertex (``parent[:#V] = arange(#V)``).
    """

    V: NDArray[np.float64]
    F: NDArray[np.int64]
    parent: NDArray[np.int64]


def cut_along(mesh: TriangleMesh, crease: NDArray[np.bool_], *, reference: bool = False) -> CutMesh:
    """Duplicate every vertex once per side of the creases through it.

    The sides of a vertex are the connected components of its corners, two corners
    (of the faces on either side of an edge through the vertex) being connected when
    the edge is not a crease; one connected-components pass over all 3#F corners
    (:func:`igl_hhj.kernels.graph_components`, union-find) finds them at once.  A vertex
    on no crease (or at the end of one) keeps one side and its index.

    Compiled (:func:`igl_hhj.kernels.crease_cut`: one union-find over the corners and the
    numbering in one pass); ``reference=True``: the numpy reference
    :func:`cut_along_reference` (the same arrays, tests/vertex_stage/test_features.py).

    ``igl.cut_mesh`` was not used: on a cube cut along its 12 edges it returns 28
    vertices instead of 24 (it cuts to disk topology).
    """
    if reference:
        return cut_along_reference(mesh, crease)
    nV = mesh.n_vertices
    Fc, extra = kernels.crease_cut(mesh, (mesh.edge_face_count == 2) & ~crease)
    par = np.concatenate([np.arange(nV), extra])
    return CutMesh(V=np.take(mesh.V, par, axis=0), F=Fc, parent=par)


def cut_along_reference(mesh: TriangleMesh, crease: NDArray[np.bool_]) -> CutMesh:
    """Numpy reference of :func:`cut_along` (corner graph by
    :func:`igl_hhj.kernels.graph_components`, the numbering by ``np.lexsort``)."""
    F = mesh.F
    nF, nV = mesh.n_faces, mesh.n_vertices
    keep = np.flatnonzero((mesh.edge_face_count == 2) & ~crease)
    take = np.take
    # int64 (the maps are int32 / int8): 3 f + i would overflow int32 above 715M faces
    ef = take(mesh.edge_faces, keep, axis=0).astype(np.int64)
    li = take(mesh.edge_local_index, keep, axis=0).astype(np.int64)
    f0, f1, i0, i1 = ef[:, 0], ef[:, 1], li[:, 0], li[:, 1]
    # in f0 the edge runs x_{i0+1} → x_{i0+2}, in f1 the other way: corner i0+1 of f0 is
    # corner i1+2 of f1 (same vertex) and i0+2 of f0 is i1+1 of f1
    nxt, prv = np.array([1, 2, 0]), np.array([2, 0, 1])
    pairs = np.empty((2 * len(keep), 2), dtype=np.int64)
    pairs[:len(keep), 0] = 3 * f0 + take(nxt, i0)
    pairs[len(keep):, 0] = 3 * f0 + take(prv, i0)
    pairs[:len(keep), 1] = 3 * f1 + take(prv, i1)
    pairs[len(keep):, 1] = 3 * f1 + take(nxt, i1)
    # the components of the corner graph, labelled in the order of their smallest corner
    # (union-find; the labels of scipy.sparse.csgraph.connected_components)
    label, ncomp = kernels.graph_components(pairs, 3 * nF)
    parent = np.zeros(ncomp, dtype=np.int64)
    parent[label] = F.ravel()
    # primary side of a vertex with several: largest incident area, ties to the lowest
    # label; its extra sides are numbered from #V on in the order (vertex, -area, label)
    multi = np.flatnonzero(np.bincount(parent, minlength=nV)[parent] > 1)
    area = np.bincount(label, weights=np.repeat(mesh.face_areas, 3), minlength=ncomp)
    order = multi[np.lexsort((multi, -area[multi], parent[multi]))]
    first = np.ones(len(order), dtype=bool)
    first[1:] = parent[order][1:] != parent[order][:-1]
    new_index = parent.copy()
    extra = order[~first]
    new_index[extra] = nV + np.arange(len(extra))
    Fc = take(new_index, label).reshape(nF, 3)
    par = np.concatenate([np.arange(nV), parent[extra]])
    Vc = take(mesh.V, par, axis=0)
    return CutMesh(V=Vc, F=Fc, parent=par)


def cut_mesh(mesh, crease):
    """The TriangleMesh of the cut, without a second validation: the cut of a valid mesh
    is a valid mesh (the same faces and positions, so no new degenerate face; cutting
    along edges keeps it edge-manifold and oriented; each side is one fan), and the
    seams are the creases (no unwelded-seam warning).  The per-face metrics of ``mesh``
    are reused (:meth:`igl_hhj.mesh.TriangleMesh._same_faces`)."""
    cut = cut_along(mesh, crease)
    return cut, TriangleMesh._same_faces(mesh, cut.V, cut.F)


def prepare_cut(mesh, feature_angle, crease_edges_, boundary, data):
    """The crease options checked, the creases found and the mesh cut along them.

    ``data``: the caller's boundary data (boundary_normals, boundary_shape_operator,
    simply_supported), which the cut cannot take (each side estimates its own normals),
    nor a ``boundary`` other than "estimate".  Returns ``(crease (#E,) bool, cut CutMesh,
    cut TriangleMesh)``."""
    if any(d is not None for d in data):
        raise ValueError("feature_angle / crease_edges cannot be combined with boundary_normals, "
                         "boundary_shape_operator or simply_supported (the cut mesh estimates its "
                         "boundary normals per side)")
    if boundary != "estimate":
        raise ValueError(f"feature_angle / crease_edges need boundary='estimate' (each side of a crease "
                         f"is clamped with its estimated normals), got boundary={boundary!r}")
    # the crease test needs |θ_e| only; the signs are for the crease network (crease_network)
    crease = crease_edges(mesh, feature_angle, edges=crease_edges_, theta=dihedral_magnitudes(mesh))
    cut, cm = cut_mesh(mesh, crease)
    return crease, cut, cm
