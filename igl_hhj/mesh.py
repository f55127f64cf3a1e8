"""Mesh layer: a validated triangle mesh ``(V, F)`` and the quantities the
finite-element layers need, computed once and vectorised over all faces.

Conventions (libigl's, restated because every formula depends on them)
----------------------------------------------------------------------
* ``V`` is ``#V by 3`` float64, ``F`` is ``#F by 3`` int64; ``F`` is never
  reordered: its orientation carries the sign of the normal.
* Edge ``i`` of face ``T`` is the edge *opposite corner i*; it runs from
  ``x_{i+1}`` to ``x_{i+2}`` (indices mod 3).  This is the corner/edge order of
  ``igl.unique_edge_map``: ``EMAP[f + c*#F]`` is the unique edge opposite
  corner ``c`` of face ``f``, so ``EMAP.reshape(3, #F).T`` is the face→edge map.
* ``t_i`` = unit edge vector ``(x_{i+2} - x_{i+1}) / l_i``; ``ν_T`` = unit face
  normal of ``(x1 - x0) × (x2 - x0)``; ``n_i = t_i × ν_T`` is the unit
  *outward* conormal of edge ``i`` in the plane of ``T``;
  ``∇λ_i = -l_i n_i / (2|T|)`` is the gradient of the P1 hat function of
  corner ``i`` on ``T`` (Walker 2023, §4; design note hhj_lowest_order).

Input checks raise ``TypeError`` (wrong kind of array) or ``ValueError`` (bad
values), each naming the problem and the first offending index.  Unreferenced
vertices are allowed; per-vertex outputs of the library give them NaN (see the
individual functions).

Numerical-robustness policy (one set of limits for every solver)
-----------------------------------------------------------------
* A face is rejected as degenerate when ``2|T| ≤ DEGENERATE_AREA_RTOL ×
  (longest edge)²`` with ``DEGENERATE_AREA_RTOL = 1e-7``.  libigl's operators
  (``igl.cotmatrix``, ``igl.massmatrix``, used by the biharmonic solver, the
  baselines and the Regge layer) compute areas from edge lengths, whose
  relative error grows like ``ε/r²`` for a face of relative area ``r``: at
  ``r = 1e-7`` a cotangent weight is still good to ~1 %, at ``r = 1e-8`` it is
  off by ~100 % and below ``3e-9`` it is NaN (``tests/mesh/test_mesh.py::
  test_threshold_matches_libigl_precision`` measures this).
* Coordinates are bounded by ``COORDINATE_MAX = 1e75`` and the longest edge must
  be at least ``MIN_MESH_SIZE = 1e-60``: beyond that, squared areas in the
  solvers overflow or underflow float64 (measured: the PCG solve returns NaN
  at coordinates 1e78).  Curvature scales as 1/length, so rescale such meshes.
* Vertices whose incident faces' area-weighted normals cancel (two-sided or
  folded sheets, a flat closed "pillow" of two coincident fans, bow-ties with
  opposite wings) have no tangent plane: per-vertex outputs are NaN there and
  they are listed in ``bad_vertices`` (:func:`mark_bad_vertices`).
* :class:`TriangleMesh` holds read-only copies of ``V`` and ``F``: the arrays
  cannot change after validation.
* The topology maps are narrow (the memory of the drop-in's solve): edge, face and
  vertex indices in them are int32 (``edges``, ``face_edges``, ``edge_faces``), local
  indices, signs and counts int8 (``edge_local_index``, ``face_edge_sign``,
  ``edge_face_count``).  Indexing, ``np.bincount`` and scipy.sparse take them as they
  are; cast to int64 before arithmetic that can exceed 2³¹ (``3 * f + i``,
  ``edges[:, 0] * #V``).  A mesh needs fewer than 2³¹ vertices, faces and unique
  edges (else ``ValueError``).
"""
from __future__ import annotations

from functools import cached_property
from typing import Any

import warnings

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .constants import COORDINATE_MAX, DEGENERATE_AREA_RTOL, FOLDED_NORMAL_RTOL, MIN_MESH_SIZE
from .mesh_objects import mesh_arrays

__all__ = ["TriangleMesh", "validate_mesh", "as_mesh", "mark_bad_vertices", "MeshWarning", "MeshDefectError",
           "DEGENERATE_AREA_RTOL", "COORDINATE_MAX", "MIN_MESH_SIZE"]



class MeshWarning(UserWarning):
    """An accepted mesh that will probably not give what the user expects (e.g. unwelded)."""


class MeshDefectError(ValueError):
    """A ``ValueError`` for a topological or degenerate-face defect that
    :func:`igl_hhj.repair.repair_mesh` can repair (the drop-in repairs these).

    ``kind`` is one of ``"repeated corner"``, ``"degenerate"``, ``"non-manifold"``,
    ``"orientation"``.  Bad coordinates, shapes or indices stay plain ``ValueError``.
    """

    def __init__(self, message, kind):
        super().__init__(message)
        self.kind = kind


def zero_area_faces(edge_vectors, double_areas):
    """(#F,) bool: the faces igl_hhj rejects as degenerate.

    Parameters
    ----------
    edge_vectors : (#F, 3, 3) the three edge vectors of each face
    double_areas : (#F,) twice the face areas

    A face is degenerate when ``double_area ≤ DEGENERATE_AREA_RTOL × (longest
    edge)²`` (NaN or overflowed areas count as degenerate).  The one criterion behind
    :class:`TriangleMesh`'s check and ``igl-hhj info``'s count.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        l2max = (np.asarray(edge_vectors) ** 2).sum(axis=2).max(axis=1)
        return _zero_area(np.asarray(double_areas), l2max)


def check_mesh_size(squared_longest_edges):
    """Raise ``ValueError`` ("too small: rescale") when the mesh's longest edge is below
    :data:`MIN_MESH_SIZE`.

    Parameters
    ----------
    squared_longest_edges : (#F,) float64, each face's squared longest edge

    Below that size the squared cross products underflow to 0, so every face would look
    degenerate (:func:`zero_area_faces`): this check comes before that one, in
    :class:`TriangleMesh` and in :func:`igl_hhj.repair.repair_mesh`, else a repair would drop
    every face and return NaN everywhere.
    """
    l2 = np.asarray(squared_longest_edges)
    with np.errstate(invalid="ignore"):
        h = float(np.sqrt(np.nanmax(l2))) if l2.size and not np.isnan(l2).all() else np.inf
    if h < MIN_MESH_SIZE:
        raise ValueError(f"the mesh is too small: its longest edge is {h:.3g} < "
                         f"{MIN_MESH_SIZE:g} (squared areas underflow float64). Rescale it "
                         f"(curvature scales as 1/length: compute on s V, multiply by s)")


def _zero_area(dbl, l2max):
    """The criterion of :func:`zero_area_faces` from twice the areas and the squared longest edges."""
    with np.errstate(over="ignore", invalid="ignore"):
        return ~((dbl > DEGENERATE_AREA_RTOL * l2max) & np.isfinite(dbl) & np.isfinite(l2max))


def _as_array(x, name):
    if np.ma.is_masked(x):          # np.asarray would silently use the values under the mask
        raise ValueError(f"{name} is a masked array with {np.ma.count_masked(x)} masked entries: fill or drop them first")
    if isinstance(x, np.ndarray):
        return x
    try:
        return np.asarray(x)
    except Exception as exc:  # ragged lists etc.
        raise TypeError(f"{name} must be array-like, could not convert: {exc}") from None


def validate_vertices(V, name="V"):
    """Validate and coerce a vertex array.

    Parameters
    ----------
    V : (#V, 3) array_like of real numbers (float32/float64/int accepted)

    Returns
    -------
    V : (#V, 3) float64 C-contiguous numpy array (a copy if conversion was needed)
    """
    V = _as_array(V, name)
    if V.size == 0:
        raise ValueError(f"{name} is empty: the mesh has no vertices")
    if V.dtype == object or not (np.issubdtype(V.dtype, np.floating)
                                 or np.issubdtype(V.dtype, np.integer)):
        raise TypeError(f"{name} must hold real numbers, got dtype {V.dtype}" + (f": {name} is a {type(V.item()).__name__}; pass the mesh object alone (f(mesh), without F)" if V.ndim == 0 and (hasattr(V.item(), "faces") or hasattr(V.item(), "n_faces")) else ""))
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"{name} must have shape (#V, 3), got shape {V.shape}")
    if V.shape[0] == 0:
        raise ValueError(f"{name} is empty: the mesh has no vertices")
    V = np.ascontiguousarray(V, dtype=np.float64)
    m = np.abs(V).max()            # one reduction: NaN propagates, inf and huge values exceed
    if m <= COORDINATE_MAX:
        return V
    finite = np.isfinite(V).all(axis=1)
    if not finite.all():
        i = int(np.flatnonzero(~finite)[0])
        raise ValueError(f"{name} has NaN or inf coordinates; first at vertex {i}: {V[i]}")
    big = (np.abs(V) > COORDINATE_MAX).any(axis=1)
    if big.any():
        i = int(np.flatnonzero(big)[0])
        raise ValueError(f"{name} has coordinates beyond {COORDINATE_MAX:g} (squared areas would "
                         f"overflow float64); first at vertex {i}: {V[i]}. Rescale the mesh "
                         f"(curvature scales as 1/length: compute on V / s, divide the result by s)")
    return V


def validate_faces(F, nV, name="F", repeated_ok=False):
    """Validate and coerce a face array against ``nV`` vertices.

    ``repeated_ok``: accept faces with a repeated vertex (:mod:`igl_hhj.repair` drops them).

    Returns
    -------
    F : (#F, 3) int64 C-contiguous numpy array
    """
    F = _as_array(F, name)
    if F.size == 0:
        raise ValueError(f"{name} is empty: the mesh has no faces")
    if F.dtype == bool or not np.issubdtype(F.dtype, np.integer):
        raise TypeError(f"{name} must hold integer vertex indices, got dtype {F.dtype}")
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"{name} must have shape (#F, 3) (triangles), got shape {F.shape}")
    if np.issubdtype(F.dtype, np.unsignedinteger):
        bad = (F >= nV).any(axis=1)       # before the int64 cast (uint64 max would wrap to -1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{name} has out-of-range vertex indices (#V = {nV}); "
                             f"first at face {i}: {F[i].tolist()}")
    F = np.ascontiguousarray(F, dtype=np.int64)
    # two global reductions first; the per-face masks only to name the culprit
    if F.min() < 0:
        i = int(np.flatnonzero((F < 0).any(axis=1))[0])
        raise ValueError(f"{name} has negative vertex indices; first at face {i}: {F[i]} "
                         f"(indices are 0-based positions in V)")
    if F.max() >= nV:
        i = int(np.flatnonzero((F >= nV).any(axis=1))[0])
        raise ValueError(f"{name} has out-of-range vertex indices (#V = {nV}); "
                         f"first at face {i}: {F[i]}")
    if repeated_ok:
        return F
    bad = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise MeshDefectError(f"{name} has degenerate faces with a repeated vertex; "
                              f"first at face {i}: {F[i]}", "repeated corner")
    return F


class TriangleMesh:
    """A validated, consistently oriented, edge-manifold triangle mesh.

    Construction validates ``(V, F)`` completely (see module docstring);
    every derived quantity is a lazily computed, cached, read-only array with
    the element (face or edge) axis first.

    Parameters
    ----------
    V : (#V, 3) array_like
        Vertex positions (float32/float64 accepted; stored as float64).
    F : (#F, 3) array_like
        Triangle vertex indices (int32/int64 accepted; stored as int64).

    Raises
    ------
    TypeError
        Non-numeric ``V`` or non-integer ``F``.
    ValueError
        Wrong shapes, empty mesh, NaN/inf coordinates or coordinates beyond
        :data:`COORDINATE_MAX`, a mesh smaller than :data:`MIN_MESH_SIZE`,
        negative or out-of-range indices, repeated vertices in a face,
        degenerate faces (relative area ≤ :data:`DEGENERATE_AREA_RTOL`),
        non-manifold edges (more than two faces) or inconsistently oriented
        neighbouring faces.

    Warns
    -----
    MeshWarning
        Boundary vertices that coincide exactly with other boundary vertices
        (an unwelded mesh or triangle soup: its seams count as boundary).

    Notes
    -----
    The cached quantities, each computed on first use and then kept in the instance's
    ``__dict__`` (:data:`CACHED` lists them; ``tests/mesh/test_mesh.py`` keeps the list
    complete): the topology (``_topology``, one compiled pass, and its views ``edges``,
    ``face_edges``, ``edge_face_count``, ``face_edge_sign``, ``edge_faces``,
    ``edge_local_index``), the boundary (``boundary_edges``, ``boundary_vertices``,
    ``has_boundary``, ``boundary_loops``), ``referenced_vertices``, the face geometry
    (``_edge_vectors``, ``_cross``, ``face_double_areas``, ``face_areas``,
    ``face_normals``, ``edge_lengths``, ``unique_edge_lengths``, ``edge_tangents``,
    ``conormals``, ``barycentric_gradients``, ``mean_edge_length``, ``max_edge_length``)
    and the vertex normals (``vertex_normals``, ``folded_vertices``).

    Who fills or drops them besides first use: validation computes ``_cross`` and
    ``face_double_areas`` in one compiled pass and drops ``_edge_vectors`` (72 B/face,
    recomputed on demand); :meth:`release_face_cross_products` drops ``_cross``;
    :meth:`_same_faces` (the cut of :mod:`igl_hhj.creases`) starts with the face metrics
    of the mesh it cuts, :meth:`_with_topology` (:func:`igl_hhj.components.split_parts`)
    with its sliced edge maps.
    """

    CACHED = ("_topology", "edges", "face_edges", "edge_face_count", "face_edge_sign", "edge_faces",
              "edge_local_index", "boundary_edges", "boundary_vertices", "has_boundary", "boundary_loops",
              "referenced_vertices", "_edge_vectors", "_cross", "face_double_areas", "face_areas",
              "face_normals", "edge_lengths", "unique_edge_lengths", "edge_tangents", "conormals",
              "barycentric_gradients", "mean_edge_length", "max_edge_length", "vertex_normals",
              "folded_vertices")
    """The names of the cached quantities (see Notes)."""

    def __init__(self, V, F, *, copy=True):
        V = validate_vertices(V)
        F = validate_faces(F, V.shape[0])
        self._set_arrays(V, F, copy)
        self._check_degenerate()
        self._check_manifold_and_orientation()
        self._warn_unwelded()
        # the (#F, 3, 3) edge vectors are recomputed on demand (memory: 72 B/face)
        self.__dict__.pop("_edge_vectors", None)

    def _set_arrays(self, V, F, copy):
        """``self.V``, ``self.F`` read-only: nothing can change the arrays after validation.
        Copies, or with ``copy=False`` (a mesh private to one call, e.g. the drop-in's)
        read-only views of V and F when they already are C-contiguous float64 / int64
        (memory: 36 B/face less)."""
        self.V = np.array(V, dtype=np.float64, order="C", copy=None if not copy else True)
        self.F = np.array(F, dtype=np.int64, order="C", copy=None if not copy else True)
        if not copy:
            self.V, self.F = self.V.view(), self.F.view()
        self.V.setflags(write=False)
        self.F.setflags(write=False)

    @classmethod
    def _same_faces(cls, mesh, V, F):
        """A mesh of the faces of ``mesh`` with new vertex indices ``F`` into ``V``, built
        without the checks (internal: the caller guarantees that every row of ``F`` has the
        positions of the same row of ``mesh.F`` and that the result is an oriented
        edge-manifold mesh, as :func:`igl_hhj.creases.cut_along` does).  The per-face
        metrics of ``mesh`` are reused: they depend only on the corner positions."""
        self = cls.__new__(cls)
        self._set_arrays(V, F, copy=True)
        if self.F.shape != mesh.F.shape:
            raise ValueError(f"_same_faces: F must have the shape {mesh.F.shape}, got {self.F.shape}")
        for key in ("_cross", "face_double_areas", "face_areas", "face_normals", "edge_lengths"):
            if key in mesh.__dict__:
                self.__dict__[key] = mesh.__dict__[key]
        return self

    @classmethod
    def _with_topology(cls, V, F, edges, edge_faces, edge_local_index):
        """A mesh ``(V, F)`` with its unique edges and edge-face maps given, built without
        the checks (internal: :func:`igl_hhj.components.split_parts` slices them from a
        validated mesh; the arrays must be what :attr:`edges`, :attr:`edge_faces` and
        :attr:`edge_local_index` would compute)."""
        self = cls.__new__(cls)
        self._set_arrays(V, F, copy=False)      # the parts' own slices of split_parts' arrays
        for name, a, dtype in (("edges", edges, np.int32), ("edge_faces", edge_faces, np.int32),
                               ("edge_local_index", edge_local_index, np.int8)):
            a = np.ascontiguousarray(a, dtype=dtype)      # the dtypes of the topology maps
            a.setflags(write=False)
            self.__dict__[name] = a
        return self

    # ------------------------------------------------------------------ sizes
    @property
    def n_vertices(self):
        return self.V.shape[0]

    @property
    def n_faces(self):
        return self.F.shape[0]

    @property
    def n_edges(self):
        return self.edges.shape[0]

    # ------------------------------------------------------------ topology
    @cached_property
    def _topology(self):
        # one compiled pass (igl_hhj.kernels.topology); reference: tests/mesh/reference_topology.py
        from . import kernels
        out = kernels.topology(self.F, self.n_vertices)
        for a in out:
            a.flags.writeable = False
        return out

    @cached_property
    def edges(self):
        """(#E, 2) int32: unique undirected edges as ``(min, max)`` vertex pairs, in
        lexicographic order (the order of ``uE`` of ``igl.unique_edge_map``).  int32 for
        memory: cast to int64 before arithmetic on the indices (module docstring)."""
        return self._topology[0]

    @cached_property
    def face_edges(self):
        """(#F, 3) int32: ``face_edges[f, i]`` = unique edge opposite corner ``i`` of face ``f``."""
        return self._topology[1]

    @cached_property
    def edge_face_count(self):
        """(#E,) int8: number of faces incident to each unique edge (1 = boundary),
        saturated at 127 (only 1, 2 and more than 2 matter: a mesh with more than two
        faces at an edge is rejected)."""
        return self._topology[2]

    @cached_property
    def face_edge_sign(self):
        """(#F, 3) int8: +1 where the half-edge ``x_{i+1} → x_{i+2}`` of face f
        runs in the direction of the unique edge ``edges[face_edges[f, i]]``, else -1
        (a float64 array times it: float64, the same bits as with a ±1.0 factor)."""
        return self._topology[5]

    @cached_property
    def edge_faces(self):
        """(#E, 2) int32: the faces on either side of each edge, -1 for none.

        Column 0 holds the face in which the edge is positively oriented
        (``face_edge_sign == +1``), column 1 the other one."""
        return self._topology[3]

    @cached_property
    def edge_local_index(self):
        """(#E, 2) int8: local index (0..2) of the edge inside each face of ``edge_faces``; -1 for none."""
        return self._topology[4]

    @cached_property
    def boundary_edges(self):
        """(#E,) bool: edges with exactly one incident face."""
        return self.edge_face_count == 1

    @cached_property
    def boundary_vertices(self):
        """(#V,) bool: vertices on a boundary edge."""
        mask = np.zeros(self.n_vertices, dtype=bool)
        mask[self.edges[self.boundary_edges].ravel()] = True
        return mask

    @cached_property
    def has_boundary(self):
        return bool(self.boundary_edges.any())

    @cached_property
    def boundary_loops(self):
        """list of (k,) int64 arrays: ordered boundary loops (``igl.boundary_loop_all``)."""
        if not self.has_boundary:
            return []
        import igl
        return [np.asarray(loop, dtype=np.int64) for loop in igl.boundary_loop_all(self.F)]

    @cached_property
    def referenced_vertices(self):
        """(#V,) bool: vertices used by at least one face."""
        mask = np.zeros(self.n_vertices, dtype=bool)
        mask[self.F.ravel()] = True
        return mask

    # ------------------------------------------------------------ geometry
    @cached_property
    def _edge_vectors(self):
        """(#F, 3, 3): vector of edge i of face f, ``x_{i+2} - x_{i+1}``."""
        X = self.V[self.F]  # (#F, 3 corners, 3)
        ev = np.empty_like(X)
        np.subtract(X[:, 2], X[:, 1], out=ev[:, 0])
        np.subtract(X[:, 0], X[:, 2], out=ev[:, 1])
        np.subtract(X[:, 1], X[:, 0], out=ev[:, 2])
        return ev

    @cached_property
    def _cross(self):
        """(#F, 3): ``(x1 - x0) × (x2 - x0)`` = ``ev_2 × (-ev_1)``, by components."""
        a, b = self._edge_vectors[:, 2], -self._edge_vectors[:, 1]
        c = np.empty_like(a)
        c[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
        c[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
        c[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        return c

    def release_face_cross_products(self):
        """Drop the cached face cross products ``_cross`` (#F, 3), 24 B/face.

        The drop-in calls it once the vertex normals are computed, before its HHJ solve
        (the call's memory peak): the default path does not read them again.  Asked for
        again, they are recomputed by the numpy property (equal to round-off)."""
        self.__dict__.pop("_cross", None)

    @cached_property
    def face_double_areas(self):
        """(#F,) float64: twice the face areas, ``|(x1 - x0) × (x2 - x0)|``."""
        c = self._cross
        return np.sqrt(np.einsum("fa,fa->f", c, c))

    @cached_property
    def face_areas(self):
        """(#F,) float64: face areas |T|."""
        return 0.5 * self.face_double_areas

    @cached_property
    def face_normals(self):
        """(#F, 3) float64: unit face normals ν_T (right-hand rule on F's order)."""
        return self._cross / self.face_double_areas[:, None]

    @cached_property
    def edge_lengths(self):
        """(#F, 3) float64: ``l[f, i]`` = length of edge i (opposite corner i) of face f."""
        return np.linalg.norm(self._edge_vectors, axis=2)

    @cached_property
    def unique_edge_lengths(self):
        """(#E,) float64: length of each unique edge."""
        d = np.take(self.V, self.edges[:, 1], axis=0)
        d -= np.take(self.V, self.edges[:, 0], axis=0)
        d *= d
        # (d0² + d1²) + d2² in this order on every machine (einsum's order depends on the
        # SIMD width), as the compiled small-mesh path (igl_hhj.small_mesh) computes it
        s = d[:, 0] + d[:, 1]
        s += d[:, 2]
        return np.sqrt(s, out=s)

    @cached_property
    def edge_tangents(self):
        """(#F, 3, 3) float64: unit edge vectors ``t[f, i] = (x_{i+2} - x_{i+1}) / l_i``."""
        return self._edge_vectors / self.edge_lengths[:, :, None]

    @cached_property
    def conormals(self):
        """(#F, 3, 3) float64: unit outward conormals ``n[f, i] = t_i × ν_T`` (in the plane of T)."""
        return np.cross(self.edge_tangents, self.face_normals[:, None, :])

    def conormals_at(self, f, i):
        """(m, 3) float64: the conormals ``n[f, i]`` of :attr:`conormals` for the given
        faces ``f`` (m,) and local edges ``i`` (m,) only, without the (#F, 3, 3) arrays
        (the boundary edges' conormals of the clamped load)."""
        f = np.asarray(f, dtype=np.int64)
        i = np.asarray(i, dtype=np.int64)
        a = self.V[self.F[f, (i + 1) % 3]]
        t = self.V[self.F[f, (i + 2) % 3]] - a
        t /= np.linalg.norm(t, axis=1, keepdims=True)
        return np.cross(t, self.face_normals[f])

    @cached_property
    def barycentric_gradients(self):
        """(#F, 3, 3) float64: ``∇λ_i = -l_i n_i / (2|T|)``, gradient of corner i's hat function on f."""
        return -(self.edge_lengths / self.face_double_areas[:, None])[:, :, None] * self.conormals

    @cached_property
    def mean_edge_length(self):
        return float(self.unique_edge_lengths.mean())

    @cached_property
    def max_edge_length(self):
        """The mesh size h = longest edge."""
        return float(self.unique_edge_lengths.max())

    @cached_property
    def vertex_normals(self):
        """(#V, 3) float64: area-weighted unit vertex normals (``igl.per_vertex_normals``).

        Rows of unreferenced vertices and of :attr:`folded_vertices` are NaN."""
        import igl
        N = igl.per_vertex_normals(self.V, self.F,
                                   igl.PerVertexNormalsWeightingType.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
        N = np.array(N, dtype=np.float64)
        N[~self.referenced_vertices | self.folded_vertices] = np.nan
        return N

    @cached_property
    def folded_vertices(self):
        """(#V,) bool: referenced vertices without a tangent plane.

        ``|Σ_T |T| ν_T| ≤ FOLDED_NORMAL_RTOL Σ_T |T|`` over the incident faces:
        their normals cancel, as on a two-sided sheet (a triangle and its
        reverse), a sheet folded onto itself, the rim of a flat closed disc
        made of two fans, or a bow-tie vertex with opposite wings."""
        from . import kernels
        s, a = kernels.vertex_area_sums(self.F, self.n_vertices, self._cross, self.face_double_areas)
        s = np.linalg.norm(s, axis=1)
        return self.referenced_vertices & (s <= FOLDED_NORMAL_RTOL * a)

    def sum_corners_to_vertices(self, values):
        """Scatter-add per-corner values to the vertices.

        Parameters
        ----------
        values : (#F, 3, ...) array, ``values[f, c]`` belongs to vertex ``F[f, c]``.

        Returns
        -------
        (#V, ...) float64: for each vertex the sum over its corners (0 for
        unreferenced vertices).
        """
        values = np.asarray(values, dtype=np.float64)
        tail = values.shape[2:]
        flat = values.reshape(3 * self.n_faces, -1)
        v = self.F.ravel()
        out = np.empty((self.n_vertices, flat.shape[1]))
        for j in range(flat.shape[1]):  # value components; vectorised over all corners
            out[:, j] = np.bincount(v, weights=flat[:, j], minlength=self.n_vertices)
        return out.reshape((self.n_vertices,) + tail)

    # ------------------------------------------------------------ checks
    def _check_degenerate(self):
        # one compiled pass (igl_hhj.kernels.face_metrics) fills the caches of _cross and
        # face_double_areas; reference: the numpy properties and zero_area_faces
        from . import kernels
        cross, dbl, l2max = kernels.face_metrics(self.V, self.F)
        self.__dict__["_cross"] = cross
        self.__dict__["face_double_areas"] = dbl
        check_mesh_size(l2max)      # first: below it every face would look degenerate
        bad = _zero_area(dbl, l2max)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            n = int(bad.sum())
            many = f" ({n} such faces)" if n > 1 else ""
            with np.errstate(over="ignore", invalid="ignore"):
                longest = float(np.sqrt((self._edge_vectors[i] ** 2).sum(axis=1).max()))
            area = 0.5 * float(dbl[i])
            if not (np.isfinite(area) and np.isfinite(longest)):
                raise ValueError(
                    f"F has faces whose area overflows float64; first at face {i}: {self.F[i]}"
                    f"{many}. Rescale the mesh (curvature scales as 1/length)")
            if area == 0.0:
                raise MeshDefectError(
                    f"F has degenerate (zero-area) faces; first at face {i}: {self.F[i]}{many} "
                    f"(collinear corners, longest edge {longest:.3g}): remove or collapse them",
                    "degenerate")
            raise MeshDefectError(
                f"F has near-degenerate (sliver) faces; first at face {i}: {self.F[i]}{many} "
                f"(area {area:.3g}, longest edge {longest:.3g}: relative area "
                f"{2 * area / longest ** 2:.2g} ≤ {DEGENERATE_AREA_RTOL:g}, below what libigl's "
                f"edge-length formulas resolve): collapse the short edge or remove the sliver",
                "degenerate")

    def _check_manifold_and_orientation(self):
        count = self.edge_face_count
        bad = count > 2
        if bad.any():
            e = int(np.flatnonzero(bad)[0])
            raise MeshDefectError(
                f"mesh has non-manifold edges (more than two incident faces); first is edge "
                f"{e} between vertices {self.edges[e].tolist()} with "
                f"{int(np.count_nonzero(self.face_edges == e))} faces",      # count saturates at 127
                "non-manifold")
        # On a consistently oriented manifold every interior edge is traversed
        # once in each direction.
        pos = np.bincount(self.face_edges.ravel(), weights=self.face_edge_sign.ravel() > 0,
                          minlength=self.n_edges)
        bad = (count == 2) & (pos != 1)
        if bad.any():
            e = int(np.flatnonzero(bad)[0])
            f = np.flatnonzero((self.face_edges == e).any(axis=1))
            raise MeshDefectError(
                f"mesh is not consistently oriented: faces {f.tolist()} traverse edge {e} "
                f"(vertices {self.edges[e].tolist()}) in the same direction; orient it with "
                f"igl.bfs_orient(F) (a non-orientable surface such as a Möbius band cannot be)",
                "orientation")

    def _warn_unwelded(self):
        """Warn when boundary vertices coincide (a triangle soup or split seams)."""
        if not self.has_boundary:
            return
        b = np.flatnonzero(self.boundary_vertices)
        _, inv, cnt = np.unique(self.V[b], axis=0, return_inverse=True, return_counts=True)
        dup = cnt[inv.ravel()] > 1
        if dup.any():
            soup = bool(self.boundary_edges.all()) and self.n_faces > 1
            what = ("a triangle soup: no two faces share an edge, so every face is curvature-free "
                    "(the results are zeros)" if soup else
                    "unwelded: its seams count as boundary and the curvature there is wrong")
            warnings.warn(
                f"{int(dup.sum())} boundary vertices coincide with other vertices (first "
                f"{int(b[dup][0])}): the mesh looks {what}; weld it first, e.g. "
                f"V, _, J = igl.remove_duplicate_vertices(V, 0.0); F = J[F]", MeshWarning,
                stacklevel=3)


def as_mesh(V: Any, F: ArrayLike | None = None, *, copy: bool = True) -> TriangleMesh:
    """Return a :class:`TriangleMesh` for ``(V, F)``; a ``TriangleMesh`` passes through.

    With ``F`` None, ``V`` may also be a mesh object of another library
    (``trimesh.Trimesh``, triangulated ``pyvista.PolyData``, ``meshio.Mesh``;
    duck-typed by :func:`igl_hhj.mesh_objects.mesh_arrays`).  ``copy=False``: the mesh keeps
    read-only views of ``V`` and ``F`` where no conversion is needed (for a mesh that
    does not outlive the call that builds it; the caller must not modify ``V``, ``F``
    meanwhile).
    """
    if isinstance(V, TriangleMesh) and F is None:
        return V
    if F is None:
        arrays = mesh_arrays(V)
        if arrays is None:
            raise TypeError("F is required unless V is a TriangleMesh or a mesh object "
                            "(trimesh.Trimesh, pyvista.PolyData, meshio.Mesh)")
        return TriangleMesh(*arrays, copy=copy)
    return TriangleMesh(V, F, copy=copy)


def validate_mesh(V: ArrayLike, F: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Validate ``(V, F)`` and return them as float64 / int64 C-contiguous (writable) copies.

    Raises the same errors as :class:`TriangleMesh`.
    """
    m = TriangleMesh(V, F)
    return m.V.copy(), m.F.copy()


def mark_bad_vertices(mesh, *arrays, copy=True):
    """Set the rows of per-vertex outputs without a value to NaN and list them.

    A vertex is *bad* when it is unreferenced, has no tangent plane
    (:attr:`TriangleMesh.folded_vertices`: two-sided or folded sheets), or any
    of ``arrays`` is non-finite in its row.  Every NaN row of the result is
    listed, and every listed row is NaN in every array.

    Parameters
    ----------
    mesh : TriangleMesh
    *arrays : (#V, ...) float arrays

    copy : bool, default True
        False: float64 arrays are marked in place (the drop-in's own fresh outputs).

    Returns
    -------
    (*arrays, bad) : float64 copies of the arrays (or the arrays, ``copy=False``) with
        NaN rows, and ``bad`` the sorted list of bad vertex indices (``int``).
    """
    out = [np.array(a, dtype=np.float64, copy=copy or None) for a in arrays]
    bad = ~mesh.referenced_vertices | mesh.folded_vertices
    for a in out:
        bad |= ~np.isfinite(a.reshape(len(a), -1)).all(axis=1)
    for a in out:
        a[bad] = np.nan
    return (*out, np.flatnonzero(bad).tolist())


def per_vertex_array(mesh, values, name, shape_tail=()):
    """Validate an optional per-vertex data array of shape (#V, *shape_tail)."""
    A = _as_array(values, name)
    if A.dtype == object or not (np.issubdtype(A.dtype, np.floating) or np.issubdtype(A.dtype, np.integer)):
        raise TypeError(f"{name} must hold real numbers, got dtype {A.dtype}")
    want = (mesh.n_vertices,) + tuple(shape_tail)
    if A.shape != want:
        raise ValueError(f"{name} must have shape {want}, got {A.shape}")
    return np.ascontiguousarray(A, dtype=np.float64)
