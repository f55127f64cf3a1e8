"""The curvature result type shared by the estimators, the files and the viewer.

:class:`CurvatureEstimate` is what every estimator of :mod:`igl_hhj.baselines` returns,
what :func:`igl_hhj.mesh_io.write_curvature` writes and :func:`igl_hhj.mesh_io.read_curvature`
reads back, and what the viewer and the ``igl-hhj`` command show.  It holds arrays only
(no estimator, no file format): the modules that produce and consume it import it from here.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["CurvatureEstimate", "QUANTITIES"]

QUANTITIES = ("k1", "k2", "H", "K")
"""The scalar fields of a :class:`CurvatureEstimate`: principal curvatures k1 ≥ k2, mean
curvature H, Gauss curvature K."""


@dataclass(frozen=True)
class CurvatureEstimate:
    """Curvatures of one estimator, at vertices or at faces.

    Attributes
    ----------
    location : {"vertex", "face"}
        Where the values live; n = #V or #F.
    k1, k2 : (n,) float64
        Principal curvatures, ``k1 ≥ k2`` (NaN where undefined).
    H : (n,) float64
        Mean curvature ``(κ1 + κ2)/2`` as the estimator defines it.
    K : (n,) float64
        Gauss curvature as the estimator defines it.
    d1, d2 : (n, 3) float64 or None
        Unit principal directions of k1 and k2; None if the method has none.
    bad : (m,) int64
        Indices (vertices or faces) without a meaningful value (NaN rows or
        rows libigl flags / zeroes).
    name : str
        Estimator name.
    """

    location: str
    k1: NDArray[np.float64]
    k2: NDArray[np.float64]
    H: NDArray[np.float64]
    K: NDArray[np.float64]
    d1: NDArray[np.float64] | None
    d2: NDArray[np.float64] | None
    bad: NDArray[np.int64]
    name: str = ""
