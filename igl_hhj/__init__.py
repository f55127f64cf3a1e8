"""igl_hhj: provably convergent finite-element curvature for libigl triangle meshes.

The core is Walker's surface Hellan–Herrmann–Johnson (HHJ) shape operator
(:func:`shape_operator`), with a drop-in replacement for
``igl.principal_curvature`` (:func:`principal_curvature`).
"""
from .curvature import (
    face_gaussian_curvature,
    face_mean_curvature,
    face_principal_curvature,
    principal_curvature,
    principal_from_shape_operator,
    shape_operator,
    surface_hessian,
)
from .mesh import TriangleMesh, validate_mesh

__version__ = "0.1.0"

__all__ = [
    "shape_operator", "surface_hessian", "principal_curvature",
    "face_principal_curvature", "face_mean_curvature", "face_gaussian_curvature",
    "principal_from_shape_operator", "TriangleMesh", "validate_mesh",
]
