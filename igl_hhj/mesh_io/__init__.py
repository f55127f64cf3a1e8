"""Guarded mesh reading and curvature output files (used by the ``igl-hhj`` command line).

Reading goes through ``igl.read_triangle_mesh``; this module only checks the
file *before* libigl sees it, because libigl 2.6's readers misbehave on some
bad inputs instead of raising (measured with libigl 2.6.3):

* a directory or a missing file: C++ messages on stderr (the directory case
  prints uninitialised memory) and a bare ``RuntimeError``;
* ``.obj``, ``.ply`` or ``.mesh`` garbage: *no* error, empty arrays;
* an ascii ``.ply`` with fewer faces than its header declares, or with
  mixed triangles and quads: ``free(): double free`` — the process aborts;
* a ``.ply`` header declaring 10¹¹ vertices in a 150-byte file: an endless
  loop; 10⁸ vertices: 4.7 GB of memory before returning;
* an ``.off`` header declaring 10⁸ vertices: 5.5 GB of memory, 15 s;
* a truncated binary ``.ply``: uninitialised memory returned as face indices.

* an ``.off`` face line claiming 2·10⁹ corners in a 45-byte file: 15.7 GB
  of memory, then ``std::bad_alloc``;
* an ascii ``.ply`` with a non-numeric token: uninitialised indices;
* ``.obj`` faces written 0-based: index -1 after libigl's 1-based shift;
* a ``.ply`` header declaring a property or an element twice, or an ascii face
  line without the values of a second list property (``texcoord``): the
  process aborts (``free(): double free``).

:func:`read_mesh` therefore checks existence, regular file, readability and
extension, then checks *every* count and token of the body before libigl
sees it, with numpy in bounded chunks (memory O(#lines), time linear in the
file size): the element counts an ``.off`` / ``.ply`` header declares against
the lines or bytes that follow, every corner count of an ``.off`` face line
against the indices it lists, that every ascii token that must be a number is
one, ``.obj`` faces 1-based, binary ``.ply`` face records triangles, binary
``.stl`` sizes ``84 + 50 × count``, ``.mesh`` / ``.msh`` section counts
against the lines that follow.  It reads with libigl's C++ messages captured
and raises :class:`MeshFileError` (a ``ValueError``) with one line naming the
problem.

The formats libigl lacks (``.gltf .glb .3mf .vtp .vtu .vtk``) and PLYs of quads or
other polygons (libigl's reader aborts on them) are read by :mod:`igl_hhj.polygon_io`
(optional trimesh / pyvista / meshio) and by a numpy PLY reader; every format splits
polygons by one rule, the fan from each polygon's first corner (what libigl's OBJ / OFF
readers do).  :func:`read_mesh_file` returns the counts (:class:`MeshFile`).

:func:`read_curvature` reads a result back (``.npz``, ``.ply``, ``.vtp``, ``.vtu``,
``.vtk``; ``igl-hhj view``).

:func:`write_curvature` writes a
:class:`igl_hhj.results.CurvatureEstimate` as ``.npz``, ``.csv``, ``.ply``
(with MeshLab's ``quality``), ``.vtp`` / ``.vtu`` / ``.vtk``
(:mod:`igl_hhj.vtk_files`, the displayed quantity as the active scalars) or
``.obj`` with per-vertex colours, in forms that meshio, pyvista/VTK/ParaView,
pymeshlab/MeshLab, trimesh and Blender read (numpy only, no per-element Python
loops, no optional dependency).

Modules
-------
:mod:`.readers` (:func:`read_mesh`, :func:`read_mesh_file`, :class:`MeshFile`),
:mod:`.guards` (the checks of OBJ, OFF, STL, ``.mesh`` / ``.msh`` files before libigl
reads them), :mod:`.ply` (PLY headers and bodies), :mod:`.scan` (the line scanner
they use), :mod:`.writers` (:func:`write_curvature`), :mod:`.result_files`
(:func:`read_curvature`), :mod:`.extensions`.  :class:`MeshFileError` is defined in
:mod:`igl_hhj.errors`, :class:`CapturedOutput` in :mod:`igl_hhj.capture`; every name
of ``__all__`` is importable from here.
"""
from __future__ import annotations

from ..capture import CapturedOutput
from ..errors import MeshFileError
from ..results import QUANTITIES  # noqa: F401  (the values quantity= takes)
from .extensions import (MESH_EXTENSIONS, MESHIO_EXTENSIONS, OUTPUT_EXTENSIONS, READ_EXTENSIONS,
                         RESULT_EXTENSIONS, VTK_EXTENSIONS)
from .readers import MeshFile, read_mesh, read_mesh_file
from .result_files import CurvatureFile, read_curvature
from .writers import CURVATURE_COLUMNS, check_output_path, probe_writable, quantity_colours, write_curvature

__all__ = ["MeshFileError", "MeshFile", "read_mesh_file", "READ_EXTENSIONS", "CapturedOutput", "MESH_EXTENSIONS", "OUTPUT_EXTENSIONS", "read_mesh",
           "check_output_path", "probe_writable", "write_curvature", "read_curvature", "CurvatureFile",
           "RESULT_EXTENSIONS", "CURVATURE_COLUMNS", "MESHIO_EXTENSIONS",
           "VTK_EXTENSIONS",
           "quantity_colours"]
