"""Stage 2 of the drop-in (:mod:`igl_hhj.pipeline`): a small mesh in one compiled call.

Internal: the pipeline calls :func:`try_dropin`; it is not part of the public API.

:func:`igl_hhj.principal_curvature` validates the mesh, builds its topology, estimates
the boundary normals of an open mesh, assembles and solves the HHJ system, forms S_h,
recovers and smooths it at the vertices and solves the 2×2 eigen-problems in some
forty Python steps of a few microseconds each: 0.3 ms on a 12-face cube and 1 ms on an
18-face open grid, where ``igl.principal_curvature`` takes 0.05 and 0.12 ms.  Code that
calls the drop-in per frame or over thousands of small parts pays that.

:func:`try_dropin` runs the same computation in one call (:func:`igl_hhj.kernels.dropin_small`,
``igl_hhj/_core/small_mesh.cpp``): the same compiled kernels in the same order on the
same inputs, and the numpy glue between them (the boundary-normal fall-backs of
:func:`igl_hhj.boundary_estimation.estimate_boundary_normals`, Walker's clamped load
:func:`igl_hhj.boundary.clamped_load`, :func:`igl_hhj.recovery.smoothing_coefficients`, the
bad-vertex rules) with the same floating-point operations in the same order, so the
values are the general path's bit for bit.  The constants are those of
:mod:`igl_hhj.constants`; libigl's vertex normals and cotangent entries are computed here
(libigl does what libigl does).

It applies to a mesh with at most :data:`MAX_EDGES` (:data:`igl_hhj.constants.ENVELOPE_MAX`)
edges, where the general path's direct solver is the same envelope LDLᵀ, given as numpy
arrays, with the default options (open meshes with ``boundary="estimate"``).  Whenever
the general path would do anything else -- raise, warn (an unwelded mesh), repair, use
another solver or fall back to one -- the kernel returns a nonzero status and
:func:`try_dropin` returns None: the caller takes the general path, which then does
exactly that.  ``tests/vertex_stage/test_small_mesh.py`` asserts that both paths give the
same bits on closed, open, multi-component, folded and unreferenced-vertex meshes, and
that every defect class goes to the general path.
"""
from __future__ import annotations

import igl
import numpy as np

from . import kernels
from .constants import (ADAPTIVE_GAIN, ADAPTIVE_POWER, ADAPTIVE_RANGE, BOUNDARY_BAND_RINGS,
                        BOUNDARY_LENGTH_FACTOR, COORDINATE_MAX, DEGENERATE_AREA_RTOL, DIRECT_RESIDUAL_RTOL,
                        FIT_RINGS, FOLDED_NORMAL_RTOL, MIN_MESH_SIZE, PILOT_RADIUS, QUALITY_FLOOR,
                        SIDE_DOT_MIN, SMOOTHING_MAXITER, SMOOTHING_ORDER, SMOOTHING_PER_RADIUS, SMOOTHING_STEPS)
from .constants import ENVELOPE_MAX as MAX_EDGES
from .intrinsic import smoothing_rtol
from .recovery import kernel_coefficients

__all__ = ["try_dropin", "MAX_EDGES"]

# the general path's constants in the order of _core/small_mesh.cpp's SmallParams
_HEAD = (DEGENERATE_AREA_RTOL, MIN_MESH_SIZE, FOLDED_NORMAL_RTOL, QUALITY_FLOOR, DIRECT_RESIDUAL_RTOL, MAX_EDGES)
_TAIL = (int(FIT_RINGS), float(SIDE_DOT_MIN), int(BOUNDARY_BAND_RINGS), float(BOUNDARY_LENGTH_FACTOR))
_CHECKS = {b: _HEAD + (b == "estimate",) + _TAIL for b in ("estimate", "plain")}
_SMOOTHING = (SMOOTHING_PER_RADIUS, float(PILOT_RADIUS), float(ADAPTIVE_GAIN), float(ADAPTIVE_POWER),
              float(ADAPTIVE_RANGE[0]), float(ADAPTIVE_RANGE[1]), int(SMOOTHING_STEPS))
_BINOM = [float(c) for c in kernel_coefficients(SMOOTHING_ORDER)]
_AREA = igl.PerVertexNormalsWeightingType.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA


def try_dropin(V, F, radius, rtol, boundary="estimate"):
    """:func:`igl_hhj.principal_curvature` ``(V, F, radius)`` in one compiled call, or None.

    Parameters
    ----------
    V : (#V, 3) numpy array (float64 or float32; anything else: None)
    F : (#F, 3) numpy integer array
    radius : float ≥ 0, the checked smoothing radius
    rtol : float, the checked solver tolerance
    boundary : {"estimate", "plain"}: open meshes with "plain" take the general path

    Returns
    -------
    ``(PD1, PD2, PV1, PV2, bad_vertices)`` as :func:`igl_hhj.principal_curvature`, or
    None when the mesh is not a small clean mesh or the options are not the defaults
    (the general path must run).
    """
    if type(V) is not np.ndarray or type(F) is not np.ndarray or V.ndim != 2 or F.ndim != 2 \
            or V.shape[1] != 3 or F.shape[1] != 3 or not 0 < 3 * F.shape[0] <= 2 * MAX_EDGES \
            or V.shape[0] == 0 or F.dtype.kind not in "iu" or V.dtype.kind != "f":
        return None
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    # the general path's coordinate and index checks (NaN fails the comparison), before
    # libigl reads the arrays
    if not np.abs(V).max() <= COORDINATE_MAX or F.min() < 0 or F.max() >= V.shape[0]:
        return None
    N = igl.per_vertex_normals(V, F, _AREA)
    cot = igl.cotmatrix_entries(V, F)
    status, PD1, PD2, PV1, PV2, bad = kernels.dropin_small(
        V, F, np.ascontiguousarray(N, dtype=np.float64), np.ascontiguousarray(cot, dtype=np.float64),
        _CHECKS[boundary],
        (float(radius), _SMOOTHING[0], _SMOOTHING[1], smoothing_rtol(rtol), *_SMOOTHING[2:], int(SMOOTHING_MAXITER)),
        _BINOM)
    if status != 0:
        return None
    return PD1, PD2, PV1, PV2, np.flatnonzero(bad).tolist()
