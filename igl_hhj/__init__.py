"""igl_hhj: provably convergent finite-element curvature for libigl triangle meshes.

Core (needs only libigl, numpy, scipy; imported on first use):

* :func:`shape_operator` — Walker's surface-HHJ shape operator S_h, one tensor per face;
* :func:`surface_hessian` — HHJ projection of the surface Hessian of a P1 function;
* :func:`principal_curvature` — drop-in replacement for ``igl.principal_curvature``;
* :func:`face_principal_curvature`, :func:`face_mean_curvature`, :func:`face_gaussian_curvature`;
* :func:`curvature_of` — one quantity (mean, gauss, k1, k2, directions) per vertex or per
  face of ``(V, F)`` or a trimesh / pyvista / meshio mesh, as arrays (not ``curvature``:
  that name is the submodule :mod:`igl_hhj.curvature`).

Submodules (imported on first use): :mod:`igl_hhj.regge` (Regge metrics and
lifted distributional Gauss curvature), :mod:`igl_hhj.biharmonic` (mixed P1
biharmonic solver, also as :func:`biharmonic_solve`), :mod:`igl_hhj.baselines`
(libigl, Heine and pymeshlab estimators behind one interface),
:mod:`igl_hhj.viewer` (polyscope viewers and headless screenshots),
:mod:`igl_hhj.mesh_io` (guarded mesh reading, curvature output files),
:mod:`igl_hhj.mesh_report` (what a mesh is made of and whether igl_hhj accepts it),
:mod:`igl_hhj.interop` (trimesh / pyvista / meshio mesh objects in, results back onto them),
:mod:`igl_hhj.demos` (the demos, ``igl-hhj demo NAME``),
:mod:`igl_hhj.surfaces` (exact test surfaces and mesh sequences), :mod:`igl_hhj.benchmarks`,
:mod:`igl_hhj.cli` (the ``igl-hhj`` command), :mod:`igl_hhj.recovery` (vertex recovery and
smoothing scale of the drop-in), :mod:`igl_hhj.boundary_estimation` (data-free boundary normals),
:mod:`igl_hhj.repair` (the drop-in's repair of meshes the strict functions refuse),
:mod:`igl_hhj.features` (sharp features: creases as internal boundaries, crease line measure).
"""
import importlib
import pkgutil
from typing import TYPE_CHECKING, Any

# Run from a source checkout (e.g. `python -m pytest` in the repository, whose folder
# shadows the installed package), the compiled core igl_hhj._hhj_core lives only in the
# installed copy: let the package's submodule search fall through to it.
__path__ = pkgutil.extend_path(__path__, __name__)

__version__ = "0.1.0"

_LAZY_MODULES = {"regge", "biharmonic", "baselines", "viewer", "surfaces", "benchmarks",
                 "hhj", "mesh", "convergence", "cli", "mesh_io", "mesh_report",
                 "curvature", "errors", "interop", "demos",
                 "recovery", "boundary_estimation", "repair", "vtk_files", "polygon_io", "batch", "features"}
# The core names resolve on first use too, so that ``import igl_hhj`` (and the
# ``igl-hhj`` command's start-up, where Ctrl-C must not print a traceback) costs
# no numpy/scipy import.
_LAZY_ATTRS = {"biharmonic_solve": "biharmonic", "BiharmonicSolver": "biharmonic",
               **{name: "curvature" for name in (
                   "boundary_treatment", "curvature_of", "face_gaussian_curvature", "face_mean_curvature",
                   "face_principal_curvature", "principal_curvature", "principal_from_shape_operator", "shape_operator",
                   "surface_hessian")},
               "SolverError": "errors", "SolverDidNotConverge": "errors",
               "TriangleMesh": "mesh", "validate_mesh": "mesh"}

__all__ = [
    "shape_operator", "surface_hessian", "principal_curvature",
    "face_principal_curvature", "face_mean_curvature", "face_gaussian_curvature",
    "principal_from_shape_operator", "boundary_treatment", "curvature_of", "TriangleMesh", "validate_mesh",
    "biharmonic_solve", "BiharmonicSolver", "SolverError", "SolverDidNotConverge",
]


if TYPE_CHECKING:
    # Static checkers (mypy, pyright, IDEs) see every public name with its real type;
    # at run time nothing here is imported and ``__getattr__`` below resolves the
    # names on first use.  Keep in step with _LAZY_MODULES / _LAZY_ATTRS
    # (tests/app/test_typing.py checks that the two agree).
    from . import (baselines, batch, benchmarks, biharmonic, boundary_estimation, cli, convergence, curvature,
                   demos, errors, features, hhj, interop, mesh, mesh_io, mesh_report, polygon_io, recovery, regge,
                   repair, surfaces, viewer, vtk_files)
    from .biharmonic import BiharmonicSolver, biharmonic_solve
    from .curvature import (boundary_treatment, curvature_of, face_gaussian_curvature,
                            face_mean_curvature, face_principal_curvature, principal_curvature,
                            principal_from_shape_operator, shape_operator, surface_hessian)
    from .errors import SolverDidNotConverge, SolverError
    from .mesh import TriangleMesh, validate_mesh


def __getattr__(name: str) -> Any:
    """Import submodules (and their headline functions) on first use."""
    if name in _LAZY_MODULES:
        return importlib.import_module(f".{name}", __name__)
    if name in _LAZY_ATTRS:
        value = getattr(importlib.import_module(f".{_LAZY_ATTRS[name]}", __name__), name)
        globals()[name] = value              # resolve once
        return value
    raise AttributeError(f"module 'igl_hhj' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | _LAZY_MODULES | set(_LAZY_ATTRS))
