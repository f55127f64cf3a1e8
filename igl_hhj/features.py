"""Sharp features: creases as internal boundaries, crease curvature as a line measure.

A crease (a sharp edge of a CAD part, a scan of a machined object) is a jump of the
normal across an edge.  Its curvature is a Dirac measure concentrated on the edge: the
HHJ shape operator S_h (Walker, paper 000) is an L2 projection onto piecewise-constant
tensors and cannot represent it (a saw-tooth of signs along the crease), and every
vertex stage that averages across the crease smears it into a band of large values.

This module treats the surface as **cut along its creases** (issue 27):

* :func:`dihedral_angles`: the signed dihedral angle θ_e of every edge (the angle
  between the two face normals, + where the edge is convex, - where concave, 0 on
  boundary edges).
* :func:`crease_edges`: the creases, ``|θ_e| > feature_angle`` (degrees), or the
  edges the caller names.
* :func:`crease_network`: chains (maximal runs of crease edges through vertices of
  crease degree 2), corners (≥ 3 creases meet) and end points (1 crease), the
  per-edge angle θ_e, length ℓ_e and the mean-curvature line measure θ_e ℓ_e / 2.
* :func:`cut_along`: the mesh with every vertex duplicated once per *side* (the
  components of its star connected across non-crease edges).  Faces keep their
  order and their corner order (only the indices change); the crease edges become
  boundary edges, so the open-boundary path of :func:`igl_hhj.shape_operator`
  clamps each side with its own O(h²) normals
  (:func:`igl_hhj.boundary_estimation.estimate_boundary_normals` on the cut mesh
  sees only that side), and the vertex stage (recovery, smoothing) never averages
  across a crease.
* :func:`feature_shape_operator`, :func:`feature_principal_curvature`: the
  feature-aware shape operator (per face) and principal curvatures (per side and,
  in the drop-in shape, one value per vertex), used by
  ``principal_curvature(..., feature_angle=...)`` and
  ``shape_operator(..., feature_angle=...)``.

The crease's own curvature is returned separately, as what it is: the mean curvature
measure of the piecewise-flat surface is ``Σ_e θ_e |e| / 2`` (Steiner's formula;
Cohen-Steiner & Morvan's normal-cycle measure restricted to the crease edges), and
``Σ_e θ_e |e|`` converges to ``∫_crease θ ds`` of the exact surface.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from . import kernels
from .mesh import TriangleMesh, _as_array, as_mesh

__all__ = [
    "DEFAULT_FEATURE_ANGLE", "dihedral_angles", "crease_edges", "crease_network", "CreaseNetwork",
    "cut_along", "CutMesh", "feature_shape_operator", "feature_principal_curvature",
    "FeatureCurvature", "check_feature_angle", "dihedral_magnitudes_reference", "cut_along_reference",
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
    theta = _dihedral_magnitudes(mesh)
    inner = np.flatnonzero(mesh.edge_face_count == 2)
    take = np.take
    ef = take(mesh.edge_faces, inner, axis=0)
    n0 = take(mesh.face_normals, ef[:, 0], axis=0)
    far = take(mesh.V, mesh.F[ef[:, 1], take(mesh.edge_local_index[:, 1], inner)], axis=0)  # corner opposite e in face 1
    side = np.einsum("ma,ma->m", n0, far - take(mesh.V, take(mesh.edges[:, 0], inner), axis=0))
    theta[inner] = np.where(side > 0, -theta[inner], theta[inner])
    return theta


def _dihedral_magnitudes(mesh):
    """``|θ_e|`` of :func:`dihedral_angles` (#E,) (all the crease test needs), compiled:
    :func:`igl_hhj.kernels.dihedral_magnitudes` (reference :func:`dihedral_magnitudes_reference`)."""
    return kernels.dihedral_magnitudes(mesh)


def dihedral_magnitudes_reference(mesh: TriangleMesh) -> NDArray[np.float64]:
    """Numpy reference of :func:`igl_hhj.kernels.dihedral_magnitudes`: ``|θ_e| =
    atan2(|ν_0 × ν_1|, ν_0 · ν_1)`` (#E,) of the normals of the two faces of every inner
    edge, 0 on boundary (and non-manifold) edges."""
    theta = np.zeros(mesh.n_edges)
    inner = np.flatnonzero(mesh.edge_face_count == 2)
    take = np.take                   # rows by np.take: several times faster than fancy indexing
    ef = take(mesh.edge_faces, inner, axis=0)
    n0, n1 = take(mesh.face_normals, ef[:, 0], axis=0), take(mesh.face_normals, ef[:, 1], axis=0)
    theta[inner] = np.arctan2(np.linalg.norm(np.cross(n0, n1), axis=1), np.einsum("ma,ma->m", n0, n1))
    return theta


def _edge_index(mesh, pairs, name):
    """Unique-edge indices of the vertex ``pairs`` (k, 2); ValueError names a pair that is no edge."""
    P = _as_array(pairs, name)
    if P.ndim != 2 or P.shape[1] != 2:
        raise ValueError(f"{name} must be a (k, 2) array of vertex pairs, got shape {P.shape}")
    if P.size and not np.issubdtype(P.dtype, np.integer):
        raise TypeError(f"{name} must hold integer vertex indices, got dtype {P.dtype}")
    P = np.sort(P.astype(np.int64), axis=1)
    nV = mesh.n_vertices
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


def _cut_mesh(mesh, crease):
    """The TriangleMesh of the cut, without a second validation: the cut of a valid mesh
    is a valid mesh (the same faces and positions, so no new degenerate face; cutting
    along edges keeps it edge-manifold and oriented; each side is one fan), and the
    seams are the creases (no unwelded-seam warning).  The per-face metrics of ``mesh``
    are reused (:meth:`igl_hhj.mesh.TriangleMesh._same_faces`)."""
    cut = cut_along(mesh, crease)
    return cut, TriangleMesh._same_faces(mesh, cut.V, cut.F)


def _prepare(V, F, feature_angle, crease_edges_, boundary, data):
    mesh = as_mesh(V, F)
    if any(d is not None for d in data):
        raise ValueError("feature_angle / crease_edges cannot be combined with boundary_normals, "
                         "boundary_shape_operator or simply_supported (the cut mesh estimates its "
                         "boundary normals per side)")
    if boundary != "estimate":
        raise ValueError(f"feature_angle / crease_edges need boundary='estimate' (each side of a crease "
                         f"is clamped with its estimated normals), got boundary={boundary!r}")
    # the crease test needs |θ_e| only; the signs are for the crease network (crease_network)
    crease = crease_edges(mesh, feature_angle, edges=crease_edges_, theta=_dihedral_magnitudes(mesh))
    cut, cm = _cut_mesh(mesh, crease)
    return mesh, (crease, None), cut, cm


def feature_shape_operator(V: Any, F: ArrayLike | None = None, *,
                           feature_angle: float | None = DEFAULT_FEATURE_ANGLE,
                           crease_edges: ArrayLike | None = None, solver: str = "auto",
                           rtol: float | None = None) -> NDArray[np.float64]:
    """Walker's S_h of the surface cut along its creases, one tensor per face.

    Solves eq. (5.19) on :func:`cut_along`'s mesh: the crease edges are clamped edges
    whose data ν~ are the O(h²) one-sided normals of each side
    (:func:`igl_hhj.boundary_estimation.estimate_boundary_normals` on the cut mesh),
    open boundaries of the mesh as ``boundary="estimate"``.  The crease's own curvature
    is not in S_h (see :func:`crease_network`).

    Returns
    -------
    S : (#F, 3, 3) float64, in the caller's F order.
    """
    from . import curvature
    from .solvers import DEFAULT_RTOL
    mesh, crease, cut, cm = _prepare(V, F, feature_angle, crease_edges, "estimate", ())
    return curvature._checked_shape_operator(cm, "estimate", None, None, None, solver,
                                             DEFAULT_RTOL if rtol is None else rtol, groups_of=mesh)


@dataclass(frozen=True)
class FeatureCurvature:
    """Result of :func:`feature_principal_curvature`.

    Attributes
    ----------
    PD1, PD2 : (#V, 3), PV1, PV2 : (#V,), bad_vertices : list of int
        The drop-in tuple of :func:`igl_hhj.principal_curvature`: at a crease vertex the
        values of its *primary side* (the side with the largest incident area).
    side_PD1, side_PD2 : (#Vc, 3), side_PV1, side_PV2 : (#Vc,)
        One row per side of every vertex (rows 0..#V-1 are the primary sides, equal to
        PD1..PV2; ``side_parent`` maps every row to its vertex).
    side_parent : (#Vc,) int64
    side_normals : (#Vc, 3), each side's own vertex normal.
    cut : CutMesh, the cut mesh (its F indexes the side rows).
    creases : CreaseNetwork, the crease edges, chains, corners and θ_e.
    """

    PD1: NDArray[np.float64]
    PD2: NDArray[np.float64]
    PV1: NDArray[np.float64]
    PV2: NDArray[np.float64]
    bad_vertices: list
    side_PD1: NDArray[np.float64]
    side_PD2: NDArray[np.float64]
    side_PV1: NDArray[np.float64]
    side_PV2: NDArray[np.float64]
    side_parent: NDArray[np.int64]
    side_normals: NDArray[np.float64]
    cut: CutMesh
    creases: CreaseNetwork

    def as_tuple(self):
        """(PD1, PD2, PV1, PV2, bad_vertices), as ``igl.principal_curvature``."""
        return self.PD1, self.PD2, self.PV1, self.PV2, self.bad_vertices

    @property
    def side_mean_curvature(self) -> NDArray[np.float64]:
        """(#Vc,) H = (κ1 + κ2)/2 per side."""
        return 0.5 * (self.side_PV1 + self.side_PV2)


def feature_principal_curvature(V: Any, F: ArrayLike | None = None, radius: int = 5, *,
                                feature_angle: float | None = DEFAULT_FEATURE_ANGLE,
                                crease_edges: ArrayLike | None = None, boundary: str = "estimate",
                                solver: str = "auto", rtol: float | None = None,
                                _data=()) -> FeatureCurvature:
    """Principal curvatures of the smooth parts of a creased surface, per side.

    :func:`feature_shape_operator`, then the drop-in's vertex stage
    (:func:`igl_hhj.curvature.dropin_vertex_values`: intrinsic recovery, adaptive
    smoothing at scale ``radius``) on the cut mesh, so that neither recovery nor
    smoothing reaches across a crease.

    Parameters
    ----------
    V : (#V, 3) array_like, F : (#F, 3) array_like of int
    radius : int, default 5, as :func:`igl_hhj.principal_curvature`.
    feature_angle : float or None, default 40
        Crease threshold in degrees (:func:`crease_edges`); None: only ``crease_edges``.
    crease_edges : (k, 2) array_like of int, optional, creases named by vertex pairs.
    boundary : "estimate" (the only treatment with features).
    solver, rtol : as :func:`igl_hhj.shape_operator`.

    Returns
    -------
    FeatureCurvature

    Examples
    --------
    >>> import igl_hhj.features as ft
    >>> from igl_hhj.surfaces.creased import capped_cylinder
    >>> V, F, _ = capped_cylinder(2)            # R = 1: H = 1/2 on the side, 0 on the caps
    >>> r = ft.feature_principal_curvature(V, F)
    >>> r.creases.n_chains, len(r.creases.corners)   # the two rims, no corners
    (2, 0)
    >>> rim = r.creases.edges[0, 0]                  # a rim vertex has two sides
    >>> sides = (r.side_parent == rim).nonzero()[0]
    >>> sorted(round(abs(float(h)), 1) for h in r.side_mean_curvature[sides])
    [0.0, 0.5]
    """
    mesh, (crease, theta), cut, cm, (sPD1, sPD2, sPV1, sPV2, sbad) = _side_values(
        V, F, radius, feature_angle, crease_edges, boundary, solver, rtol, _data)
    nV = mesh.n_vertices
    bad = [b for b in sbad if b < nV]
    return FeatureCurvature(
        PD1=np.ascontiguousarray(sPD1[:nV]), PD2=np.ascontiguousarray(sPD2[:nV]),
        PV1=np.ascontiguousarray(sPV1[:nV]), PV2=np.ascontiguousarray(sPV2[:nV]), bad_vertices=bad,
        side_PD1=sPD1, side_PD2=sPD2, side_PV1=sPV1, side_PV2=sPV2, side_parent=cut.parent,
        side_normals=cm.vertex_normals, cut=cut, creases=crease_network(mesh, crease, theta))


def _side_values(V, F, radius, feature_angle, crease_edges, boundary, solver, rtol, data):
    """The drop-in's pipeline on the cut mesh: per-side (PD1, PD2, PV1, PV2, bad)."""
    from . import curvature
    from .solvers import DEFAULT_RTOL
    curvature.check_principal_curvature_args(radius, True)
    mesh, ct, cut, cm = _prepare(V, F, feature_angle, crease_edges, boundary, data)
    # the smoothing: one call per side, each side's stopping test in the units of the
    # caller's connected part that it belongs to (intrinsic.adaptive_smoothing_by_parts)
    parts = kernels.vertex_components(mesh)[0][cut.parent]
    return mesh, ct, cut, cm, curvature.dropin_on_mesh(cm, radius, "estimate", None, None, None, solver,
                                                       DEFAULT_RTOL if rtol is None else rtol,
                                                       groups_of=mesh, by_parts=parts)


def _feature_dropin(V: Any, F: ArrayLike | None, radius: int, *, feature_angle: float | None,
                   crease_edges: ArrayLike | None = None, boundary: str = "estimate", solver: str = "auto",
                   rtol: float | None = None, data=()) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                                     NDArray[np.float64], list[int]]:
    """``principal_curvature(..., feature_angle=...)``: the primary sides' values only
    (:func:`feature_principal_curvature` without the crease network)."""
    mesh, _, _, _, (PD1, PD2, PV1, PV2, bad) = _side_values(
        V, F, radius, feature_angle, crease_edges, boundary, solver, rtol, data)
    nV = mesh.n_vertices
    return (np.ascontiguousarray(PD1[:nV]), np.ascontiguousarray(PD2[:nV]),
            np.ascontiguousarray(PV1[:nV]), np.ascontiguousarray(PV2[:nV]), [b for b in bad if b < nV])
