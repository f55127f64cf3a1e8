"""The curvature of one mesh exactly as ``igl-hhj curvature`` and ``igl-hhj batch``
compute it, and the check of the options they take."""
from __future__ import annotations

import numpy as np

# (method, per) -> igl_hhj.baselines estimator
ESTIMATORS = {("hhj", "vertex"): "hhj_vertex", ("hhj", "face"): "hhj_face",
              ("igl", "vertex"): "libigl_quadric", ("heine", "vertex"): "heine"}
METHOD_LABELS = {"hhj": "HHJ solve", "igl": "libigl quadric fit", "heine": "Heine P1 solve"}
MAX_RADIUS = 10**6
"""Largest ``--radius`` (as :func:`igl_hhj.curvature.check_principal_curvature_args`)."""


def check_curvature_options(method, per, radius=None, feature_angle=None):
    """Raise ``ValueError`` for a combination ``igl-hhj curvature`` / ``batch`` cannot compute.

    ``radius``: hhj per vertex, the smoothing scale of :func:`igl_hhj.principal_curvature`
    (> 0); hhj per face, ``smoothing`` of :func:`igl_hhj.face_principal_curvature` (≥ 0);
    igl, libigl's k-ring (> 0); not for heine.  None: the defaults of
    :func:`default_radius`.  ``feature_angle``: degrees in (0, 180), hhj only (per face
    only unsmoothed, radius 0), see :mod:`igl_hhj.features`."""
    if method not in METHOD_LABELS:
        raise ValueError(f"unknown method {method!r} (use {', '.join(METHOD_LABELS)})")
    if per not in ("vertex", "face"):
        raise ValueError(f"unknown per {per!r} (use vertex or face)")
    if method != "hhj" and per == "face":
        raise ValueError(f"--method {method} computes per-vertex curvature only; "
                         f"use --per vertex (or --method hhj for per-face values)")
    if radius is not None:
        if method == "heine":
            raise ValueError("--radius applies to --method hhj and igl, not heine")
        if isinstance(radius, (bool, np.bool_)) or not isinstance(radius, (int, np.integer)):
            raise ValueError(f"--radius must be an integer, got {radius!r}")
        if radius < 0 or (radius == 0 and not (method == "hhj" and per == "face")):
            raise ValueError(f"--radius must be a positive integer (0 only with --per face), "
                             f"got {radius}")
        if radius > MAX_RADIUS:
            raise ValueError(f"--radius must be at most {MAX_RADIUS} (10**6), got {radius:.3g}")
    if feature_angle is not None:
        if method != "hhj":
            raise ValueError(f"--feature-angle applies to --method hhj, not {method}")
        if per == "face" and radius:
            raise ValueError("--feature-angle with --per face gives Walker's S_h of the cut surface "
                             "unsmoothed: use --radius 0 (or --per vertex)")
        from ..features import check_feature_angle
        try:
            check_feature_angle(feature_angle)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"--{exc}".replace("feature_angle", "feature-angle", 1)) from None


def default_radius(method, per):
    """The ``radius`` used when none is given: 5 per vertex (as ``igl.principal_curvature``),
    0 per face (Walker's S_h itself), None for heine."""
    if method == "heine":
        return None
    return 0 if per == "face" else 5


def _call(label, fn, *args, **kwargs):
    return fn(*args, **kwargs)


def compute_curvature(V, F, *, method="hhj", per="vertex", radius=None, keep_shape_operator=False,
                      run=None, feature_angle=None):
    """Curvature of one mesh exactly as ``igl-hhj curvature`` and ``igl-hhj batch`` compute it.

    Parameters
    ----------
    V : (#V, 3) float64, F : (#F, 3) int
        A mesh :class:`igl_hhj.mesh.TriangleMesh` accepts.
    method : {"hhj", "igl", "heine"}
    per : {"vertex", "face"} ("face": hhj only)
    radius : int, optional
        See :func:`check_curvature_options`; None: :func:`default_radius`.
    keep_shape_operator : bool
        Also return the HHJ shape operator S_h (Walker eq. 5.12), as stored in
        the ``.npz`` output; ignored for igl/heine.
    run : callable, optional
        ``run(label, fn, *args, **kwargs)`` wraps each stage (the CLI's
        progress lines); default: call ``fn``.
    feature_angle : float, optional
        hhj only: sharp features (:mod:`igl_hhj.features`), creases above this many degrees.

    Returns
    -------
    est : igl_hhj.baselines.CurvatureEstimate
    S : (#F, 3, 3) float64 or None
    """
    from .. import baselines
    check_curvature_options(method, per, radius, feature_angle)
    run = run or _call
    if radius is None:
        radius = default_radius(method, per)
    label = f"{METHOD_LABELS[method]} ({per})"
    if method == "hhj" and feature_angle is not None:
        from ..curvature import shape_operator
        hhj = baselines.hhj_face if per == "face" else baselines.hhj_vertex
        S = run(f"{METHOD_LABELS[method]} (shape operator, creases)", shape_operator, V, F,
                feature_angle=feature_angle) if keep_shape_operator or per == "face" else None
        if per == "face":                 # S_h of the cut surface itself
            return run(f"curvatures ({per})", hhj, V, F, shape_operator=S), S
        return run(label, hhj, V, F, radius=radius, feature_angle=feature_angle), S
    if method == "hhj":
        hhj = baselines.hhj_face if per == "face" else baselines.hhj_vertex
        scale = {"smoothing": radius} if per == "face" else {"radius": radius}
        if keep_shape_operator:    # solve once, keep S_h for the npz, derive the curvatures from it
            from ..curvature import shape_operator
            S = run(f"{METHOD_LABELS[method]} (shape operator)", shape_operator, V, F)
            return run(f"curvatures ({per})", hhj, V, F, shape_operator=S, **scale), S
        return run(label, hhj, V, F, **scale), None
    if method == "igl":
        return run(label, baselines.libigl_quadric, V, F, radius=radius), None
    return run(label, baselines.estimate, ESTIMATORS[method, per], V, F), None


class MeshRefusedError(ValueError):
    """The mesh of a file cannot be used: :class:`igl_hhj.mesh.TriangleMesh`'s message
    (``defect``: a repairable :class:`~igl_hhj.mesh.MeshDefectError` refused because of ``strict``)."""

    def __init__(self, message, defect=False):
        super().__init__(message)
        self.defect = defect


def compute_curvature_repairing(V, F, *, strict=False, **options):
    """:func:`compute_curvature` that repairs what :func:`igl_hhj.principal_curvature` repairs.

    A mesh :class:`igl_hhj.mesh.TriangleMesh` refuses for a repairable defect
    (:class:`igl_hhj.mesh.MeshDefectError`: non-manifold edges or vertices, duplicate,
    reversed-duplicate or flipped faces, degenerate faces, repeated corners) is repaired
    with :func:`igl_hhj.repair.repair_mesh`, the curvature is computed on the repaired mesh
    and mapped back to the caller's rows, and one :class:`igl_hhj.mesh.MeshWarning` names
    what was repaired: the drop-in's path (``igl-hhj curvature`` and ``batch``).

    Parameters
    ----------
    V : (#V, 3) float64, F : (#F, 3) int
        The mesh as read from the file.
    strict : bool
        Refuse a mesh that needs repair (the ``MeshDefectError``) instead (``--strict``).
    **options
        Those of :func:`compute_curvature`.

    Returns
    -------
    est : CurvatureEstimate
        One row per caller vertex (``per="vertex"``) or face (``per="face"``); rows left
        without a usable face by the repair, and vertices of a two-sided patch (whose sign
        is undefined), are NaN and listed in ``est.bad``.
    S : (#F, 3, 3) float64 or None
        The shape operator on the caller's faces (NaN on faces the repair dropped).
    mesh : igl_hhj.mesh.TriangleMesh
        The mesh computed on: the file's, or the repaired one.
    repaired : igl_hhj.repair.RepairedMesh or None
        The repaired mesh, None when the mesh needed no repair.

    Raises
    ------
    MeshRefusedError
        The mesh cannot be used (bad coordinates or indices, too small), or needs a repair
        and ``strict`` is set.
    """
    from ..mesh import MeshDefectError, TriangleMesh
    from ..pipeline import on_repaired_mesh
    from ..repair import seams_not_warned
    try:
        mesh = TriangleMesh(V, F)
    except MeshDefectError as exc:
        if strict:
            raise MeshRefusedError(str(exc), defect=True) from None
        defect = exc
    except (ValueError, TypeError) as exc:
        raise MeshRefusedError(str(exc)) from None
    else:
        return compute_curvature(mesh.V, mesh.F, **options) + (mesh, None)
    what = "principal curvatures" if options.get("per", "vertex") == "vertex" else "the shape operator"
    try:
        R, out = on_repaired_mesh(defect, V, F, {}, lambda V2, F2, _: compute_curvature(V2, F2, **options),
                                  what, count_lost=True, stacklevel=2)
    except ValueError as exc:                   # e.g. too small: the repair refuses it too
        raise MeshRefusedError(str(exc)) from None
    with seams_not_warned():     # its split vertices coincide on purpose (one warning: the repair's)
        mesh = TriangleMesh(R.V, R.F)
    return _to_caller(R, out) + (mesh, R)


def _to_caller(R, out):
    """``(est, S)`` on the repaired mesh ``R`` -> on the caller's rows (NaN rows listed bad)."""
    from dataclasses import replace
    from .. import repair
    if out is None:                                   # every face dropped
        raise MeshRefusedError("the repair dropped every face (see the warning): nothing left to compute on")
    est, S = out
    fields = ["k1", "k2", "H", "K"] + [d for d in ("d1", "d2") if getattr(est, d) is not None]
    values = [getattr(est, f) for f in fields]
    if est.location == "vertex":
        ambiguous = repair.two_sided_vertices(R)
        values = [np.where(ambiguous.reshape((-1,) + (1,) * (v.ndim - 1)), np.nan, v) for v in values]
        mapped = repair.vertex_values_to_caller(R, *values)
    else:
        if R.two_sided is not None:
            values = [np.where(R.two_sided.reshape((-1,) + (1,) * (v.ndim - 1)), np.nan, v) for v in values]
        mapped = repair.face_values_to_caller(R, *values)
    bad = ~np.all([np.isfinite(m).reshape(len(m), -1).all(axis=1) for m in mapped], axis=0)
    for m in mapped:
        m[bad] = np.nan
    est = replace(est, bad=np.flatnonzero(bad), **dict(zip(fields, mapped)))
    if S is not None:
        if R.two_sided is not None:
            S = np.where(R.two_sided[:, None, None], np.nan, S)
        S = repair.face_values_to_caller(R, S)[0]
    return est, S
