"""Mesh objects of other libraries in and out: trimesh, pyvista, meshio.

Everywhere igl_hhj takes ``(V, F)`` it also takes a mesh object in place of
``V`` with ``F`` omitted (or None): a ``trimesh.Trimesh``, a triangulated
``pyvista.PolyData``, a ``pyvista.UnstructuredGrid`` of triangles or a
``meshio.Mesh`` with triangle cells.  The objects
are recognised by their attributes (duck typing), so none of those libraries
is a dependency; :func:`mesh_arrays` is the one adapter
(:func:`igl_hhj.mesh.as_mesh` calls it).  The arrays are copied and validated
like any ``(V, F)``; faces are never reordered.

:func:`to_trimesh`, :func:`to_pyvista` and :func:`to_meshio` go the other
way: a mesh with results attached (per-vertex values as vertex / point data,
per-face values as face / cell data), e.g. a
:class:`igl_hhj.baselines.CurvatureEstimate` or the shape operator.

Examples
--------
>>> import trimesh, igl_hhj                                   # doctest: +SKIP
>>> tm = trimesh.load("bunny.obj", process=False)              # doctest: +SKIP
>>> H = igl_hhj.face_mean_curvature(tm)                        # (#F,)  # doctest: +SKIP
>>> from igl_hhj import baselines, interop                     # doctest: +SKIP
>>> out = interop.to_pyvista(tm, baselines.hhj_vertex(tm))     # doctest: +SKIP
>>> out.plot(scalars="H")                                      # doctest: +SKIP
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np

__all__ = ["mesh_arrays", "is_mesh_object", "to_trimesh", "to_pyvista", "to_meshio", "result_fields"]

_SURFACE_CELLS = {"triangle", "quad", "polygon", "triangle6", "quad8", "quad9"}
_VTK_TRIANGLE = 5
_VTK_NAMES = {1: "vertex", 3: "line", 4: "polyline", 7: "polygon", 9: "quad", 10: "tetra",
              12: "hexahedron", 13: "wedge", 14: "pyramid", 22: "quadratic triangle"}
_VOLUME_CELLS = {"tetra", "hexahedron", "wedge", "pyramid", "tetra10", "hexahedron20", "hexahedron27"}


def _kind(obj: Any) -> str | None:
    """"meshio", "pyvista", "pyvista_grid", "trimesh" or None, from the object's attributes."""
    if hasattr(obj, "points") and hasattr(obj, "cells") and hasattr(obj, "celltypes") \
            and hasattr(obj, "n_points"):                 # pyvista.UnstructuredGrid (has cells_dict too)
        return "pyvista_grid"
    if hasattr(obj, "points") and hasattr(obj, "cells") and hasattr(obj, "cells_dict"):
        return "meshio"
    if hasattr(obj, "points") and hasattr(obj, "faces") and hasattr(obj, "n_points"):
        return "pyvista"
    if hasattr(obj, "vertices") and hasattr(obj, "faces"):
        return "trimesh"
    return None


def is_mesh_object(obj: Any) -> bool:
    """True for a trimesh / pyvista / meshio mesh object (by duck typing)."""
    return not isinstance(obj, np.ndarray) and _kind(obj) is not None


def mesh_arrays(obj: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """``(V, F)`` of a mesh object, or None if ``obj`` is not one.

    Parameters
    ----------
    obj : trimesh.Trimesh, pyvista.PolyData, pyvista.UnstructuredGrid or meshio.Mesh (anything with the
        same attributes)

    Returns
    -------
    V : (#V, 3) ndarray, F : (#F, 3) ndarray of int (as stored; validated later).

    Raises
    ------
    ValueError
        A pyvista mesh with faces that are not triangles (``.triangulate()``
        first), a meshio mesh with polygons other than triangles or with volume
        cells, or one without triangles.

    Examples
    --------
    >>> import meshio                                          # doctest: +SKIP
    >>> m = meshio.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [("triangle", [[0, 1, 2]])])  # doctest: +SKIP
    >>> V, F = mesh_arrays(m)                                 # doctest: +SKIP
    """
    kind = None if isinstance(obj, np.ndarray) else _kind(obj)
    if kind is None:
        return None
    if kind == "trimesh":
        return np.asarray(obj.vertices), np.asarray(obj.faces)
    if kind == "pyvista_grid":
        vtk_types = np.asarray(obj.celltypes).ravel()
        flat = np.asarray(obj.cells).ravel()
        if vtk_types.size == 0:
            raise ValueError("the pyvista UnstructuredGrid has no cells")
        if not np.all(vtk_types == _VTK_TRIANGLE):
            names = sorted({_VTK_NAMES.get(int(t), f"VTK type {int(t)}") for t in np.unique(vtk_types)
                            if t != _VTK_TRIANGLE})
            raise ValueError(f"the pyvista UnstructuredGrid has {', '.join(names)} cells: only triangles "
                             f"are supported (grid.extract_surface().triangulate() first)")
        if flat.size != 4 * vtk_types.size or not np.all(flat[0::4] == 3):
            raise ValueError("the pyvista UnstructuredGrid's cell connectivity does not match its "
                             "triangle cell types")
        return np.asarray(obj.points), flat.reshape(-1, 4)[:, 1:]
    if kind == "pyvista":
        V = np.asarray(obj.points)
        flat = np.asarray(obj.faces).ravel()
        if flat.size == 0:
            raise ValueError("the pyvista mesh has no faces (a point cloud or lines only)")
        if flat.size % 4 or not np.all(flat[0::4] == 3):
            raise ValueError("the pyvista mesh has faces that are not triangles; call mesh.triangulate() first")
        return V, flat.reshape(-1, 4)[:, 1:]
    # meshio
    types = [c.type for c in obj.cells]
    bad = sorted(set(types) & (_SURFACE_CELLS - {"triangle"}))
    if bad:
        raise ValueError(f"the meshio mesh has {', '.join(bad)} cells: only triangle meshes are supported "
                         f"(triangulate it first)")
    vol = sorted(set(types) & _VOLUME_CELLS)
    if vol:
        raise ValueError(f"the meshio mesh is a volume mesh ({', '.join(vol)} cells): pass its boundary surface")
    tris = [np.asarray(c.data) for c in obj.cells if c.type == "triangle"]
    if not tris:
        raise ValueError(f"the meshio mesh has no triangle cells (cell types: {sorted(set(types)) or 'none'})")
    V = np.asarray(obj.points)
    if V.ndim == 2 and V.shape[1] == 2:             # planar meshes: z = 0
        V = np.column_stack([V, np.zeros(len(V))])
    return V, np.concatenate(tris)


def result_fields(result: Any, n_vertices: int, n_faces: int) -> tuple[dict, dict]:
    """Split results into ({name: per-vertex array}, {name: per-face array}).

    ``result``: a CurvatureEstimate (k1, k2, H, K and d1, d2 on its
    location), a mapping name -> array whose first axis has #V or #F entries
    (#V wins when they are equal), or None.
    """
    if result is None:
        return {}, {}
    if hasattr(result, "k1") and hasattr(result, "location"):
        fields = {q: getattr(result, q) for q in ("k1", "k2", "H", "K")}
        if getattr(result, "d1", None) is not None:
            fields.update(d1=result.d1, d2=result.d2)
        fields = {k: np.asarray(v, dtype=np.float64) for k, v in fields.items()}
        return (fields, {}) if result.location == "vertex" else ({}, fields)
    if not isinstance(result, Mapping):
        raise TypeError(f"results must be a CurvatureEstimate or a dict name -> array, got {type(result).__name__}")
    per_vertex, per_face = {}, {}
    for name, values in result.items():
        a = np.asarray(values)
        if a.ndim >= 1 and len(a) == n_vertices:
            per_vertex[str(name)] = a
        elif a.ndim >= 1 and len(a) == n_faces:
            per_face[str(name)] = a
        else:
            raise ValueError(f"result {name!r} has shape {a.shape}: its first axis must have #V = {n_vertices} "
                             f"(per vertex) or #F = {n_faces} (per face) entries")
    return per_vertex, per_face


def _validated(V, F, results):
    """(V, F, results): ``to_*(obj, results)`` (a mesh object or TriangleMesh first) means
    ``to_*(obj, None, results)``."""
    from .mesh import TriangleMesh, as_mesh
    if F is not None and (isinstance(V, TriangleMesh) or is_mesh_object(V)):
        if results is not None:
            raise TypeError("pass either (V, F, results) or (mesh_object, results)")
        F, results = None, F
    mesh = as_mesh(V, F)
    return mesh.V, mesh.F, results


def to_trimesh(V: Any, F: Any = None, results: Any = None) -> Any:
    """A ``trimesh.Trimesh`` (``process=False``: vertex order kept) with the results
    as ``vertex_attributes`` / ``face_attributes``.

    Parameters
    ----------
    V, F : the mesh (arrays, or a mesh object with ``F`` omitted: ``to_trimesh(obj, results)``)
    results : CurvatureEstimate or dict name -> (#V, ...) / (#F, ...) array, optional
    """
    import trimesh
    V, F, results = _validated(V, F, results)
    pv_, pf = result_fields(results, len(V), len(F))
    return trimesh.Trimesh(V, F, process=False, vertex_attributes=pv_, face_attributes=pf)


def _rows(fields):
    """{name: array} with tensors ``(n, 3, 3)`` (any ``ndim > 2``) as ``(n, 9)`` rows, the
    layout VTK stores and ParaView shows as a tensor (row-major: ``S.reshape(-1, 3, 3)``
    restores it)."""
    return {k: (v.reshape(len(v), -1) if v.ndim > 2 else v) for k, v in fields.items()}


def to_pyvista(V: Any, F: Any = None, results: Any = None, *, scalars: str | None = None) -> Any:
    """A ``pyvista.PolyData`` with the results as ``point_data`` / ``cell_data``.

    Tensors ``(n, 3, 3)`` become ``(n, 9)`` arrays.  ``scalars`` names the array
    made active (what ``out.plot()`` shows); default ``"H"`` when the results have it.
    """
    import pyvista
    V, F, results = _validated(V, F, results)
    out = pyvista.PolyData(V, np.column_stack([np.full(len(F), 3), F]).ravel())
    pv_, pf = result_fields(results, len(V), len(F))
    for k, v in _rows(pv_).items():
        out.point_data[k] = v
    for k, v in _rows(pf).items():
        out.cell_data[k] = v
    active = scalars if scalars is not None else ("H" if "H" in pv_ or "H" in pf else None)
    if active is not None:
        if active not in pv_ and active not in pf:
            raise ValueError(f"scalars={active!r} is not one of the results "
                             f"({', '.join(list(pv_) + list(pf)) or 'none'})")
        out.set_active_scalars(active, preference="point" if active in pv_ else "cell")
    return out


def to_meshio(V: Any, F: Any = None, results: Any = None) -> Any:
    """A ``meshio.Mesh`` (one triangle block) with the results as ``point_data`` /
    ``cell_data`` (``mesh.write("x.vtu")`` for ParaView).

    Tensors ``(n, 3, 3)`` become ``(n, 9)`` arrays (meshio writes a 3-d array into
    ``.vtu`` with a wrong layout).  meshio marks no array as the active scalars; for
    files ParaView opens coloured by H write them with
    :func:`igl_hhj.vtk_files.write_vtk` (``.vtp`` / ``.vtu``, ``scalars="H"``).
    """
    import meshio
    V, F, results = _validated(V, F, results)
    pv_, pf = result_fields(results, len(V), len(F))
    return meshio.Mesh(V, [("triangle", F)], point_data=_rows(pv_),
                       cell_data={k: [v] for k, v in _rows(pf).items()})
