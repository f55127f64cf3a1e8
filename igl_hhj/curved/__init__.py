"""Curved higher-order surfaces: Walker's HHJ shape operator for Lagrange
triangles of order m = 1, 2, 3 (HHJ degree r = m − 1) and Heine's
L2-projected Weingarten map in Lagrange degree γ.

Modules: :mod:`.reference` (reference triangle, gmsh node order, quadrature),
:mod:`.surface` (:class:`LagrangeSurface`), :mod:`.interpolation` (Walker's
modified interpolant, eq. 4.2/4.14), :mod:`.hhj` (the curved HHJ space and its
matrices), :mod:`.hessian` (the HHJ surface Hessian of a scalar function,
Theorem 4.1), :mod:`.shape_operator`, :mod:`.field` (:class:`CurvedField`),
:mod:`.heine`, :mod:`.errors` (Walker's error norms on Γ^m), :mod:`.display`
(flat display meshes for the viewer).
"""
from .field import CurvedField
from .heine import LagrangeSpace, heine_weingarten
from .hessian import HessianField, surface_hessian
from .hhj import CurvedHHJ
from .interpolation import modified_interpolant
from .shape_operator import shape_operator
from .surface import LagrangeSurface

__all__ = ["LagrangeSurface", "CurvedHHJ", "CurvedField", "LagrangeSpace", "shape_operator", "heine_weingarten",
           "surface_hessian", "HessianField", "modified_interpolant"]
