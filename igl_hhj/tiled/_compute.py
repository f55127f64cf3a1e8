"""The computation of one grown tile: the drop-in, keeping the scale its vertex stage chose.

:func:`tile_values` is the one place where a tile is computed; it takes a ``params``
dict so that a second pass (global parameters reduced from a first pass over the
cores) only adds keys.  It runs stages 5-8 of the drop-in (:func:`igl_hhj.pipeline.dropin_on_mesh`:
boundary treatment, S_h per solve group, the vertex stage of :mod:`igl_hhj.intrinsic`, principal
values and NaN rows) on the tile and returns, with the values,
the per-face smoothing radius r_T the stage used: the overlap rule
(:mod:`igl_hhj.tiled.reach`) needs it, and the drop-in reports only its median.  The
tests compare the tiled values with :func:`igl_hhj.principal_curvature` on the whole
mesh, so a change of the drop-in that these steps miss fails them.
"""
from __future__ import annotations

import warnings

import numpy as np

__all__ = ["tile_values", "PARAM_KEYS"]

PARAM_KEYS = ("radius", "rtol", "solver", "boundary")
"""Keys of ``params`` read by :func:`tile_values` (as :func:`igl_hhj.principal_curvature`)."""


def _band(mesh, seeds, rings):
    """Vertices within ``rings`` edges of the ``seeds`` (bool), as
    :func:`igl_hhj.recovery.boundary_band` from the boundary."""
    b = seeds.copy()
    E0, E1 = mesh.edges[:, 0], mesh.edges[:, 1]
    for _ in range(rings):
        g0, g1 = np.take(b, E0), np.take(b, E1)
        b[E0[g1]] = True
        b[E1[g0]] = True
    return b


def _uncut_coefficients(mesh, C0, real_boundary):
    """The smoothing's stiffness without the longer length next to the cut.

    :func:`igl_hhj.recovery.smoothing_coefficients` multiplies the stiffness of the faces
    near the boundary by ``BOUNDARY_LENGTH_FACTOR²`` (a real boundary sees half a
    neighbourhood); next to the cut the tile's surface goes on, and the stiffer band
    nearly doubled the smoothing's CG iterations (169 instead of 96 on a 550k-face tile
    of a jittered torus).  The factor is divided out on faces that are near the cut but
    not near a real boundary: exact (a power of two), and the core, ``rings`` away,
    changes by less than the rule's ε."""
    from ..constants import BOUNDARY_BAND_RINGS, BOUNDARY_LENGTH_FACTOR
    from ..recovery import boundary_band
    F = mesh.F
    near_any = boundary_band(mesh)[F].any(axis=1)
    near_real = _band(mesh, real_boundary, BOUNDARY_BAND_RINGS)[F].any(axis=1)
    fix = near_any & ~near_real
    C0[fix] /= BOUNDARY_LENGTH_FACTOR ** 2
    return C0


def _vertex_stage(mesh, S, radius, rtol, real_boundary=None):
    """Stage 7 of :func:`igl_hhj.pipeline.dropin_on_mesh` (:func:`igl_hhj.intrinsic.vertex_recovery`,
    then the smoothing of :func:`igl_hhj.intrinsic.vertex_smoothing` in one call for the mesh)
    returning the per-face radius too: ``(X, N, r (#F,))``; ``S`` is freed between the two.
    ``real_boundary`` (#V,) bool: the vertices on a boundary of the mesh (the others on the
    tile's boundary are on the cut, :func:`_uncut_coefficients`), None: all."""
    from .. import intrinsic, kernels
    from ..recovery import smoothing_coefficients
    X, rough, N, w = intrinsic.vertex_recovery(mesh, S)
    del S
    C0, m = smoothing_coefficients(mesh, w)
    if real_boundary is not None and mesh.has_boundary:
        C0 = _uncut_coefficients(mesh, C0, real_boundary)
    phase = kernels.transport_phases(mesh, N)
    status, _, _, r = intrinsic.adaptive_smoothing(mesh, X, C0, m, phase, rough, radius, rtol)
    if status != 0:          # a solve stalled: the sparse-LU smoothing, as the drop-in
        X = intrinsic.smooth_reference(mesh, X, N, w, rough, radius)
    return X, N, r


def _on_mesh(mesh, params, real_boundary=None):
    """Stages 5-8 of the drop-in on a validated mesh: ``(PD1, PD2, PV1, PV2, bad list, r (#F,))``."""
    from .. import kernels
    from ..boundary import resolve_boundary
    from ..mesh import mark_bad_vertices
    from ..pipeline import check_rtol, face_shape_operator
    rtol = check_rtol(params["rtol"])
    normals, treatment = resolve_boundary(mesh, params["boundary"], None, None)       # 5.
    mesh.vertex_normals                      # then release the cross products (the peak)
    mesh.release_face_cross_products()
    S = face_shape_operator(mesh, normals, None, None, params["solver"], rtol,            # 6.
                            estimated=treatment == "estimate")
    X, N, r = _vertex_stage(mesh, S, params["radius"], rtol, real_boundary)             # 7.
    del S
    PD1, PD2, PV1, PV2 = kernels.principal_hz(X, N)                                    # 8.
    del X                                    # NaN rows: unreferenced, no tangent plane
    return (*mark_bad_vertices(mesh, PD1, PD2, PV1, PV2, copy=False), r)


def tile_values(V, F, params, real_boundary=None):
    """The drop-in's values on one grown tile and the scale its vertex stage used.

    Parameters
    ----------
    V : (#V, 3) float64, F : (#F, 3) int64
        The grown tile, numbered on its own.
    params : dict
        ``radius``, ``rtol``, ``solver``, ``boundary`` as :func:`igl_hhj.principal_curvature`.
    real_boundary : (#V,) bool, optional
        The vertices on a boundary of the mesh; the tile's other boundary vertices are on
        its cut, where the smoothing keeps its interior length (:func:`_uncut_coefficients`).
        None: the drop-in exactly (every boundary is real).  Not used on a tile that needs
        a repair (its vertices are renumbered).

    Returns
    -------
    dict
        ``PD1, PD2`` (#V, 3), ``PV1, PV2`` (#V,) float64 (NaN rows: the drop-in's
        ``bad_vertices`` of the tile); ``radius`` (#F,) the vertex stage's per-face
        smoothing radius r_T (on a repaired tile: its largest value on every face);
        ``warnings``: the messages of the warnings the computation raised (a repair's
        :class:`igl_hhj.mesh.MeshWarning`), in order, without duplicates.
    """
    from .. import kernels
    from ..mesh import MeshDefectError, as_mesh
    from ..pipeline import on_repaired_mesh, repaired_values_to_caller
    radius_of = []

    def on_arrays(V2, F2, data):
        out = _on_mesh(as_mesh(V2, F2, copy=False), params)
        radius_of.append(out[-1])
        return out[:-1]

    with warnings.catch_warnings(record=True) as caught, kernels.large_call_heap(len(F)):
        warnings.simplefilter("always")
        try:
            mesh = as_mesh(V, F, copy=False)
        except MeshDefectError as exc:         # repairable: as the drop-in (stage 3 | repair)
            data = dict(boundary_normals=None, boundary_shape_operator=None, simply_supported=None)
            R, out = on_repaired_mesh(exc, V, F, data, on_arrays, "principal curvatures", count_lost=True)
            PD1, PD2, PV1, PV2, _ = repaired_values_to_caller(R, out)
            rmax = float(np.max(radius_of[0])) if radius_of and len(radius_of[0]) else 0.0
            r = np.full(len(F), rmax)
        else:
            PD1, PD2, PV1, PV2, _, r = _on_mesh(mesh, params, real_boundary)
    messages = list(dict.fromkeys(str(w.message) for w in caught))
    return dict(PD1=PD1, PD2=PD2, PV1=PV1, PV2=PV2, radius=np.asarray(r, dtype=np.float64),
                warnings=messages)
