"""The file extensions of the mesh and result files: what is read, written and re-opened."""
from __future__ import annotations

from ..polygon_io import EXTRA_EXTENSIONS

__all__ = ["MESH_EXTENSIONS", "READ_EXTENSIONS", "OUTPUT_EXTENSIONS", "VTK_EXTENSIONS", "MESHIO_EXTENSIONS",
           "RESULT_EXTENSIONS"]

MESH_EXTENSIONS = (".obj", ".off", ".ply", ".stl", ".wrl", ".mesh", ".msh")
"""Extensions ``igl.read_triangle_mesh`` dispatches on (case-insensitive)."""

READ_EXTENSIONS = MESH_EXTENSIONS + tuple(EXTRA_EXTENSIONS)
"""Extensions :func:`igl_hhj.mesh_io.read_mesh` reads: libigl's, and through optional packages those of
:data:`igl_hhj.polygon_io.EXTRA_EXTENSIONS` (glTF/GLB, 3MF, VTP, VTU, VTK)."""

OUTPUT_EXTENSIONS = (".npz", ".csv", ".ply", ".vtp", ".vtu", ".vtk", ".obj")
VTK_EXTENSIONS = (".vtp", ".vtu", ".vtk")
"""Output extensions written as VTK files (:mod:`igl_hhj.vtk_files`, numpy only)."""

MESHIO_EXTENSIONS: tuple[str, ...] = ()
"""Output extensions that need meshio: none (``.vtu`` / ``.vtk`` are written with numpy);
kept for scripts that check it."""

RESULT_EXTENSIONS = (".npz", ".ply", ".vtp", ".vtu", ".vtk")
"""Outputs of :func:`igl_hhj.mesh_io.write_curvature` that :func:`igl_hhj.mesh_io.read_curvature` (and ``igl-hhj view``) re-open:
those that hold the mesh with its values (``.csv`` holds no mesh, ``.obj`` only colours)."""
