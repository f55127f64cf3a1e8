"""Public curvature API: Walker's HHJ shape operator, the HHJ surface Hessian,
per-face curvatures, and the drop-in ``principal_curvature``.

The functions here check their arguments and hold the documentation; the drop-in and the
shape operator run as one sequence in :mod:`igl_hhj.pipeline`.

Sign convention (libigl's and Walker's): with outward normals (F oriented so
that ``(x1 - x0) × (x2 - x0)`` points out), a sphere of radius R has shape
operator ``P / R`` and principal curvatures ``+1/R``.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal, Union, overload

import igl  # noqa: F401  (imported with the public API, not inside the first call: its first call costs as the later ones)
import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import intrinsic as _intrinsic
from . import kernels, pipeline
from . import recovery as _recovery
from .boundary import check_boundary, check_magnitude, clamped_load, data_rows
from .constants import DEFAULT_RTOL
from .mesh import MeshDefectError, _as_array, as_mesh, per_vertex_array
from .repair import face_values_to_caller
from .solvers import HHJSystem
# the pipeline's entry points, named here as before
from .pipeline import check_principal_curvature_args, dropin_on_mesh, dropin_vertex_values  # noqa: F401
from .pipeline import face_shape_operator as _shape_operator  # noqa: F401 (the benchmarks' name)

__all__ = [
    "shape_operator", "surface_hessian", "principal_curvature",
    "face_principal_curvature", "face_mean_curvature", "face_gaussian_curvature",
    "principal_from_shape_operator", "vertex_shape_operator", "vertex_principal_curvature",
    "check_principal_curvature_args", "boundary_treatment", "smoothed_face_shape_operator",
    "dropin_vertex_values", "dropin_on_mesh", "curvature_of", "CURVATURE_KINDS", "CURVATURE_KIND_ALIASES", "CURVATURE_PER",
]


def boundary_treatment(V: Any, F: ArrayLike | None, *, boundary: str = "estimate",
                       boundary_normals: ArrayLike | None = None,
                       boundary_shape_operator: ArrayLike | None = None) -> str:
    """Which boundary treatment :func:`shape_operator` applies to this mesh and these arguments.

    Returns
    -------
    str : "none" (closed mesh), "data" (the caller's boundary data), "estimate"
        (clamped with estimated O(h²) normals) or "plain" (plain assembly).
    """
    mesh = as_mesh(V, F)
    check_boundary(boundary)
    if not mesh.has_boundary:
        return "none"
    if boundary_normals is not None or boundary_shape_operator is not None:
        return "data"
    return boundary


@kernels.with_large_call_heap
def shape_operator(V: Any, F: ArrayLike | None = None, *, boundary: str = "estimate",
                   boundary_normals: ArrayLike | None = None,
                   boundary_shape_operator: ArrayLike | None = None, simply_supported: ArrayLike | None = None,
                   solver: str = "auto", rtol: float = DEFAULT_RTOL, repair: bool = False,
                   feature_angle: float | None = None,
                   crease_edges: ArrayLike | None = None) -> NDArray[np.float64]:
    """Walker's HHJ approximation S_h of the shape operator ∇_Γν, one tensor per face.

    Solves ``A s^k = -B X^k + g^k`` for the three coordinate functions
    (Walker eq. 5.14 for closed surfaces, eq. 5.19 with boundary) and sets
    ``S_h|_T = -Σ_k ν_T^k σ^k_h|_T`` (eq. 5.12).  Converges like O(h) in L2 on
    irregular piecewise-linear meshes (Theorem 5.2/5.3).

    Parameters
    ----------
    V : (#V, 3) array_like of float
        Vertex positions.
    F : (#F, 3) array_like of int
        Consistently oriented triangles (never reordered).
    boundary : {"estimate", "plain"}, default "estimate"
        What to do on an open mesh *without* boundary data: "estimate" makes
        the boundary edges clamped with O(h²) normals fitted to the mesh
        (:func:`igl_hhj.boundary_estimation.estimate_boundary_normals`), which
        keeps the O(h) rate up to the boundary; "plain" is Walker's plain
        assembly (the face normal stands in for the true one: about O(h^1/2)
        in L2 near the boundary, no convergence in L∞).  Ignored when
        boundary data is given or the mesh is closed.
    boundary_normals : (#V, 3) array_like, optional
        True unit surface normals at (at least) the boundary vertices; boundary
        edges not simply supported become *clamped* edges with this data
        (Σ_c of eq. 5.19, normals interpolated linearly along each edge).
        Must agree with F's orientation.
    boundary_shape_operator : (#V, 3, 3) array_like, optional
        True shape operator ∇_Γν at (at least) the boundary vertices; boundary
        edges become *simply supported* (Σ_s, eq. 5.18): their DOFs are fixed
        to ``-ν_T^k nᵀS~n``.
    simply_supported : (#V,) bool array, optional
        With both data arrays: boundary edges whose two endpoints are flagged
        are simply supported, the other boundary edges clamped.
    solver : {"auto", "cg", "direct"}
        Linear solver for A (strategy in :mod:`igl_hhj.solvers`): "auto" picks
        sparse Cholesky or the compiled face-Schwarz PCG by measured cost.
    rtol : float, default :data:`igl_hhj.solvers.DEFAULT_RTOL` (1e-6)
        Relative residual of the iterative solve, per coordinate right-hand
        side; the default leaves a solver error far below the O(h)
        discretisation error (see :mod:`igl_hhj.solvers`).
    repair : bool, default False
        True: a mesh refused for a repairable defect (non-manifold edges or
        vertices, duplicate or reversed-duplicate faces, inconsistent
        orientation, non-orientable patches, degenerate faces, repeated
        corners) is repaired as in :func:`principal_curvature` (one
        :class:`~igl_hhj.mesh.MeshWarning`); rows of dropped faces are NaN,
        in the caller's F order.  False: such meshes raise ``ValueError``.
    feature_angle : float, optional (default None: off)
        Cut the surface along the edges whose dihedral angle exceeds ``feature_angle``
        degrees and clamp each side with its own estimated normals
        (:func:`igl_hhj.features.feature_shape_operator`); the creases' curvature (a
        line measure) is then not in S_h but in :func:`igl_hhj.features.crease_network`.
    crease_edges : (k, 2) array_like of int, optional
        Creases named by their vertex pairs (either order), cut in addition to those of
        ``feature_angle`` (alone when ``feature_angle`` is None): scanned or CAD creases
        that are known rather than detected (:func:`igl_hhj.features.crease_edges`).

    Returns
    -------
    S : (#F, 3, 3) float64
        Symmetric tensors, tangential to each face (``S[f] @ ν_f ≈ 0``).

    Raises
    ------
    SolverError
        The solve did not give a finite S_h (``.faces`` lists the faces).

    Notes
    -----
    Without boundary data and with ``boundary="plain"``, boundary edges get
    the *plain assembly* (the face normal stands in for the true one); the
    method still runs on any mesh but its rate near the boundary drops to
    about O(h^1/2).  Triangles with all
    three vertices on the boundary (excluded by Walker's Property 1) are
    allowed: A stays SPD; their values are least accurate.

    Examples
    --------
    >>> import numpy as np, igl_hhj
    >>> from igl_hhj.surfaces import icosphere
    >>> V, F = icosphere(3)                       # unit sphere, outward normals
    >>> S = igl_hhj.shape_operator(V, F)
    >>> S.shape
    (1280, 3, 3)
    >>> round(float(np.median(np.trace(S, axis1=1, axis2=2))), 2)   # κ1 + κ2 = 2/R
    2.0
    """
    return pipeline.shape_operator(V, F, pipeline.Options(
        boundary, boundary_normals, boundary_shape_operator, simply_supported, solver, rtol, feature_angle,
        crease_edges), repair_defects=repair)


@kernels.with_large_call_heap
def surface_hessian(V: Any, F: ArrayLike | None, w: ArrayLike, *, boundary_gradient: ArrayLike | None = None,
                    solver: str = "auto", rtol: float = DEFAULT_RTOL, repair: bool = False) -> NDArray[np.float64]:
    """HHJ projection of the surface Hessian ∇_Γ∇_Γ w of a P1 function (Walker eq. 4.9).

    Parameters
    ----------
    V, F : mesh (see :func:`shape_operator`).
    w : (#V,) or (#V, k) array_like
        Vertex values of one (or k) piecewise-linear functions.
    boundary_gradient : (#V, 3) or (#V, k, 3) array_like, optional
        True surface gradient of w at (at least) the boundary vertices: clamped
        boundary data (eq. 3.12's Σ_c term). Without it, the plain assembly.
    solver : {"auto", "cg", "direct"}
    repair : bool, default False
        True: a mesh refused for a repairable defect is repaired as in
        :func:`shape_operator` (``w`` and ``boundary_gradient`` follow the
        repaired vertices; one :class:`~igl_hhj.mesh.MeshWarning`); rows of
        dropped faces are NaN, in the caller's F order.  False: such meshes
        raise ``ValueError``.

    Returns
    -------
    H : (#F, 3, 3) (or (#F, k, 3, 3)) float64, symmetric tangential tensors.
    Examples
    --------
    >>> import igl_hhj
    >>> from igl_hhj.surfaces import icosphere
    >>> V, F = icosphere(3)
    >>> igl_hhj.surface_hessian(V, F, V[:, 2] ** 2).shape   # (#F, 3, 3), one tensor per face
    (1280, 3, 3)
    """
    try:
        mesh = as_mesh(V, F)
    except MeshDefectError as exc:       # repairable: only on request
        if not repair:
            raise
        R, H = pipeline.on_repaired_mesh(exc, V, F, dict(w=w, boundary_gradient=boundary_gradient),
                                         lambda V2, F2, data: surface_hessian(V2, F2, solver=solver, rtol=rtol, **data),
                                         "the surface Hessian", stacklevel=4)
        return face_values_to_caller(R, np.zeros((0,) + np.shape(w)[1:] + (3, 3)) if H is None else H)[0]
    w_arr = _as_array(w, "w")             # np.asarray dropped a mask silently
    single = w_arr.ndim == 1
    if single:
        W = per_vertex_array(mesh, w_arr, "w")[:, None]
    else:
        if w_arr.ndim != 2:
            raise ValueError("w is required: the (#V,) or (#V, k) vertex values of the function(s) to differentiate" if w is None else f"w must have shape (#V,) or (#V, k), got {w_arr.shape}")
        W = per_vertex_array(mesh, w_arr, "w", (w_arr.shape[1],))
    ref = mesh.referenced_vertices
    if not np.isfinite(W[ref]).all():
        raise ValueError(f"w has NaN or inf at vertex {int(np.flatnonzero(~np.isfinite(W).all(1) & ref)[0])}")
    W = np.where(np.isfinite(W), W, 0.0)
    check_magnitude(W, np.arange(len(W)), "w")
    rtol = pipeline.check_rtol(rtol)
    rhs = -kernels.jump_apply(mesh, W)                        # -B w, (#E, k)
    bnd = mesh.boundary_edges
    if boundary_gradient is not None and mesh.has_boundary:
        G = _as_array(boundary_gradient, "boundary_gradient")
        G = per_vertex_array(mesh, G, "boundary_gradient", (3,))[:, None, :] if single \
            else per_vertex_array(mesh, G, "boundary_gradient", (W.shape[1], 3))
        data_rows(mesh, G, bnd, "boundary_gradient")
        G = np.where(np.isfinite(G), G, 0.0)
        rhs[bnd] += clamped_load(mesh, bnd, G)[bnd]
    else:
        rhs[bnd] = 0.0                                        # plain assembly
    s, _ = HHJSystem(mesh).solve(rhs, solver, rtol)
    H = kernels.face_tensors(mesh, s)
    return H[:, 0] if single else H


def principal_from_shape_operator(S: NDArray[np.floating], normals: NDArray[np.floating]
                                  ) -> tuple[NDArray[np.float64], ...]:
    """Principal curvatures and directions of tangential tensors.

    Parameters
    ----------
    S : (n, 3, 3) symmetric tensors (tangential to ``normals``).
    normals : (n, 3) unit normals of the tangent planes.

    Returns
    -------
    PD1, PD2 : (n, 3) unit principal directions (PD2 = normal × PD1).
    PV1, PV2 : (n,) principal curvatures, PV1 ≥ PV2: the eigenvalues of the
        tangential 2×2 block of S.

    Notes
    -----
    Compiled closed-form 2×2 eigen-solve (:func:`igl_hhj.kernels.principal_2x2`)
    in the tangent frame ``e1 = N × a / |N × a|`` (a the coordinate axis least
    aligned with N), ``e2 = N × e1``; the numpy ``eigh`` reference is
    :func:`_principal_from_shape_operator_reference`.  Where κ1 = κ2 the
    direction is arbitrary (both implementations pick some unit tangent).
    """
    S = np.asarray(S, dtype=np.float64)
    N = np.asarray(normals, dtype=np.float64)
    if S.ndim != 3 or S.shape[1:] != (3, 3) or N.shape != (S.shape[0], 3):
        raise ValueError(f"S must be (n, 3, 3) and normals (n, 3), got {S.shape} and {N.shape}")
    return kernels.principal_2x2(S, N)


@kernels.with_large_call_heap
def face_principal_curvature(V: Any, F: ArrayLike | None = None, *, smoothing: float = 0,
                             **boundary: Any) -> tuple[NDArray[np.float64], ...]:
    """Per-face principal curvatures and directions from the HHJ shape operator.

    Parameters
    ----------
    V, F : mesh (see :func:`shape_operator`).
    smoothing : float, default 0
        Smoothing scale in the units of :func:`principal_curvature`'s ``radius``
        (rings ≈ mean edge lengths).  0: Walker's S_h itself.  > 0: S_h is
        recovered at the vertices and smoothed as by :func:`principal_curvature`
        with ``radius = smoothing`` (the per-face adaptive length
        ``ℓ_T = SMOOTHING_PER_RADIUS · r_T · h_T``, see there;
        :func:`vertex_shape_operator`), and each face gets the mean of its three
        vertex tensors projected onto its plane.
    **boundary : ``boundary``, boundary data, ``solver`` of :func:`shape_operator`.

    Returns
    -------
    PD1, PD2 : (#F, 3) unit directions of maximal / minimal curvature in the
        face plane (PD2 = ν_T × PD1).
    PV1, PV2 : (#F,) principal curvatures κ1 ≥ κ2.
    Examples
    --------
    >>> import igl_hhj
    >>> from igl_hhj.surfaces import icosphere
    >>> PD1, PD2, PV1, PV2 = igl_hhj.face_principal_curvature(*icosphere(3))
    >>> PD1.shape, PV1.shape
    ((1280, 3), (1280,))
    """
    mesh = as_mesh(V, F)
    S = shape_operator(mesh, None, **boundary)   # the validated mesh passes through as_mesh
    S = smoothed_face_shape_operator(mesh, S, smoothing)
    return principal_from_shape_operator(S, mesh.face_normals)


def smoothed_face_shape_operator(mesh, S, smoothing):
    """Face tensors at smoothing scale ``smoothing`` (see :func:`face_principal_curvature`).

    Returns S itself for ``smoothing == 0``; otherwise (#F, 3, 3) symmetric
    tensors tangential to each face."""
    _check_smoothing(smoothing, "smoothing")
    if smoothing == 0:
        return S
    Sv, N = vertex_shape_operator(mesh, S, smoothing=smoothing)
    Sf = np.nanmean(Sv[mesh.F], axis=1)
    return _recovery.tangent_projection(Sf, mesh.face_normals)


def _check_smoothing(x, name):
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be a number, got {type(x).__name__}")
    if not 0 <= x <= 10**6:                 # also NaN, inf and ints beyond float64
        raise ValueError(f"{name} must be finite, >= 0 and <= 10**6, got {x:.3g}")


def face_mean_curvature(V: Any, F: ArrayLike | None = None, **boundary: Any) -> NDArray[np.float64]:
    """Per-face mean curvature H = (κ1 + κ2)/2 = tr(S_h)/2 (Walker's κ^a / 2), shape (#F,)."""
    S = shape_operator(V, F, **boundary)
    return 0.5 * np.trace(S, axis1=1, axis2=2)


def face_gaussian_curvature(V: Any, F: ArrayLike | None = None, **boundary: Any) -> NDArray[np.float64]:
    """Per-face Gauss curvature K = κ1 κ2 = det(S_h + ν_T ⊗ ν_T) (Walker eq. 6.1), shape (#F,)."""
    mesh = as_mesh(V, F)
    S = shape_operator(mesh, None, **boundary)
    nu = mesh.face_normals
    return np.linalg.det(S + nu[:, :, None] * nu[:, None, :])


def vertex_principal_curvature(mesh, Sv, N):
    """Principal directions/curvatures of per-vertex tensors, NaN at unreferenced vertices.

    Parameters
    ----------
    Sv : (#V, 3, 3) per-vertex tensors (tangential to N), N : (#V, 3) unit normals.

    Returns
    -------
    PD1, PD2 : (#V, 3), PV1, PV2 : (#V,) as :func:`principal_from_shape_operator`.
    """
    ref = mesh.referenced_vertices
    if ref.all():                       # no masked copies of the (#V, 3, 3) tensors
        return principal_from_shape_operator(Sv, N)
    nV = mesh.n_vertices
    PD1 = np.full((nV, 3), np.nan)
    PD2 = np.full((nV, 3), np.nan)
    PV1 = np.full(nV, np.nan)
    PV2 = np.full(nV, np.nan)
    PD1[ref], PD2[ref], PV1[ref], PV2[ref] = principal_from_shape_operator(Sv[ref], N[ref])
    return PD1, PD2, PV1, PV2


def vertex_shape_operator(mesh, S, *, smoothing=0, recovery="intrinsic"):
    """Recover per-vertex tensors from face tensors, optionally smoothed.

    ``recovery="intrinsic"`` (default, the drop-in's vertex stage,
    :mod:`igl_hhj.intrinsic`): every face tensor is carried into the tangent plane
    of its vertices by the minimal rotation ν_T → N_v, fitted there by a weighted
    linear least-squares patch fit, and (``smoothing > 0``) smoothed by the twiced
    implicit diffusion of its trace (scalar cotangent Laplacian) and its deviator
    (spin-2 connection Laplacian) at the per-face length
    ``ℓ_T = SMOOTHING_PER_RADIUS · r_T · h_T``, ``r_T`` the adaptive radius at scale
    ``smoothing`` (see :func:`principal_curvature`'s ``radius``).

    The ambient variants, kept for comparison (numpy, :mod:`igl_hhj.recovery`), average
    the 3×3 tensors of the incident faces and project the result onto the vertex plane
    (biased where the normal turns fast, e.g. thin tubes): "patch" (linear fit), "lumped"
    (weighted average) and "consistent" (consistent-mass L2 projection), each followed for
    ``smoothing > 0`` by :func:`igl_hhj.recovery.smooth_vertex_tensors` at the global length
    ``ℓ = SMOOTHING_PER_RADIUS · smoothing · h̄``.

    Returns
    -------
    Sv : (#V, 3, 3) float64 symmetric tangential tensors (NaN rows for unreferenced vertices)
    N : (#V, 3) vertex normals used
    """
    _check_smoothing(smoothing, "smoothing")
    if recovery == "intrinsic":
        X, N = _intrinsic.vertex_stage(mesh, S, smoothing)
        Sv = _intrinsic.to_tensors(X, N)
        Sv[~mesh.referenced_vertices] = np.nan
        return Sv, N
    w = _recovery.recovery_weights(mesh)          # one computation for recovery and smoothing
    Sv, N = _recovery.recover_vertex_tensors(mesh, S, method=recovery, weights=w)
    if smoothing > 0:
        Sv = _recovery.smooth_vertex_tensors(mesh, Sv, N, _recovery.smoothing_length(mesh, smoothing),
                                             weights=w)
    return Sv, N


@kernels.with_large_call_heap
def principal_curvature(V: Any, F: ArrayLike | None = None, radius: int = 5, useKring: bool = True, *,
                        boundary: str = "estimate",
                        boundary_normals: ArrayLike | None = None, boundary_shape_operator: ArrayLike | None = None,
                        simply_supported: ArrayLike | None = None, solver: str = "auto",
                        rtol: float = DEFAULT_RTOL, feature_angle: float | None = None,
                        crease_edges: ArrayLike | None = None
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                                   list[int]]:
    """Drop-in replacement for ``igl.principal_curvature`` (libigl ≥ 2.5.4 / 2.6).

    Same call forms, same return tuple, shapes, dtypes, ordering and sign, but
    the values come from Walker's convergent HHJ shape operator
    (:func:`shape_operator`), recovered at the vertices and smoothed at the
    scale ``radius`` (:func:`vertex_shape_operator`), then a 2×2 eigen-problem
    (the stages: :mod:`igl_hhj.pipeline`).

    Parameters
    ----------
    V : (#V, 3) array_like
        Vertex positions.
    F : (#F, 3) array_like
        Triangle indices.
    radius : int, default 5
        Smoothing scale, as libigl's neighbourhood size in rings (``useKring``) or
        mean edge lengths (``useKring=False``): for this estimator the two are the
        same scale.  The recovered tensor field is smoothed by a twiced implicit
        diffusion whose length is set per face (:mod:`igl_hhj.intrinsic`):
        ``ℓ_T = SMOOTHING_PER_RADIUS · r_T · h_T`` with h_T the face's mean edge
        length, ``SMOOTHING_PER_RADIUS`` = 0.2, and the adaptive radius
        ``r_T = radius · mean_{v∈T} a_v``, ``a_v = clip(0.3 ρ̄_v^{1/4} / c̄_v, 0.2, 5)``:
        ρ̄ the measured roughness of S_h around the vertex, c̄ the curvature of a
        pilot smoothing step times the local edge length (constants:
        :mod:`igl_hhj.constants`).  At the default radius a smooth mesh gets
        r_T ≈ 1–9, thin features (c̄ large) ``0.2 · radius``, noisy scans up to
        ``5 · radius``; within 2 rings of an open boundary ℓ_T is twice as long.
        Larger: less noise, more bias.  ℓ_T follows the local edge length (the
        tests measure the O(h) rate at the default radius).
    useKring : bool, default True
        Accepted for compatibility (see ``radius``).
    boundary : {"estimate", "plain"}, default "estimate"
        Open meshes without boundary data: clamped with estimated O(h²) normals
        (converges up to the boundary) or the plain assembly (see
        :func:`shape_operator`).
    boundary_normals, boundary_shape_operator, simply_supported, solver, rtol
        Keyword-only extras, see :func:`shape_operator`.
    feature_angle : float, optional (keyword-only; default None: off, libigl's contract)
        Sharp features: edges whose dihedral angle exceeds ``feature_angle``
        degrees are creases; the surface is cut along them and each side is clamped
        with its own one-sided normals, so that the smooth parts converge up to the
        crease and no value is averaged across it
        (:func:`igl_hhj.features.feature_principal_curvature`).  A crease vertex gets
        the values of its side with the largest incident area; the per-side values and
        the crease's own line measure θ_e ℓ_e are in the richer
        :func:`igl_hhj.features.feature_principal_curvature`.  Only with
        ``boundary="estimate"`` and without boundary data.
    crease_edges : (k, 2) array_like of int, optional (keyword-only)
        Creases named by their vertex pairs (either order), cut in addition to those of
        ``feature_angle`` (alone when ``feature_angle`` is None), e.g. the sharp edges a
        CAD exporter marks (:func:`igl_hhj.features.crease_edges`).  Not with a mesh that
        needs repair (its vertices are renumbered): repair it first
        (:func:`igl_hhj.repair.repair_mesh`).

    Returns
    -------
    PD1 : (#V, 3) float64, unit direction of maximal curvature
    PD2 : (#V, 3) float64, unit direction of minimal curvature (N × PD1)
    PV1 : (#V,) float64, maximal curvature
    PV2 : (#V,) float64, minimal curvature (PV1 ≥ PV2)
    bad_vertices : list of int
        Exactly the vertices whose rows are NaN: unreferenced vertices and
        vertices without a tangent plane (two-sided or folded sheets, see
        :func:`igl_hhj.mesh.mark_bad_vertices`).  Empty for a mesh without them.

    Repairs
    -------
    Meshes that libigl accepts but the strict functions refuse are repaired
    (:func:`igl_hhj.repair.repair_mesh`) only after the strict validation has
    failed: faces with a repeated corner, degenerate or sliver faces and
    duplicate (also reversed) faces are dropped, non-manifold edges and
    vertices split, each patch oriented consistently and then to the caller's
    majority orientation of that patch (so the signs are the caller's), and
    non-orientable (Möbius) patches removed.  The values are computed on the
    repaired mesh and mapped back (a split vertex takes its copy with the
    largest incident area); vertices left without a usable face are NaN and
    listed in ``bad_vertices``.  One :class:`igl_hhj.mesh.MeshWarning` names
    what was repaired.  Bad coordinates, shapes or indices still raise.

    Positive curvature on a sphere with outward normals, as libigl.
    Examples
    --------
    >>> import numpy as np, igl_hhj
    >>> from igl_hhj.surfaces import icosphere
    >>> V, F = icosphere(3)
    >>> PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(V, F)   # as igl.principal_curvature(V, F)
    >>> PV1.shape, bad
    ((642,), [])
    >>> round(float(np.median(PV1)), 2)         # +1/R on a sphere with outward normals
    1.0
    """
    return pipeline.principal_curvature(V, F, radius, useKring, pipeline.Options(
        boundary, boundary_normals, boundary_shape_operator, simply_supported, solver, rtol, feature_angle,
        crease_edges))


# --------------------------------------------------------------------------- one call, any mesh
CURVATURE_KINDS = ("mean", "gauss", "k1", "k2", "directions")
"""The quantities of :func:`curvature_of` (canonical names)."""
CURVATURE_KIND_ALIASES = {"gaussian": "gauss", "H": "mean", "K": "gauss"}
"""Other accepted names: pyvista's ``"gaussian"``, and ``"H"`` / ``"K"`` as in
:class:`igl_hhj.baselines.CurvatureEstimate`, the viewer and ``igl-hhj curvature --quantity``."""
CURVATURE_PER = ("vertex", "face")
"""Where :func:`curvature_of` gives values."""

_Scalar = Literal["mean", "gauss", "gaussian", "k1", "k2", "H", "K"]


def _curvature_kind(kind):
    if isinstance(kind, str):
        kind = CURVATURE_KIND_ALIASES.get(kind, kind)
        if kind in CURVATURE_KINDS:
            return kind
    raise ValueError(f"kind must be one of {', '.join(map(repr, CURVATURE_KINDS))} (aliases: "
                     f"{', '.join(f'{a!r} = {c!r}' for a, c in CURVATURE_KIND_ALIASES.items())}), got {kind!r}")


_Faces = Union[NDArray[np.integer[Any]], Sequence[Sequence[int]], None]
"""The type of ``curvature_of``'s ``F``: an integer array or nested sequence, never a string (a
quantity passed as ``F`` is a type error, for mypy too)."""


@overload
def curvature_of(mesh_or_V: Any, F: _Faces = None, *, kind: Literal["directions"],
                 per: Literal["vertex", "face"] = "vertex",
                 **kwargs: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...


@overload
def curvature_of(mesh_or_V: Any, F: _Faces = None, *, kind: _Scalar = "mean",
                 per: Literal["vertex", "face"] = "vertex", **kwargs: Any) -> NDArray[np.float64]: ...


def curvature_of(mesh_or_V: Any, F: _Faces = None, *, kind: str = "mean", per: str = "vertex",
                 **kwargs: Any) -> NDArray[np.float64] | tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One curvature quantity of a mesh as plain arrays, in one call (in the spirit of
    pyvista's ``mesh.curvature("mean")``).

    Named ``curvature_of`` because ``igl_hhj.curvature`` is the module that holds the
    curvature functions (this one included): a function of that name would shadow it.

    Parameters
    ----------
    mesh_or_V : (#V, 3) array_like, or a mesh object with ``F`` omitted
        Vertex positions, a :class:`igl_hhj.mesh.TriangleMesh`, or anything
        :func:`igl_hhj.interop.mesh_arrays` accepts (``trimesh.Trimesh``,
        triangulated ``pyvista.PolyData``, ``meshio.Mesh``).
    F : (#F, 3) array_like int, optional
        Triangles (required with arrays).
    kind : {"mean", "gauss", "k1", "k2", "directions"}, default "mean", keyword-only
        Mean curvature H = (κ1 + κ2)/2, Gauss curvature K = κ1 κ2, the principal
        curvatures κ1 ≥ κ2, or the principal directions.  ``"gaussian"``, ``"H"``
        and ``"K"`` are accepted as aliases (:data:`CURVATURE_KIND_ALIASES`).
    per : {"vertex", "face"}, default "vertex", keyword-only
        "vertex": from the drop-in :func:`principal_curvature` (recovered and
        smoothed at ``radius``); "face": Walker's per-face S_h itself
        (:func:`face_mean_curvature`, :func:`face_gaussian_curvature`,
        :func:`face_principal_curvature`), the quantity with the convergence proof.
    **kwargs
        Passed on: ``radius``, ``useKring``, boundary data, ``solver``, ``rtol`` of
        :func:`principal_curvature` (per vertex); boundary data, ``solver``,
        ``smoothing`` of :func:`face_principal_curvature` (per face).

    Returns
    -------
    values : (#V,) or (#F,) float64
        For the scalar kinds.  Per vertex, the rows of the drop-in's
        ``bad_vertices`` (unreferenced vertices, no tangent plane) are NaN.
    (PD1, PD2) : tuple of two (#V, 3) or (#F, 3) float64
        For ``"directions"``: unit directions of maximal / minimal curvature
        (PD2 = N × PD1).

    Raises
    ------
    ValueError
        Unknown ``kind`` or ``per`` (the message lists the choices); and whatever
        the underlying function raises for the mesh or the keyword arguments.

    Examples
    --------
    >>> import igl_hhj
    >>> from igl_hhj.surfaces import icosphere
    >>> V, F = icosphere(3)
    >>> H = igl_hhj.curvature_of(V, F)                        # per-vertex mean curvature
    >>> K = igl_hhj.curvature_of(V, F, kind="gauss", per="face")   # Walker's S_h, per face
    >>> H.shape, K.shape, round(float(H.mean()), 2)
    ((642,), (1280,), 1.0)
    >>> PD1, PD2 = igl_hhj.curvature_of(V, F, kind="directions")
    """
    if isinstance(F, (str, bytes)):
        raise TypeError(f"curvature_of: F must be the faces, got the string {F!r}; the quantity is "
                        f"keyword-only: curvature_of(mesh, kind={F!r}) or curvature_of(V, F, kind={F!r})")
    kind = _curvature_kind(kind)
    if per not in CURVATURE_PER:
        raise ValueError(f"per must be one of {', '.join(map(repr, CURVATURE_PER))}, got {per!r}")
    if per == "vertex":
        PD1, PD2, PV1, PV2, _ = principal_curvature(mesh_or_V, F, **kwargs)
    elif kind in ("mean", "gauss") and "smoothing" not in kwargs:
        return (face_mean_curvature if kind == "mean" else face_gaussian_curvature)(mesh_or_V, F, **kwargs)
    else:
        PD1, PD2, PV1, PV2 = face_principal_curvature(mesh_or_V, F, **kwargs)
    if kind == "directions":
        return PD1, PD2
    return {"k1": PV1, "k2": PV2, "mean": 0.5 * (PV1 + PV2), "gauss": PV1 * PV2}[kind]
