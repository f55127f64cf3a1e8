"""Mesh objects of other libraries in and out: trimesh, pyvista, meshio.

Everywhere igl_hhj takes ``(V, F)`` it also takes a mesh object in place of
``V`` with ``F`` omitted (or None): a ``trimesh.Trimesh``, a triangulated
``pyvista.PolyData``, a ``pyvista.UnstructuredGrid`` of triangles or a
``meshio.Mesh`` with triangle cells.  The objects
are recognised by their attributes (duck typing), so none of those libraries
is a dependency; :func:`mesh_arrays` is the one adapter
(:mod:`igl_hhj.mesh_objects`, which :func:`igl_hhj.mesh.as_mesh` calls).  The arrays are copied and validated
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

from .mesh_objects import is_mesh_object, mesh_arrays

__all__ = ["mesh_arrays", "is_mesh_object", "to_trimesh", "to_pyvista", "to_meshio", "result_fields"]


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
