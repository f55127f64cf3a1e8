"""Mesh objects of other libraries, recognised by their attributes: their ``(V, F)`` arrays.

Everywhere igl_hhj takes ``(V, F)`` it also takes a mesh object in place of ``V`` with
``F`` omitted (or None): a ``trimesh.Trimesh``, a triangulated ``pyvista.PolyData``, a
``pyvista.UnstructuredGrid`` of triangles or a ``meshio.Mesh`` with triangle cells.  The
objects are recognised by their attributes (duck typing), so none of those libraries is
imported here or is a dependency; :func:`mesh_arrays` is the one adapter
(:func:`igl_hhj.mesh.as_mesh` and the drop-in's repair call it; the public name is
:func:`igl_hhj.interop.mesh_arrays`, where the way back, results onto mesh objects, lives).
"""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["mesh_arrays", "is_mesh_object"]

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
