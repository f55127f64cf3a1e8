"""What a triangle mesh is made of, and whether igl_hhj accepts it (``igl-hhj info``).

:func:`mesh_report` computes the statistics with libigl functions that
tolerate the meshes :class:`igl_hhj.mesh.TriangleMesh` rejects (non-manifold
edges and vertices, zero-area faces, inconsistent orientation, duplicate
faces), then asks ``TriangleMesh`` for the verdict and keeps its exact message.

Topology
--------
With ``V_c, E_c, F_c`` the referenced vertices, unique edges and faces of a
connected component (faces connected through edges, ``igl.facet_components``)
and ``b_c`` its boundary loops, the Euler characteristic is
``χ_c = V_c - E_c + F_c`` and, for an orientable 2-manifold component,
``genus_c = (2 - χ_c - b_c) / 2``.  The genus is reported (summed over the
components) only when the mesh is edge- and vertex-manifold, has no face with
a repeated vertex, and every component is orientable (``igl.bfs_orient``
finds a consistent orientation); otherwise the report says why it is
undefined.

Repairs
-------
A mesh refused for a repairable defect (:class:`igl_hhj.mesh.MeshDefectError`)
is run through :func:`igl_hhj.repair.repair_mesh`, as the drop-in
``principal_curvature`` would: ``repairs`` holds its counts per kind and the
report line names them, and whether the repaired mesh is then accepted.

Boundary loops are the connected components of the graph of boundary edges
(``scipy.sparse.csgraph``), which stays correct on inconsistently oriented or
non-orientable meshes where ``igl.boundary_loop_all`` (it follows half-edge
directions) returns wrong loops; on valid meshes the two agree (tested).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

import warnings

from .mesh import MeshDefectError, MeshWarning, TriangleMesh, zero_area_faces

if TYPE_CHECKING:
    from .polygon_io import PolygonSplit

__all__ = ["MeshReport", "mesh_report"]


@dataclass
class MeshReport:
    """Statistics of a triangle mesh and igl_hhj's verdict on it.

    Counts are None when the face array could not be analysed (wrong shape,
    out-of-range indices); ``topology_note`` then says why.
    """

    n_vertices: int
    n_faces: int
    accepted: bool
    reason: str = ""
    topology_note: str = ""
    n_edges: int | None = None
    n_unreferenced: int | None = None
    n_components: int | None = None
    n_boundary_edges: int | None = None
    boundary_loop_lengths: list = field(default_factory=list)
    euler_characteristic: int | None = None
    component_euler: list = field(default_factory=list)
    genus: int | None = None
    component_genus: list = field(default_factory=list)
    genus_note: str = ""
    edge_manifold: bool | None = None
    n_nonmanifold_edges: int | None = None
    vertex_manifold: bool | None = None
    n_nonmanifold_vertices: int | None = None
    consistently_oriented: bool | None = None
    n_misoriented_edges: int | None = None
    orientable: bool | None = None
    n_zero_area_faces: int | None = None
    n_repeated_vertex_faces: int | None = None
    n_duplicate_faces: int | None = None
    n_two_sided_faces: int | None = None
    bbox: tuple | None = None
    mean_edge_length: float | None = None
    repairs: dict | None = None
    repair_note: str = ""
    polygons: dict | None = None
    polygon_note: str = ""

    @property
    def n_quads_split(self) -> int:
        """Quads of the file split into two triangles each (0 when not read from a file)."""
        return int((self.polygons or {}).get(4, 0))

    def lines(self):
        """The report as text lines (``igl-hhj info`` prints them)."""
        yn = {True: "yes", False: "no", None: "not analysed"}
        out = [f"vertices          {self.n_vertices}"
               + ("" if self.n_unreferenced is None else f" ({self.n_unreferenced} unreferenced)"),
               f"faces             {self.n_faces}"]
        if self.polygon_note:
            out.append(f"polygons          {self.polygon_note}")
        if self.n_edges is None:
            out.append(f"topology          not analysed: {self.topology_note}")
        else:
            loops = self.boundary_loop_lengths
            shown = ", ".join(map(str, loops[:10])) + (", ..." if len(loops) > 10 else "")
            out += [
                f"edges             {self.n_edges} ({self.n_boundary_edges} on the boundary)",
                f"components        {self.n_components}",
                f"boundary loops    {len(loops)}" + (f" (edges per loop: {shown})" if loops else ""),
                f"Euler char.       {self.euler_characteristic}"
                + (f" (per component: {', '.join(map(str, self.component_euler))})"
                   if 1 < len(self.component_euler) <= 10 else ""),
                "genus             " + (
                    f"{self.genus}" + (f" (per component: {', '.join(map(str, self.component_genus))})"
                                       if 1 < len(self.component_genus) <= 10 else "")
                    if self.genus is not None else f"not defined: {self.genus_note}"),
                f"edge-manifold     {yn[self.edge_manifold]}"
                + (f" ({self.n_nonmanifold_edges} edges with more than two faces)"
                   if self.n_nonmanifold_edges else ""),
                f"vertex-manifold   {yn[self.vertex_manifold]}"
                + (f" ({self.n_nonmanifold_vertices} non-manifold vertices)"
                   if self.n_nonmanifold_vertices else ""),
                "orientation       " + (
                    f"ambiguous ({self.n_two_sided_faces} faces also given reversed: a two-sided "
                    f"sheet has no outside, the sign of its curvature is undefined)"
                    if self.n_two_sided_faces else "consistent" if self.consistently_oriented else
                    f"inconsistent ({self.n_misoriented_edges} edges traversed "
                    f"twice in the same direction)")
                + {True: ", orientable", False: ", non-orientable", None: ""}[self.orientable],
                "degenerate faces  " + (f"{self.n_zero_area_faces} zero-area or sliver, " if self.n_zero_area_faces
                                        is not None else "zero-area not checked (non-finite coordinates), ")
                + f"{self.n_repeated_vertex_faces} with a repeated vertex",
                f"duplicate faces   {self.n_duplicate_faces}",
            ]
        if self.bbox is not None:
            lo, hi = self.bbox
            out.append("bounding box      [" + ", ".join(f"{x:.4g}" for x in lo) + "] - ["
                       + ", ".join(f"{x:.4g}" for x in hi) + "]")
        if self.mean_edge_length is not None:
            out.append(f"mean edge length  {self.mean_edge_length:.4g}")
        out.append("drop-in repairs   " + ("none needed" if self.accepted else self.repair_note))
        out.append("verdict           " + ("accepted by igl_hhj" if self.accepted
                                           else f"rejected: {self.reason}"))
        return out


def _misoriented(E, uE, EMAP, count):
    """(#E,) bool: interior (2-face) edges not traversed once in each direction."""
    forward = E[:, 0] == uE[EMAP, 0]
    n_forward = np.bincount(EMAP, weights=forward, minlength=len(uE))
    return (count == 2) & (n_forward != 1)


def _repairs(V, F, defect):
    """(summary or None, report text): what the drop-in's repair does to a refused mesh."""
    if defect is None:
        return None, "none possible (the drop-in refuses it too)"
    from .repair import repair_mesh
    try:
        R = repair_mesh(V, F)
    except (ValueError, TypeError) as exc:
        return None, f"none possible (the drop-in refuses it: {exc})"
    text = R.describe()
    had = np.zeros(len(V), dtype=bool)
    had[np.asarray(F, dtype=np.int64).ravel()] = True
    had[R.vertex_map] = False
    if had.any():
        text += f"; {int(had.sum())} vertices left without a face (NaN)"
    if not len(R.F):
        return R.summary, text + "; no face left: principal_curvature gives NaN everywhere"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshWarning)      # split seams coincide on purpose
            TriangleMesh(R.V, R.F)
    except (ValueError, TypeError) as exc:
        return R.summary, text + f"; the repaired mesh is still refused: {exc}"
    return R.summary, text + ("; principal_curvature computes on the repaired mesh, the strict "
                              "functions refuse it unless repair=True")


def _two_sided_faces(F):
    """(#F,) bool: faces whose three vertices are also given in the opposite orientation
    (the parity of the permutation that sorts the corners differs)."""
    if len(F) == 0:
        return np.zeros(0, dtype=bool)
    _, inverse = np.unique(np.sort(F, axis=1), axis=0, return_inverse=True)
    inverse = np.asarray(inverse).ravel()
    a, b, c = F.T
    odd = ((a > b).astype(np.int8) + (a > c) + (b > c)) % 2 == 1
    n = int(inverse.max()) + 1
    both = (np.bincount(inverse, weights=odd, minlength=n) > 0) & (np.bincount(inverse, weights=~odd, minlength=n) > 0)
    return both[inverse]


def mesh_report(V: Any, F: Any, split: PolygonSplit | None = None) -> MeshReport:
    """Analyse ``(V, F)`` without requiring a valid mesh.

    Parameters
    ----------
    V : (#V, 3) float array
    F : (#F, k) integer array as read from a file (k = 3 for triangles)
    split : igl_hhj.polygon_io.PolygonSplit, optional
        The file's polygons before they were split (:attr:`igl_hhj.mesh_io.MeshFile.split`):
        ``polygons`` ({corners: count}), ``n_quads_split`` and the "polygons" line
        ("12 quads split into 24 triangles ...") report it.

    Returns
    -------
    MeshReport
    """
    import igl
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    V = np.asarray(V)
    F = np.asarray(F)
    defect = None
    try:
        TriangleMesh(V, F)
        accepted, reason = True, ""
    except MeshDefectError as exc:
        accepted, reason, defect = False, str(exc), exc
    except (ValueError, TypeError) as exc:
        accepted, reason = False, str(exc)
    nV, nF = len(V), len(F)
    rep = MeshReport(n_vertices=nV, n_faces=nF, accepted=accepted, reason=reason)
    if split is not None:
        rep.polygons = dict(split.corners)
        rep.polygon_note = split.describe()
    if not accepted:
        rep.repairs, rep.repair_note = _repairs(V, F, defect)
    if V.ndim == 2 and V.shape[1] == 3 and nV and np.isfinite(V).all():
        rep.bbox = (V.min(axis=0), V.max(axis=0))
    if F.ndim != 2 or F.shape[1] != 3 or not np.issubdtype(F.dtype, np.integer):
        rep.topology_note = f"faces are not triangles (shape {F.shape}, dtype {F.dtype})"
        return rep
    if nF == 0 or F.min() < 0 or F.max() >= nV:
        rep.topology_note = "no faces or face indices out of range"
        return rep
    F = np.ascontiguousarray(F, dtype=np.int64)
    referenced = np.zeros(nV, dtype=bool)
    referenced[F.ravel()] = True
    rep.n_unreferenced = int(nV - referenced.sum())

    E, uE, EMAP, uEC, _ = igl.unique_edge_map(F)
    nE = len(uE)
    count = np.diff(uEC)
    boundary = count == 1
    rep.n_edges, rep.n_boundary_edges = nE, int(boundary.sum())
    rep.edge_manifold = bool(igl.is_edge_manifold(F)[0])
    rep.n_nonmanifold_edges = int((count > 2).sum())
    vm = np.ones(nV, dtype=bool)
    B = np.asarray(igl.is_vertex_manifold(F), dtype=bool)
    vm[:len(B)] = B
    bad_v = referenced & ~vm
    rep.vertex_manifold, rep.n_nonmanifold_vertices = not bad_v.any(), int(bad_v.sum())
    mis = _misoriented(E, uE, EMAP, count)
    rep.consistently_oriented, rep.n_misoriented_edges = not mis.any(), int(mis.sum())

    repeated = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
    rep.n_repeated_vertex_faces = int(repeated.sum())
    if np.isfinite(V).all():
        X = V[F].astype(np.float64)
        dbl = np.asarray(igl.doublearea(np.ascontiguousarray(V, dtype=np.float64), F)).ravel()
        zero = zero_area_faces(X[:, [2, 0, 1]] - X[:, [1, 2, 0]], dbl)
        rep.n_zero_area_faces = int((zero & ~repeated).sum())
        rep.mean_edge_length = float(np.linalg.norm(V[uE[:, 1]] - V[uE[:, 0]], axis=1).mean())
    rep.n_duplicate_faces = int(nF - len(igl.unique_simplices(F)[0]))
    rep.n_two_sided_faces = int(_two_sided_faces(F).sum())

    # components, boundary loops, Euler characteristic per component
    n_comp, C = igl.facet_components(F)
    rep.n_components = int(n_comp)
    edge_face = np.empty(nE, dtype=np.int64)
    edge_face[EMAP] = np.arange(3 * nF) % nF          # any incident face: same component
    Ec = np.bincount(C[edge_face], minlength=n_comp)
    Fc = np.bincount(C, minlength=n_comp)
    pairs = np.unique(C[:, None] * nV + F)             # (component, vertex) pairs
    Vc = np.bincount(pairs // nV, minlength=n_comp)
    bE = uE[boundary]
    if len(bE):
        G = coo_matrix((np.ones(len(bE)), (bE[:, 0], bE[:, 1])), shape=(nV, nV))
        _, lab = connected_components(G, directed=False)
        loop_ids, loop_edges = np.unique(lab[bE[:, 0]], return_counts=True)
        order = np.argsort(-loop_edges, kind="stable")
        rep.boundary_loop_lengths = loop_edges[order].tolist()
        # component of each loop: that of a face on one of its edges
        first_edge = np.full(lab.max() + 1, -1)
        first_edge[lab[bE[::-1, 0]]] = np.flatnonzero(boundary)[::-1]
        bc = np.bincount(C[edge_face[first_edge[loop_ids]]], minlength=n_comp)
    else:
        bc = np.zeros(n_comp, dtype=np.int64)
    chi_c = Vc - Ec + Fc
    rep.component_euler = chi_c.tolist()
    rep.euler_characteristic = int(referenced.sum() - nE + nF)

    reasons = []
    if not rep.edge_manifold:
        reasons.append("not edge-manifold")
    if not rep.vertex_manifold:
        reasons.append("not vertex-manifold")
    if rep.n_repeated_vertex_faces:
        reasons.append("faces with a repeated vertex")
    if not reasons:
        FF = igl.bfs_orient(F)[0]
        E2, uE2, EMAP2, uEC2, _ = igl.unique_edge_map(FF)
        rep.orientable = not _misoriented(E2, uE2, EMAP2, np.diff(uEC2)).any()
        if not rep.orientable:
            reasons.append("non-orientable")
    if reasons:
        rep.genus_note = " and ".join(reasons)
    else:
        g2 = 2 - chi_c - bc
        rep.component_genus = (g2 // 2).tolist()
        rep.genus = int(g2.sum() // 2)
    return rep
