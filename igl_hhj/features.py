"""Sharp features: creases as internal boundaries, crease curvature as a line measure.

A crease (a sharp edge of a CAD part, a scan of a machined object) is a jump of the
normal across an edge.  Its curvature is a Dirac measure concentrated on the edge: the
HHJ shape operator S_h (Walker 2023) is an L2 projection onto piecewise-constant
tensors and cannot represent it (a saw-tooth of signs along the crease), and every
vertex stage that averages across the crease smears it into a band of large values.

This module treats the surface as **cut along its creases** (the functions of the crease
itself live in :mod:`igl_hhj.creases`; they are re-exported here):

* :func:`dihedral_angles`: the signed dihedral angle θ_e of every edge (the angle
  between the two face normals, + where the edge is convex, - where concave, 0 on
  boundary edges).
* :func:`crease_edges`: the creases, ``|θ_e| > feature_angle`` (degrees), or the
  edges the caller names.
* :func:`crease_network`: chains (maximal runs of crease edges through vertices of
  crease degree 2), corners (≥ 3 creases meet) and end points (1 crease), the
  per-edge angle θ_e, length ℓ_e and the mean-curvature line measure θ_e ℓ_e / 2.
* :func:`cut_along`: the mesh with every vertex duplicated once per *side* (the
  components of its star connected across non-crease edges).  Faces keep their
  order and their corner order (only the indices change); the crease edges become
  boundary edges, so the open-boundary path of :func:`igl_hhj.shape_operator`
  clamps each side with its own O(h²) normals
  (:func:`igl_hhj.boundary_estimation.estimate_boundary_normals` on the cut mesh
  sees only that side), and the vertex stage (recovery, smoothing) never averages
  across a crease.
* :func:`feature_shape_operator`, :func:`feature_principal_curvature`: the
  feature-aware shape operator (per face) and principal curvatures (per side and,
  in the drop-in shape, one value per vertex), used by
  ``principal_curvature(..., feature_angle=...)`` and
  ``shape_operator(..., feature_angle=...)``.

The crease's own curvature is returned separately, as what it is: the mean curvature
measure of the piecewise-flat surface is ``Σ_e θ_e |e| / 2`` (Steiner's formula;
Cohen-Steiner & Morvan's normal-cycle measure restricted to the crease edges), and
``Σ_e θ_e |e|`` converges to ``∫_crease θ ds`` of the exact surface.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import pipeline
from .constants import DEFAULT_RTOL
# the crease functions, named here as before (their home: igl_hhj.creases)
from .creases import (DEFAULT_FEATURE_ANGLE, CreaseNetwork, CutMesh, check_feature_angle, crease_edges,  # noqa: F401
                      crease_network, cut_along, cut_along_reference, dihedral_angles, prepare_cut)
from .mesh import as_mesh

__all__ = [
    "DEFAULT_FEATURE_ANGLE", "dihedral_angles", "crease_edges", "crease_network", "CreaseNetwork",
    "cut_along", "CutMesh", "feature_shape_operator", "feature_principal_curvature",
    "FeatureCurvature", "check_feature_angle", "cut_along_reference",
]


def feature_shape_operator(V: Any, F: ArrayLike | None = None, *,
                           feature_angle: float | None = DEFAULT_FEATURE_ANGLE,
                           crease_edges: ArrayLike | None = None, solver: str = "auto",
                           rtol: float | None = None) -> NDArray[np.float64]:
    """Walker's S_h of the surface cut along its creases, one tensor per face.

    Solves eq. (5.19) on :func:`cut_along`'s mesh: the crease edges are clamped edges
    whose data ν~ are the O(h²) one-sided normals of each side
    (:func:`igl_hhj.boundary_estimation.estimate_boundary_normals` on the cut mesh),
    open boundaries of the mesh as ``boundary="estimate"``.  The crease's own curvature
    is not in S_h (see :func:`crease_network`).

    Returns
    -------
    S : (#F, 3, 3) float64, in the caller's F order.
    """
    mesh = as_mesh(V, F)
    _, _, cm = prepare_cut(mesh, feature_angle, crease_edges, "estimate", ())
    return pipeline.checked_shape_operator(cm, "estimate", None, None, None, solver,
                                           DEFAULT_RTOL if rtol is None else rtol, groups_of=mesh)


@dataclass(frozen=True)
class FeatureCurvature:
    """Result of :func:`feature_principal_curvature`.

    Attributes
    ----------
    PD1, PD2 : (#V, 3), PV1, PV2 : (#V,), bad_vertices : list of int
        The drop-in tuple of :func:`igl_hhj.principal_curvature`: at a crease vertex the
        values of its *primary side* (the side with the largest incident area).
    side_PD1, side_PD2 : (#Vc, 3), side_PV1, side_PV2 : (#Vc,)
        One row per side of every vertex (rows 0..#V-1 are the primary sides, equal to
        PD1..PV2; ``side_parent`` maps every row to its vertex).
    side_parent : (#Vc,) int64
    side_normals : (#Vc, 3), each side's own vertex normal.
    cut : CutMesh, the cut mesh (its F indexes the side rows).
    creases : CreaseNetwork, the crease edges, chains, corners and θ_e.
    """

    PD1: NDArray[np.float64]
    PD2: NDArray[np.float64]
    PV1: NDArray[np.float64]
    PV2: NDArray[np.float64]
    bad_vertices: list
    side_PD1: NDArray[np.float64]
    side_PD2: NDArray[np.float64]
    side_PV1: NDArray[np.float64]
    side_PV2: NDArray[np.float64]
    side_parent: NDArray[np.int64]
    side_normals: NDArray[np.float64]
    cut: CutMesh
    creases: CreaseNetwork

    def as_tuple(self):
        """(PD1, PD2, PV1, PV2, bad_vertices), as ``igl.principal_curvature``."""
        return self.PD1, self.PD2, self.PV1, self.PV2, self.bad_vertices

    @property
    def side_mean_curvature(self) -> NDArray[np.float64]:
        """(#Vc,) H = (κ1 + κ2)/2 per side."""
        return 0.5 * (self.side_PV1 + self.side_PV2)


def feature_principal_curvature(V: Any, F: ArrayLike | None = None, radius: int = 5, *,
                                feature_angle: float | None = DEFAULT_FEATURE_ANGLE,
                                crease_edges: ArrayLike | None = None, boundary: str = "estimate",
                                solver: str = "auto", rtol: float | None = None) -> FeatureCurvature:
    """Principal curvatures of the smooth parts of a creased surface, per side.

    :func:`feature_shape_operator`, then the drop-in's vertex stage (intrinsic recovery,
    adaptive smoothing at scale ``radius``) on the cut mesh, so that neither recovery nor
    smoothing reaches across a crease (:func:`igl_hhj.pipeline.side_values`).

    Parameters
    ----------
    V : (#V, 3) array_like, F : (#F, 3) array_like of int
    radius : int, default 5, as :func:`igl_hhj.principal_curvature`.
    feature_angle : float or None, default 40
        Crease threshold in degrees (:func:`crease_edges`); None: only ``crease_edges``.
    crease_edges : (k, 2) array_like of int, optional, creases named by vertex pairs.
    boundary : "estimate" (the only treatment with features).
    solver, rtol : as :func:`igl_hhj.shape_operator`.

    Returns
    -------
    FeatureCurvature

    Examples
    --------
    >>> import igl_hhj.features as ft
    >>> from igl_hhj.surfaces.creased import capped_cylinder
    >>> V, F, _ = capped_cylinder(2)            # R = 1: H = 1/2 on the side, 0 on the caps
    >>> r = ft.feature_principal_curvature(V, F)
    >>> r.creases.n_chains, len(r.creases.corners)   # the two rims, no corners
    (2, 0)
    >>> rim = r.creases.edges[0, 0]                  # a rim vertex has two sides
    >>> sides = (r.side_parent == rim).nonzero()[0]
    >>> sorted(round(abs(float(h)), 1) for h in r.side_mean_curvature[sides])
    [0.0, 0.5]
    """
    pipeline.check_principal_curvature_args(radius, True)
    mesh = as_mesh(V, F)
    opts = pipeline.Options(boundary, solver=solver, rtol=DEFAULT_RTOL if rtol is None else rtol,
                            feature_angle=feature_angle, crease_edges=crease_edges)
    crease, cut, cm, (sPD1, sPD2, sPV1, sPV2, sbad) = pipeline.side_values(mesh, radius, opts)
    nV = mesh.n_vertices
    bad = [b for b in sbad if b < nV]
    return FeatureCurvature(
        PD1=np.ascontiguousarray(sPD1[:nV]), PD2=np.ascontiguousarray(sPD2[:nV]),
        PV1=np.ascontiguousarray(sPV1[:nV]), PV2=np.ascontiguousarray(sPV2[:nV]), bad_vertices=bad,
        side_PD1=sPD1, side_PD2=sPD2, side_PV1=sPV1, side_PV2=sPV2, side_parent=cut.parent,
        side_normals=cm.vertex_normals, cut=cut, creases=crease_network(mesh, crease))
