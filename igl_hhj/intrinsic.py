"""The drop-in's vertex stage: Walker's face tensors S_h carried to the vertices intrinsically,
recovered there and smoothed at a scale that adapts to the mesh (compiled).

The HHJ shape operator S_h (Walker 2023) is one symmetric tangential tensor per face; the
drop-in :func:`igl_hhj.principal_curvature` needs one per vertex and, on noisy meshes, a
length scale.  Averaging the *ambient* 3×3 tensors of faces whose normals differ (and
projecting the average onto the vertex plane) loses the part of the curvature that turned
into the normal–normal block: on a tube with 8 vertices around it κ1 drops by a third and
κ2 rises from 0 to 1.5/r.  Here every tensor is moved *intrinsically* instead:

* **transport**: the face plane of T is carried onto the tangent plane of its vertex v by
  the minimal rotation ``R_{T→v}`` taking ν_T to N_v (Rodrigues; the discrete Levi-Civita
  connection between the two planes).  A tangential tensor S_T becomes ``R S_T Rᵀ``,
  tangential to N_v, with the same eigenvalues.
* **components**: in the vertex frame (e1, e2) a symmetric 2-tensor is
  ``h I + [[a, b], [b, -a]]``: its trace part ``h`` (the mean curvature H) and its deviator
  as the complex number ``z = a + i b``, ``|z| = (κ1 - κ2)/2``, ``arg z = 2 × (angle of
  PD1)``.  Changing the frame by an angle φ multiplies z by ``e^{-2iφ}`` (spin 2).
* **recovery** (:func:`vertex_recovery`): the weighted least-squares linear fit of the three
  corner components over the incident faces, evaluated at the vertex (the face weights of
  :func:`igl_hhj.recovery.recovery_weights`: area, reduced on slivers and their
  neighbours); corners whose face normal points away from the vertex normal (folds) carry
  no weight.  It also measures the **roughness** ρ_v of S_h around each vertex: the
  weighted rms distance of the corner components from the fit, times the local edge length.
* **smoothing** (:func:`vertex_smoothing`): implicit diffusion ``(M + L_t) Y = M Y_prev`` of h
  with libigl's cotangent Laplacian and of z with the *connection* Laplacian
  ``(L_c z)_i = Σ_j w_ij (z_i - r_ij z_j)``, ``r_ij = e^{2iρ_ij}`` the transport of the frame
  of j into the frame of i along the edge (Knöppel et al. 2013, Sharp et al. 2019: the
  Bochner Laplacian on spin-2 fields), weights from
  :func:`igl_hhj.recovery.smoothing_coefficients` (reliability, boundary band), combined by
  Tukey's twicing ``2G - G²`` (bias O(ℓ⁴)).  The length is **per face**:
  ``ℓ_T = SMOOTHING_PER_RADIUS · r_T · h_T`` with h_T the mean edge length of T and the
  adaptive radius ``r_T = radius · mean_{v∈T} clip(ADAPTIVE_GAIN ρ̄_v^{1/4} / c̄_v,
  ADAPTIVE_RANGE)``, ρ̄ the ring mean of the roughness and c̄ that of ``h_v max|κ|`` after a
  pilot step of one implicit diffusion at radius ``PILOT_RADIUS``
  (:func:`igl_hhj.intrinsic_numpy.adaptive_radius`; the constants in
  :mod:`igl_hhj.constants`).  So a smooth mesh gets about 1–2 rings at the default radius
  5, thin features (κh large) 1 ring, noisy scans up to 25; every scale is local (graded
  meshes), and a connected component never sees another.

The compiled kernels do all of it: :func:`igl_hhj.kernels.intrinsic_patch_recovery` (recovery
and roughness) and :func:`igl_hhj.kernels.intrinsic_smoothing` (pilot, adaptive radius,
twiced smoothing, one PCG per solve).  Should a smoothing solve stall, the sparse-LU
smoothing of :mod:`igl_hhj.intrinsic_numpy` finishes the job; that module and
``tests/vertex_stage/reference_intrinsic.py`` are the readable numpy version the tests
compare with.

Exact invariances (to round-off, whatever the solver tolerance): a rigid motion or uniform
scaling of V, a relabelling of the vertices and a reversal of the orientation transform
every intermediate quantity covariantly (the frames change by a rotation per vertex, which
multiplies z by a unit complex number; the Jacobi preconditioner is a scalar per vertex, so
CG's iterates transform the same way).
"""
from __future__ import annotations

import numpy as np

from . import kernels, runtime
from .components import split_parts
from .constants import (ADAPTIVE_GAIN, ADAPTIVE_POWER, ADAPTIVE_RANGE, DEFAULT_RTOL, PILOT_RADIUS,
                        QUALITY_FLOOR, SMOOTHING_MAXITER, SMOOTHING_ORDER, SMOOTHING_PER_RADIUS,
                        SMOOTHING_STEPS, SPLIT_MIN_VERTICES)
# the numpy smoothing (the fallback) and, under their old names here, its building blocks
from .intrinsic_numpy import (adaptive_radius, connection_laplacians, smooth, smooth_reference,  # noqa: F401
                              smoothing_times, to_tensors, transport, transport_phase_components,
                              transport_phases, vertex_frames)
from .mesh import TriangleMesh
from .recovery import kernel_coefficients, smoothing_coefficients

__all__ = [
    "vertex_stage", "vertex_recovery", "vertex_smoothing", "adaptive_smoothing", "adaptive_smoothing_by_parts",
    "smoothing_rtol", "SMOOTHING_STEPS", "SMOOTHING_ORDER",
    # the numpy building blocks (igl_hhj.intrinsic_numpy), named here as before
    "vertex_frames", "transport", "transport_phases", "transport_phase_components", "connection_laplacians",
    "smoothing_times", "smooth", "adaptive_radius", "to_tensors",
]


def smoothing_rtol(rtol):
    """Relative residual of the smoothing solves for a caller's ``rtol``: ``min(1e-3, √rtol)``.

    Each smoothing solve is for a correction ``dY = -(M + L_t)⁻¹ L_t Y`` that is itself
    O(ℓ²ΔS) ≪ S, so a residual of √rtol of the correction leaves an error of about
    √rtol · ℓ²|ΔS| in the result: 1e-3 at the default rtol = 1e-6, below the
    discretisation error of the vertex values, and 1e-6 for ``rtol=1e-12``.  The
    invariances (rotation, scaling, relabelling, orientation, other components) hold
    to round-off whatever the tolerance (module docstring)."""
    return min(1e-3, float(np.sqrt(rtol)))


def adaptive_smoothing(mesh: TriangleMesh, X, C0, mass, phase, rough, radius, rtol,
                       maxiter=SMOOTHING_MAXITER, *, solve_rtol=None):
    """The smoothing of the vertex stage with the constants of :mod:`igl_hhj.constants`, in place on
    ``X`` (#V, 3): one compiled call (:func:`igl_hhj.kernels.intrinsic_smoothing`: pilot step,
    adaptive per-face radius, twiced smoothing), every solve to :func:`smoothing_rtol` of
    the caller's ``rtol``.  ``C0, mass`` from :func:`igl_hhj.recovery.smoothing_coefficients`,
    ``phase`` from :func:`igl_hhj.kernels.transport_phases`, ``rough`` from the recovery;
    ``solve_rtol``: the relative residual of every solve instead of :func:`smoothing_rtol`
    (:func:`adaptive_smoothing_by_parts`).

    Returns ``(status, iterations, components, radius (#F,))`` (status 0: every solve converged;
    else X is unchanged)."""
    srtol = smoothing_rtol(rtol) if solve_rtol is None else float(solve_rtol)
    return kernels.intrinsic_smoothing(
        mesh, X, C0, mass, phase, rough, radius, per_radius=SMOOTHING_PER_RADIUS, pilot_radius=PILOT_RADIUS,
        pilot_rtol=srtol, gain=ADAPTIVE_GAIN, power=ADAPTIVE_POWER, bounds=ADAPTIVE_RANGE,
        steps=SMOOTHING_STEPS, coefficients=kernel_coefficients(SMOOTHING_ORDER), rtol=srtol, maxiter=maxiter)


def adaptive_smoothing_by_parts(mesh: TriangleMesh, X, C0, mass, phase, rough, radius, rtol,
                                maxiter=SMOOTHING_MAXITER, *, scale_groups=None):
    """:func:`adaptive_smoothing` with one compiled call per connected component (those
    with fewer than :data:`SPLIT_MIN_VERTICES` vertices together in one more call; one call
    of the whole mesh where at most one component has that many), in place on ``X`` (#V, 3).

    One call on the whole mesh keeps separate CG scalars and stopping tests per
    component, but every iteration sweeps all rows until the slowest component has
    converged: on the cut of :mod:`igl_hhj.features` (fandisk: 12 sides, 29 to 232
    iterations) most of that work is on sides that have converged already.  Here each
    call iterates over its own component's rows only.  Each component's iterates are those
    of its own solve either way; only the order of the CG's sums changes (the rows of a
    component no longer fall in the chunks of the whole mesh), so the values agree to
    round-off, and a component's values do not depend on the others at all.  The inputs are
    sliced, not recomputed (:func:`igl_hhj.components.split_parts`).

    Parameters
    ----------
    scale_groups : (#V,) int, optional
        Labels of groups of components (the sides of one connected part of the caller's
        mesh, for a cut) whose common scale sets the stopping tests: a component c of
        group g is solved to the relative residual ``min(1, s · max(1, |X|_g / |X|_c))``,
        ``s`` = :func:`smoothing_rtol`, ``|X|`` the RMS of the components (h, z) over the
        rows.  The uncut part was one solve with one test ``|r| ≤ s |b|`` over all its
        rows; cut, each side would be solved to ``s`` of its *own* values, and a flat side
        (fandisk: values 1e-6 of the part's curvature) would spend 130-230 iterations on
        digits that are round-off of the part's.  Scaled, every side is solved to the same
        accuracy in the part's units, and a side with negligible values takes one
        iteration per solve.  The small components' call keeps ``s``.

    Returns ``(status, iterations, components, radius (#F,))`` as :func:`adaptive_smoothing`
    (iterations: the largest of a call's; status: the first failed call's, X then unchanged).
    """
    labels, n = kernels.vertex_components(mesh)
    size = np.bincount(labels, minlength=n)
    big = size >= SPLIT_MIN_VERTICES
    nbig = int(big.sum())
    if nbig <= 1:        # one component worth a call of its own: the others cost it nothing
        return adaptive_smoothing(mesh, X, C0, mass, phase, rough, radius, rtol, maxiter)
    call = np.full(n, nbig, dtype=np.int64)           # the small components: one call, the last
    call[big] = np.arange(nbig)
    (vo, fo, eo), parts = split_parts(mesh, call[labels], nbig + int(nbig < n))
    srtol = smoothing_rtol(rtol)
    tol = np.full(len(parts), srtol)
    if scale_groups is not None:
        g = np.asarray(scale_groups, dtype=np.int64)
        if g.shape != (mesh.n_vertices,):
            raise ValueError(f"scale_groups must have shape ({mesh.n_vertices},), got {g.shape}")
        x2 = (X * X).sum(axis=1)
        x2 = np.where(np.isfinite(x2), x2, 0.0)
        first = vo[[v.start for _, v, _, _ in parts[:nbig]]]    # a vertex of each big component:
        with np.errstate(invalid="ignore", divide="ignore"):   # its group (the cut refines the parts)
            ms_call = np.bincount(call[labels], x2, nbig + 1)[:nbig] / size[big]
            ms_group = np.bincount(g, x2) / np.bincount(g)
            ratio = np.sqrt(ms_group[g[first]] / ms_call)
        ratio = np.where(np.isfinite(ratio), np.maximum(ratio, 1.0), np.inf)   # 0/0, x/0: no scale
        tol[:nbig] = np.minimum(1.0, srtol * ratio)
    Xp, C0p, php = (np.take(A, o, axis=0) for A, o in ((X, vo), (C0, fo), (phase, eo)))
    mp, rp = np.take(mass, vo), np.take(rough, vo)
    r = np.empty(mesh.n_faces)

    def solve(c):
        sub, v, f, e = parts[c]                       # Xp[v]: a contiguous view, smoothed in place
        return adaptive_smoothing(sub, Xp[v], C0p[f], mp[v], php[e], rp[v], radius, rtol, maxiter,
                                  solve_rtol=tol[c])

    # the parts are independent: on several threads at once (runtime.run_tasks; the same bits)
    its = 0
    results = runtime.run_tasks(solve, range(len(parts)), [p[0].n_vertices for p in parts])
    for (status, k, _, rf), (_, _, f, _) in zip(results, parts):
        if status != 0:
            return status, its, n, r
        r[fo[f]] = rf
        its = max(its, k)
    X[vo] = Xp
    return 0, its, n, r



def vertex_recovery(mesh: TriangleMesh, S):
    """The recovery half of the vertex stage, compiled: the intrinsic patch fit of the face
    tensors at the vertices and the roughness around them
    (:func:`igl_hhj.kernels.intrinsic_patch_recovery`).

    Parameters
    ----------
    S : (#F, 3, 3) tangential face tensors (Walker's S_h).

    Returns
    -------
    X : (#V, 3) float64 components (h, Re z, Im z) in the frames of N (rows of unreferenced
        vertices 0).
    rough : (#V,) float64, the roughness ρ_v.
    N : (#V, 3) the vertex normals (``mesh.vertex_normals``).
    w : (#F,) the face weights of the fit (:func:`igl_hhj.recovery.recovery_weights`).
    """
    N = mesh.vertex_normals
    w = kernels.recovery_weights(mesh, QUALITY_FLOOR)
    X, rough = kernels.intrinsic_patch_recovery(mesh, S, N, w)
    return X, rough, N, w


def vertex_smoothing(mesh: TriangleMesh, X, N, w, rough, radius, rtol=DEFAULT_RTOL, *,
                     maxiter=SMOOTHING_MAXITER, info=None, by_parts=False):
    """The smoothing half of the vertex stage, compiled, in place on ``X`` where it can.

    Parameters
    ----------
    X, N, w, rough : from :func:`vertex_recovery`.
    radius : float ≥ 0, smoothing scale in rings (0: ``X`` itself).
    rtol : float, the caller's tolerance; every smoothing solve runs to the relative
        residual :func:`smoothing_rtol` of it.
    info : dict, optional; receives ``smoothing_iterations``, ``components`` and
        ``radius_median``.
    by_parts : bool or (#V,) int array, default False
        True: smooth each connected component in its own compiled call
        (:func:`adaptive_smoothing_by_parts`), the same values to round-off.  An array:
        the same, each component solved to the tolerance of the scale of its group
        (``scale_groups`` of :func:`adaptive_smoothing_by_parts`; the sides of the cut of
        :mod:`igl_hhj.creases`, grouped by the caller's connected parts).

    Returns
    -------
    X : (#V, 3) float64, the smoothed components: ``X`` itself, or a new array when a solve
        stalled and the sparse-LU smoothing (:func:`igl_hhj.intrinsic_numpy.smooth_reference`)
        took over from the unchanged input.
    """
    if not radius > 0:
        return X
    C0, m = smoothing_coefficients(mesh, w)
    phase = kernels.transport_phases(mesh, N)
    if isinstance(by_parts, bool) and not by_parts:
        status, its, ncomp, r = adaptive_smoothing(mesh, X, C0, m, phase, rough, radius, rtol, maxiter)
    else:
        status, its, ncomp, r = adaptive_smoothing_by_parts(
            mesh, X, C0, m, phase, rough, radius, rtol, maxiter,
            scale_groups=None if isinstance(by_parts, bool) else by_parts)
    if info is not None:
        info.update(smoothing_iterations=its, components=ncomp, radius_median=float(np.median(r)))
    if status != 0:          # a solve stalled (the kernel left X unchanged): the sparse-LU smoothing
        X = smooth_reference(mesh, X, N, w, rough, radius)
    return X


def vertex_stage(mesh: TriangleMesh, S, radius, *, rtol=None, maxiter=SMOOTHING_MAXITER, info=None,
                 by_parts=False):
    """The drop-in's vertex stage, compiled: :func:`vertex_recovery`, then
    :func:`vertex_smoothing` at scale ``radius`` (0: recovery only).

    ``rtol`` (default :data:`igl_hhj.constants.DEFAULT_RTOL`), ``maxiter``, ``info``,
    ``by_parts``: see :func:`vertex_smoothing`.

    Returns
    -------
    X : (#V, 3) float64 components (h, Re z, Im z) in the frames of N (rows of
        unreferenced vertices 0).
    N : (#V, 3) the vertex normals (``mesh.vertex_normals``).
    """
    X, rough, N, w = vertex_recovery(mesh, S)
    X = vertex_smoothing(mesh, X, N, w, rough, radius, DEFAULT_RTOL if rtol is None else rtol,
                         maxiter=maxiter, info=info, by_parts=by_parts)
    return X, N
