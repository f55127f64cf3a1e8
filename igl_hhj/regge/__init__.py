"""Regge metric layer: distributional Gauss curvature of Regge metrics and its
lifting to Lagrange elements (Gopalakrishnan–Neunteufel–Schöberl–Wardetzky,
Gopalakrishnan et al. 2024: Definitions 2.1 and 2.3, canonical interpolant eq. 3.1, §4).

Degree 0 on triangle meshes (embedded or intrinsic)::

    K = igl_hhj.regge.gauss_curvature(V, F)                 # (#V,), P1 lifting
    K = igl_hhj.regge.gauss_curvature_intrinsic(l_sq, F)    # from squared edge lengths

Degree k on planar triangulations with a metric::

    g_h = igl_hhj.regge.interpolate(P, F, metric, k)        # canonical interpolant
    K_h = igl_hhj.regge.lift_gauss_curvature(g_h, degree=k, dirichlet=..., ...)
    K_h(faces, bary), K_h.dofs, K_h.l2_error(K_exact), K_h.h_minus1_error(K_exact),
    K_h.h1_error(K_exact, grad_K_exact), K_h.l2_error(K_omega_exact, times_omega_h=True)
"""
from .curvature import (LiftedCurvature, corner_angles, edge_geodesic_curvature,
                        gauss_curvature_functional, lift_gauss_curvature,
                        metric_gauss_curvature, triangle_gauss_bonnet)
from .edge_metric import (angle_defect, gauss_curvature, gauss_curvature_intrinsic,
                          intrinsic_angles, intrinsic_areas, intrinsic_mass_matrix,
                          squared_edge_lengths)
from .elements import LagrangeSpace, PlanarTriangulation, ReggeMetric, interpolate
from .quadrature import gauss_legendre, triangle_rule

__all__ = [
    "gauss_curvature", "gauss_curvature_intrinsic", "squared_edge_lengths", "angle_defect",
    "intrinsic_angles", "intrinsic_areas", "intrinsic_mass_matrix",
    "interpolate", "lift_gauss_curvature", "LiftedCurvature", "ReggeMetric", "LagrangeSpace",
    "PlanarTriangulation", "gauss_curvature_functional", "metric_gauss_curvature",
    "edge_geodesic_curvature", "corner_angles", "triangle_gauss_bonnet",
    "gauss_legendre", "triangle_rule",
]
