"""Mesh repair for the drop-in: turn a mesh that libigl accepts but
:class:`igl_hhj.mesh.TriangleMesh` refuses into one it accepts, and map the
results back to the caller's vertices and faces.

The strict functions keep refusing such meshes; :func:`igl_hhj.principal_curvature`
(and :func:`igl_hhj.shape_operator`, :func:`igl_hhj.surface_hessian` with
``repair=True``) call :func:`repair_mesh` only after the strict validation has
failed with a repairable :class:`igl_hhj.mesh.MeshDefectError`, so a clean mesh
does no extra work.

Repairs, in this order (all vectorised; loops run over components only)
----------------------------------------------------------------------
1. Faces with a repeated corner are dropped.
2. Degenerate faces (zero area, or relative area ≤ ``DEGENERATE_AREA_RTOL``,
   the criterion of :func:`igl_hhj.mesh.zero_area_faces`) are dropped.
3. Duplicate faces (the same three vertices in any order, so reversed
   duplicates too) are dropped but the first of each set.  A patch whose every
   face was given in both orientations (a two-sided sheet) has no orientation:
   the sign of its curvature is undefined, its faces are flagged
   (:attr:`RepairedMesh.two_sided`) and the drop-in gives its vertices no value.
4. Each patch of faces connected through edges with exactly two faces is
   oriented consistently (``igl.bfs_orient``), then flipped as a whole when
   the caller's orientation of that patch disagrees on more than half its
   area: the signs of the results are those the caller's majority orientation
   gives.  A patch that ``bfs_orient`` cannot make consistent (non-orientable:
   a Möbius band) is removed; its vertices get no value unless another face
   uses them.
5. Non-manifold edges and vertices are split (``igl.split_nonmanifold``): a
   caller vertex may get several copies in the repaired mesh.

Per-vertex values on the repaired mesh go back to the caller's rows with
:func:`vertex_values_to_caller` (a split vertex takes the copy with the largest
incident area; a caller vertex without a copy gets NaN); per-face values with
:func:`face_values_to_caller` (dropped faces get NaN, the caller's F order).
"""
from __future__ import annotations

import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .mesh import MeshWarning, check_mesh_size, validate_faces, validate_vertices, zero_area_faces
from .mesh_objects import mesh_arrays

__all__ = ["RepairedMesh", "repair_mesh", "vertex_values_to_caller", "face_values_to_caller",
           "REPAIR_KINDS"]

REPAIR_KINDS = ("repeated corner", "degenerate", "duplicate", "two-sided", "flipped", "non-orientable",
                "non-manifold")
"""Keys of :attr:`RepairedMesh.summary`, in the order of the repairs."""

@dataclass(frozen=True)
class RepairedMesh:
    """A repaired mesh and the maps back to the caller's mesh.

    Attributes
    ----------
    V : (#V2, 3) float64
        Vertex positions of the repaired mesh (only referenced vertices).
    F : (#F2, 3) int64
        Faces of the repaired mesh: a subset of the caller's faces, in the
        caller's order, some with reversed orientation.  Passes
        :class:`igl_hhj.mesh.TriangleMesh`'s validation.
    vertex_map : (#V2,) int64
        ``vertex_map[i]`` is the caller's vertex of repaired vertex ``i``.
    face_map : (#F2,) int64
        ``face_map[j]`` is the caller's face of repaired face ``j`` (increasing).
    n_vertices, n_faces : int
        The caller's #V and #F.
    summary : dict str -> int
        Counts per kind (:data:`REPAIR_KINDS`): faces dropped with a repeated
        corner, degenerate, duplicate; faces whose orientation was reversed
        ("flipped"); faces removed in non-orientable patches; extra vertex
        copies made by splitting non-manifold edges / vertices ("non-manifold");
        faces of two-sided patches, whose orientation is undefined ("two-sided").
    two_sided : (#F2,) bool or None
        Faces of a patch whose every face was given in both orientations: the sign
        of anything computed there is undefined (None: no such face).
    """
    V: np.ndarray
    F: np.ndarray
    vertex_map: np.ndarray
    face_map: np.ndarray
    n_vertices: int
    n_faces: int
    summary: dict = field(default_factory=dict)
    two_sided: Any = None

    @property
    def repaired(self):
        """True when anything was changed."""
        return any(self.summary.values())

    def describe(self):
        """One line naming what was repaired, e.g. ``"2 duplicate faces dropped, ..."``."""
        s = self.summary
        words = {
            "repeated corner": "faces with a repeated corner dropped",
            "degenerate": "degenerate (zero-area or sliver) faces dropped",
            "duplicate": "duplicate faces dropped (reversed duplicates included)",
            "two-sided": "faces of two-sided patches (each face given in both orientations: the sign "
                         "of the curvature is undefined there, their vertices get no value)",
            "flipped": "faces re-oriented to the majority orientation of their patch",
            "non-orientable": "faces of non-orientable (Möbius) patches removed",
            "non-manifold": "vertex copies made to split non-manifold edges/vertices",
        }
        parts = [f"{s[k]} {words[k]}" for k in REPAIR_KINDS if s.get(k)]
        return "; ".join(parts) if parts else "nothing repaired"


def _double_areas(V, F):
    X = V[F]
    c = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    return np.sqrt(np.einsum("fa,fa->f", c, c)), X


def _same_cycle(A, B):
    """(n,) bool: row A[i] is a cyclic rotation of row B[i] (same vertices, same orientation)."""
    out = np.zeros(len(A), dtype=bool)
    for k in range(3):                      # the three rotations, vectorised over faces
        out |= (A[:, 0] == B[:, k]) & (A[:, 1] == B[:, (k + 1) % 3])
    return out


def _row_keys(A, n):
    """(m,) int64 keys of the rows of A (m, k), entries in [0, n), ordered as the rows are
    lexicographically (``Σ_j A[:, j] n^(k-1-j)``), or None when n^k would overflow int64:
    ``np.unique`` of the keys is the row-``np.unique`` (``axis=0``) without its structured
    sort (armadillo's 86k faces: 50 ms → 10 ms)."""
    k = A.shape[1]
    if n ** k >= 2 ** 62:
        return None
    key = np.zeros(len(A), dtype=np.int64)
    for j in range(k):
        key = key * n + A[:, j]
    return key


def _unique_rows(A, n, **kwargs):
    """``np.unique(A, axis=0, **kwargs)`` without the unique rows themselves (the index,
    inverse and count arrays asked for, in that order), through :func:`_row_keys`."""
    key = _row_keys(A, n)
    out = np.unique(A if key is None else key, axis=0 if key is None else None, **kwargs)
    return out[1:]


def _inconsistent_faces(F, n=None):
    """(#F,) bool: faces on an edge with exactly two faces that traverse it in the same direction
    (``n``: a bound on the vertex indices, default ``F.max() + 1``).  The edge maps are the
    compiled :func:`igl_hhj.kernels.topology` pass, the test that of
    :class:`igl_hhj.mesh.TriangleMesh` (no face may repeat a corner here)."""
    from . import kernels
    n = int(F.max()) + 1 if n is None else n
    _, face_edges, count, _, _, sign = kernels.topology(F, n)
    pos = np.bincount(face_edges.ravel(), weights=sign.ravel() > 0, minlength=len(count))
    bad_edge = (count == 2) & (pos != 1)
    return bad_edge[face_edges].any(axis=1)


def repair_mesh(V: Any, F: Any) -> RepairedMesh:
    """Repair the defects that :class:`igl_hhj.mesh.TriangleMesh` refuses and libigl accepts.

    Parameters
    ----------
    V : (#V, 3) array_like of float
        Vertex positions (validated as by :class:`~igl_hhj.mesh.TriangleMesh`:
        finite, bounded).
    F : (#F, 3) array_like of int
        Triangles; faces with a repeated corner are allowed.  Never reordered.

    Returns
    -------
    RepairedMesh
        The repaired ``(V, F)``, the maps to the caller's vertices and faces and
        the counts of each repair (see the module docstring for the repairs).
        Its ``F`` may be empty (every face dropped).

    Raises
    ------
    TypeError, ValueError
        Defects that are not repaired: wrong shapes or dtypes, empty arrays,
        NaN/inf or huge coordinates, negative or out-of-range indices.

    Examples
    --------
    >>> import numpy as np
    >>> from igl_hhj.surfaces import icosphere
    >>> V, F = icosphere(1)
    >>> R = repair_mesh(V, np.vstack([F, F[:2, ::-1]]))      # two reversed duplicates
    >>> R.F.shape, R.summary["duplicate"]
    ((80, 3), 2)
    """
    import igl
    V = validate_vertices(V)
    F = validate_faces(F, V.shape[0], repeated_ok=True)
    nV, nF = V.shape[0], F.shape[0]
    summary = dict.fromkeys(REPAIR_KINDS, 0)

    # 1.-2. faces with a repeated corner, degenerate faces
    repeated = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
    dbl, X = _double_areas(V, F)
    ev = np.stack([X[:, 2] - X[:, 1], X[:, 0] - X[:, 2], X[:, 1] - X[:, 0]], axis=1)
    with np.errstate(over="ignore", invalid="ignore"):
        check_mesh_size((ev ** 2).sum(axis=2).max(axis=1))      # "too small", not every face dropped
    degenerate = zero_area_faces(ev, dbl) & ~repeated
    keep = ~(repeated | degenerate)
    summary["repeated corner"] = int(repeated.sum())
    summary["degenerate"] = int(degenerate.sum())

    # 3. duplicates (any vertex order): keep the first of each set; a set given in both
    # orientations (the parity of the permutation that sorts the corners) is two-sided
    idx = np.flatnonzero(keep)
    two_sided = np.zeros(nF, dtype=bool)
    if len(idx):
        first, inverse = _unique_rows(np.sort(F[idx], axis=1), nV, return_index=True, return_inverse=True)
        inverse = np.asarray(inverse).ravel()
        a, b, c = F[idx].T
        odd = ((a > b).astype(np.int8) + (a > c) + (b > c)) % 2 == 1
        both = (np.bincount(inverse, weights=odd, minlength=len(first)) > 0) & \
               (np.bincount(inverse, weights=~odd, minlength=len(first)) > 0)
        two_sided[idx] = both[inverse]
        dup = np.ones(len(idx), dtype=bool)
        dup[first] = False
        summary["duplicate"] = int(dup.sum())
        keep[idx[dup]] = False
    idx = np.flatnonzero(keep)
    if len(idx) == 0:
        return RepairedMesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64),
                            np.zeros(0, dtype=np.int64), idx, nV, nF, summary)

    # 4. orientation per patch (edges with two faces), majority of the caller's orientation.
    # Where every such edge is already traversed both ways, bfs_orient would return the faces
    # as they are (it flips a face only against a neighbour): skip it (armadillo with one
    # non-manifold face: 0.11 s; a voxel soup of 85k patches: 1 s)
    Fk = F[idx]
    ts = two_sided[idx]
    if not ts.any() and not _inconsistent_faces(Fk, nV).any():
        O = Fk.copy()
    else:
        O, C = igl.bfs_orient(Fk)
        O = np.asarray(O, dtype=np.int64)
        C = np.asarray(C, dtype=np.int64).ravel()
        nC = int(C.max()) + 1
        flipped = ~_same_cycle(O, Fk)
        w = dbl[idx] * ~ts                              # a two-sided face votes for neither side
        flip_area = np.bincount(C, weights=w * flipped, minlength=nC)
        total = np.bincount(C, weights=w, minlength=nC)
        back = flip_area > 0.5 * total                  # the caller's majority says the other way
        ts = (total == 0)[C]                            # no face says which side is out: undefined
        O[back[C]] = O[back[C]][:, ::-1]
        bad_comp = np.zeros(nC, dtype=bool)
        bad_comp[C[_inconsistent_faces(O, nV)]] = True  # bfs_orient could not make it consistent
        good = ~bad_comp[C]
        summary["non-orientable"] = int((~good).sum())
        summary["flipped"] = int((~_same_cycle(O, Fk) & good).sum())
        O, idx, ts = O[good], idx[good], ts[good]
    summary["two-sided"] = int(ts.sum())
    if len(idx) == 0:
        return RepairedMesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64),
                            np.zeros(0, dtype=np.int64), idx, nV, nF, summary)

    # 5. split non-manifold edges and vertices (orientation and face order are kept)
    SV, SF, SVI = igl.split_nonmanifold(V, O)
    SF = np.asarray(SF, dtype=np.int64)
    SVI = np.asarray(SVI, dtype=np.int64).ravel()
    used = np.zeros(len(SVI), dtype=bool)
    used[SF.ravel()] = True
    if not used.all():                                  # keep referenced vertices only
        new = np.cumsum(used) - 1
        SF, SVI = new[SF], SVI[used]
    n_ref = len(np.unique(O))
    summary["non-manifold"] = int(len(SVI) - n_ref)
    V2 = np.ascontiguousarray(V[SVI])                   # exact caller coordinates
    return RepairedMesh(V2, np.ascontiguousarray(SF), SVI, idx, nV, nF, summary, ts if ts.any() else None)


def two_sided_vertices(repaired):
    """(#V2,) bool: the repaired mesh's vertices on a face of a two-sided patch
    (:attr:`RepairedMesh.two_sided`), whose curvature has no defined sign."""
    R = repaired
    out = np.zeros(len(R.vertex_map), dtype=bool)
    if R.two_sided is not None:
        out[R.F[R.two_sided].ravel()] = True
    return out


def vertex_values_to_caller(repaired, *arrays):
    """Map per-vertex arrays on the repaired mesh back to the caller's ``#V`` rows.

    Parameters
    ----------
    repaired : RepairedMesh
    *arrays : (#V2, ...) arrays on ``repaired.V``

    Returns
    -------
    tuple of (#V, ...) float64 arrays.  A caller vertex split into several
    copies takes the row of the copy with the largest incident area (sum of
    its faces' areas in the repaired mesh), among the copies whose rows are
    finite in every array when there are any; a caller vertex without a copy
    (unreferenced, or only on dropped / removed faces) gets NaN.  The same copy
    is used for all arrays.
    """
    R = repaired
    nV2 = len(R.vertex_map)
    out = [np.full((R.n_vertices,) + np.shape(a)[1:], np.nan) for a in arrays]
    if nV2 == 0:
        return tuple(out)
    dbl, _ = _double_areas(R.V, R.F)
    area = np.bincount(R.F.ravel(), weights=np.repeat(dbl, 3), minlength=nV2)
    finite = np.ones(nV2, dtype=bool)
    for a in arrays:
        finite &= np.isfinite(np.asarray(a, dtype=np.float64).reshape(nV2, -1)).all(axis=1)
    # sort by caller vertex, then finite, then area: the last of each group wins
    order = np.lexsort((area, finite, R.vertex_map))
    vm = R.vertex_map[order]
    last = np.ones(nV2, dtype=bool)
    last[:-1] = vm[1:] != vm[:-1]
    pick = order[last]
    for o, a in zip(out, arrays):
        o[R.vertex_map[pick]] = np.asarray(a, dtype=np.float64)[pick]
    return tuple(out)


def face_values_to_caller(repaired, *arrays):
    """Map per-face arrays on the repaired mesh to the caller's ``#F`` rows, NaN
    for dropped or removed faces (the caller's F order).  Returns a tuple."""
    R = repaired
    out = []
    for a in arrays:
        a = np.asarray(a, dtype=np.float64)
        o = np.full((R.n_faces,) + a.shape[1:], np.nan)
        o[R.face_map] = a
        out.append(o)
    return tuple(out)


# --------------------------------------------------------------------------- the pipeline's repair stage
PER_VERTEX_KWARGS = ("w", "boundary_normals", "boundary_shape_operator", "simply_supported",
                     "boundary_gradient")
"""The arguments of the public functions that hold per-vertex data (the values ``w`` of
:func:`igl_hhj.surface_hessian` and the boundary data), mapped to the repaired vertices by
:func:`map_vertex_kwargs`."""


def caller_arrays(V, F):
    """The caller's ``(V, F)``: the arrays, or those of a mesh object given alone (``F`` None)."""
    if F is None:
        arrays = mesh_arrays(V)
        if arrays is None:
            raise TypeError("F is required unless V is a TriangleMesh or a mesh object "
                            "(trimesh.Trimesh, pyvista.PolyData, meshio.Mesh)")
        return arrays
    return V, F


def vertex_rows(R, x, name):
    """The rows of per-vertex data ``x`` (#V, ...) for the repaired mesh's vertices."""
    x = np.asarray(x)
    if x.ndim == 0 or x.shape[0] != R.n_vertices:
        raise ValueError(f"{name} must have one row per vertex (#V = {R.n_vertices}), "
                         f"got shape {x.shape}")
    return x[R.vertex_map]


def map_vertex_kwargs(R, kwargs):
    """``kwargs`` with its per-vertex entries (:data:`PER_VERTEX_KWARGS`, when not None)
    restricted to the repaired mesh's vertices (:func:`vertex_rows`)."""
    kw = dict(kwargs)
    for name in PER_VERTEX_KWARGS:
        if kw.get(name) is not None:
            kw[name] = vertex_rows(R, kw[name], name)
    return kw


@contextmanager
def seams_not_warned():
    """The computation on a repaired mesh: its split vertices coincide on purpose, so the
    unwelded-seam :class:`~igl_hhj.mesh.MeshWarning` is not given (the caller gets one
    warning, :func:`warn_repaired`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshWarning)
        yield


def warn_repaired(R, exc, what, F=None, stacklevel=2):
    """The one :class:`~igl_hhj.mesh.MeshWarning` of a repaired call: what was repaired
    (``exc``: why the mesh was refused) before computing ``what``; with the caller's ``F``,
    how many caller vertices lost every face."""
    lost = ""
    if F is not None:                       # caller vertices whose every face was dropped
        had = np.zeros(R.n_vertices, dtype=bool)
        had[np.asarray(F, dtype=np.int64).ravel()] = True
        had[R.vertex_map] = False
        if had.any():
            lost = f"; {int(had.sum())} vertices left without a face (NaN, in bad_vertices)"
    warnings.warn(f"the mesh was repaired before computing {what} (it was refused with: {exc}): "
                  f"{R.describe()}{lost}. Results are mapped back to the caller's rows; NaN rows are "
                  f"vertices (faces) left without a usable face. Repair the mesh yourself with "
                  f"igl_hhj.repair.repair_mesh to silence this", MeshWarning, stacklevel=stacklevel)
