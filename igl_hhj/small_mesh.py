"""The drop-in on small closed meshes in one compiled call (issue 24: fixed cost per call).

:func:`igl_hhj.principal_curvature` validates the mesh, builds its topology, assembles
and solves the HHJ system, forms S_h, recovers and smooths it at the vertices and
solves the 2×2 eigen-problems in some forty Python steps of a few microseconds each:
0.3 ms on a 12-face cube, where ``igl.principal_curvature`` takes 0.05 ms.  Code that
calls the drop-in per frame or over thousands of small parts pays that.

:func:`try_dropin` runs the same compiled kernels in the same order on the same
inputs in one call (``_hhj_core.dropin_small``, ``igl_hhj/_core/small_mesh.cpp``):
libigl's vertex normals and cotangent entries are computed here (libigl does what
libigl does), everything else in the kernel.  It applies to a closed mesh with at
most :data:`igl_hhj.solvers.ENVELOPE_MAX` edges (the general path's direct solver
there is the same envelope LDLᵀ) given as numpy arrays, with the default boundary
options.  Whenever the general path would do anything else -- raise, warn, repair,
estimate boundary normals, split components into solve groups of another solver,
fall back to another solver -- the kernel returns a nonzero status and
:func:`try_dropin` returns None: the caller takes the general path, which then does
exactly that.  ``tests/test_small_mesh.py`` asserts that both paths give the same
values (to round-off) on closed, multi-component, folded and unreferenced-vertex
meshes, and that every defect class goes to the general path.
"""
from __future__ import annotations

import numpy as np

__all__ = ["try_dropin", "MAX_EDGES"]

from .solvers import ENVELOPE_MAX as MAX_EDGES

_PARAMS = None


def _params():
    """The general path's constants, in the order of ``_hhj_core.dropin_small``."""
    global _PARAMS
    if _PARAMS is None:
        from . import intrinsic as it
        from .mesh import DEGENERATE_AREA_RTOL, FOLDED_NORMAL_RTOL, MIN_MESH_SIZE
        from .recovery import QUALITY_FLOOR, SMOOTHING_PER_RADIUS, _kernel_coefficients
        from .solvers import DIRECT_RESIDUAL_RTOL
        checks = (DEGENERATE_AREA_RTOL, MIN_MESH_SIZE, FOLDED_NORMAL_RTOL, QUALITY_FLOOR,
                  DIRECT_RESIDUAL_RTOL, MAX_EDGES)
        smoothing = (SMOOTHING_PER_RADIUS, float(it.PILOT_RADIUS), float(it.ADAPTIVE_GAIN),
                     float(it.ADAPTIVE_POWER), float(it.ADAPTIVE_RANGE[0]), float(it.ADAPTIVE_RANGE[1]),
                     int(it.SMOOTHING_STEPS))
        binom = [float(c) for c in _kernel_coefficients(it.SMOOTHING_ORDER)]
        _PARAMS = (checks, smoothing, binom, it.smoothing_rtol)
    return _PARAMS


def try_dropin(V, F, radius, rtol):
    """:func:`igl_hhj.principal_curvature` ``(V, F, radius)`` in one compiled call, or None.

    Parameters
    ----------
    V : (#V, 3) numpy array (float64 or float32; anything else: None)
    F : (#F, 3) numpy integer array
    radius : float ≥ 0, the checked smoothing radius
    rtol : float, the checked solver tolerance

    Returns
    -------
    ``(PD1, PD2, PV1, PV2, bad_vertices)`` as :func:`igl_hhj.principal_curvature`, or
    None when the mesh is not a small clean closed mesh (the general path must run).
    """
    if type(V) is not np.ndarray or type(F) is not np.ndarray or V.ndim != 2 or F.ndim != 2 \
            or V.shape[1] != 3 or F.shape[1] != 3 or not 0 < 3 * F.shape[0] <= 2 * MAX_EDGES \
            or V.shape[0] == 0 or F.dtype.kind not in "iu" or V.dtype.kind != "f":
        return None
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    # the general path's coordinate and index checks (NaN fails the comparison)
    if not np.abs(V).max() <= _coordinate_max() or F.min() < 0 or F.max() >= V.shape[0]:
        return None
    import igl

    from . import _hhj_core
    checks, smoothing, binom, smoothing_rtol = _params()
    N = igl.per_vertex_normals(V, F, _AREA())
    cot = igl.cotmatrix_entries(V, F)
    srtol = smoothing_rtol(rtol)
    status, PD1, PD2, PV1, PV2, bad = _hhj_core.dropin_small(
        V, F, np.ascontiguousarray(N, dtype=np.float64), np.ascontiguousarray(cot, dtype=np.float64), checks,
        (float(radius), smoothing[0], smoothing[1], srtol, *smoothing[2:], 500), binom)
    if status != 0:
        return None
    return PD1, PD2, PV1, PV2, np.flatnonzero(bad).tolist()


def _coordinate_max():
    from .mesh import COORDINATE_MAX
    return COORDINATE_MAX


def _AREA():
    import igl
    return igl.PerVertexNormalsWeightingType.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA
