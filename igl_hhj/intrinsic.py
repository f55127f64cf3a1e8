"""Intrinsic vertex stage: face tensors carried into the vertex tangent planes by
minimal rotations, recovered there, and smoothed with the spin-2 connection Laplacian.

The HHJ shape operator S_h (Walker, paper 000) is one symmetric tangential tensor
per face; the drop-in :func:`igl_hhj.principal_curvature` needs one per vertex and,
on noisy meshes, a length scale.  Averaging the *ambient* 3×3 tensors of faces whose
normals differ (and projecting the average onto the vertex plane) loses the part of
the curvature that turned into the normal–normal block: on a tube with 8 vertices
around it κ1 drops by a third and κ2 rises from 0 to 1.5/r (issue 23).  Here every
tensor is moved *intrinsically* instead:

* **transport** (:func:`transport`): the face plane of T is carried onto the
  tangent plane of its vertex v by the minimal rotation ``R_{T→v}`` taking ν_T to
  N_v (Rodrigues; the discrete Levi-Civita connection between the two planes).  A
  tangential tensor S_T becomes ``R S_T Rᵀ``, tangential to N_v, with the same
  eigenvalues.  On a cylinder (a tube) this maps the circumferential direction of
  every face onto the vertex's own: no bias, whatever the angle.
* **components** (:func:`corner_components`): in the vertex frame (e1, e2) a
  symmetric 2-tensor is ``h I + [[a, b], [b, -a]]``: its trace part ``h``
  (the mean curvature H, a scalar) and its deviator as the complex number
  ``z = a + i b``, ``|z| = (κ1 - κ2)/2``, ``arg z = 2 × (angle of PD1)``.
  Changing the frame by an angle φ multiplies z by ``e^{-2iφ}`` (spin 2).
* **recovery** (:func:`recover`): the weighted least-squares linear fit of the
  three corner components over the incident faces, evaluated at the vertex
  (:func:`igl_hhj.recovery.recovery_operator`, "patch"); corners whose face
  normal points away from the vertex normal (folds) carry no weight.
* **smoothing** (:func:`smooth`): implicit diffusion ``(M + L_t) Y = M Y_prev`` of
  h with libigl's cotangent Laplacian and of z with the *connection* Laplacian
  ``(L_c z)_i = Σ_j w_ij (z_i - r_ij z_j)``, ``r_ij = e^{2iρ_ij}`` the transport of
  the frame of j into the frame of i along the edge (Knöppel et al. 2013, Sharp
  et al. 2019: the Bochner Laplacian on spin-2 fields).  Both are Hermitian PSD,
  with the weights of :func:`igl_hhj.recovery.smoothing_coefficients`
  (reliability, boundary band) times a **per-face** time ``t_T = ℓ_T² / steps``,
  ``ℓ_T = SMOOTHING_PER_RADIUS · radius · h_T`` with h_T the mean edge length of
  T: the scale is local (graded meshes), and a connected component never sees
  another.  Tukey's twicing ``2G - G²`` as before (bias O(ℓ⁴)).

Exact invariances (to round-off, whatever the solver tolerance): a rigid motion or
uniform scaling of V, a relabelling of the vertices and a reversal of the
orientation transform every intermediate quantity covariantly (the frames change by
a rotation per vertex, which multiplies z by a unit complex number; the Jacobi
preconditioner is a scalar per vertex, so CG's iterates transform the same way).

The compiled kernels (:func:`igl_hhj.kernels.intrinsic_patch_recovery`,
:func:`igl_hhj.kernels.intrinsic_smoothing`) compute the same; this module is
their readable numpy reference (``tests/vertex_stage/test_intrinsic.py`` compares them).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .mesh import TriangleMesh

__all__ = [
    "vertex_frames", "transport", "corner_components", "recover", "transport_phases",
    "connection_laplacians", "smoothing_times", "smooth", "principal", "to_tensors",
    "vertex_stage", "vertex_stage_reference", "adaptive_smoothing", "adaptive_smoothing_by_parts", "smoothing_rtol", "roughness", "adaptive_radius", "transport_phase_components", "SMOOTHING_STEPS", "SMOOTHING_ORDER",
]

SMOOTHING_STEPS = 2
SMOOTHING_ORDER = 2
ADAPTIVE_GAIN = 0.3
"""Gain of :func:`adaptive_radius` (r = radius · 0.3 ρ^{1/4} / (κh), fitted)."""
ADAPTIVE_POWER = 0.25
ADAPTIVE_RANGE = (0.2, 5.0)
"""Bounds of the factor ``a`` of :func:`adaptive_radius` (radius 5: 1 to 25 rings)."""
SMOOTHING_MAXITER = 500
"""Iteration cap of each smoothing solve of :func:`vertex_stage` (a solve that reaches it
sends the vertex stage to the direct reference)."""
PILOT_RADIUS = 5
"""Radius of the pilot smoothing (one implicit step) whose curvature sets the scale."""
SPLIT_MIN_VERTICES = 64
""":func:`adaptive_smoothing_by_parts`: components with fewer vertices are smoothed
together in one call (a call's fixed cost would outweigh their iterations)."""


def vertex_frames(N):
    """Tangent frames ``e1 = N × a / |N × a|`` (a the coordinate axis least aligned with N),
    ``e2 = N × e1``; N (n, 3) unit → e1, e2 (n, 3).  Rows of non-finite N get the frame of +z."""
    N = np.where(np.isfinite(N).all(axis=1, keepdims=True), N, (0.0, 0.0, 1.0))
    ax = np.eye(3)[np.argmin(np.abs(N), axis=1)]
    e1 = np.cross(N, ax)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(N, e1)


def transport(x, a, b):
    """Minimal rotation taking the unit vector a to the unit vector b, applied to x.

    Rodrigues' formula ``R x = c x + k × x + (k·x) k / (1 + c)``, ``k = a × b``,
    ``c = a · b``; all arrays (m, 3).  Undefined for c = -1 (the callers give such
    pairs no weight)."""
    k = np.cross(a, b)
    c = np.einsum("ma,ma->m", a, b)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.einsum("ma,ma->m", k, x) / (1.0 + c)
    return c[:, None] * x + np.cross(k, x) + s[:, None] * k


def corner_components(mesh: TriangleMesh, S, N, e1, e2):
    """The face tensors seen from each corner's vertex frame.

    Parameters
    ----------
    S : (#F, 3, 3) tangential face tensors; N, e1, e2 : (#V, 3) vertex normals and frames.

    Returns
    -------
    Y : (#F, 3, 3) float64, ``Y[f, c] = (h, Re z, Im z)`` of ``R S_f Rᵀ`` in the frame of
        vertex ``F[f, c]``, R the minimal rotation ν_f → N_v (:func:`transport`).
    cosine : (#F, 3) float64, ``ν_f · N_v``.
    """
    F = mesh.F
    v = F.ravel()
    nu = np.repeat(mesh.face_normals, 3, axis=0)
    # (R S Rᵀ) e = R S (Rᵀ e): carry the vertex frame into the face plane instead
    f1 = transport(e1[v], N[v], nu)
    f2 = transport(e2[v], N[v], nu)
    Sf = np.repeat(S, 3, axis=0)
    a = np.einsum("ma,mab,mb->m", f1, Sf, f1)
    d = np.einsum("ma,mab,mb->m", f2, Sf, f2)
    b = np.einsum("ma,mab,mb->m", f1, Sf, f2)
    Y = np.stack([0.5 * (a + d), 0.5 * (a - d), b], axis=1).reshape(mesh.n_faces, 3, 3)
    cosine = np.einsum("ma,ma->m", N[v], nu).reshape(mesh.n_faces, 3)
    return Y, cosine


def recover(mesh: TriangleMesh, S, N, weights):
    """Intrinsic patch recovery: (#V, 3) components ``(h, Re z, Im z)`` in the frames of N.

    The corner components (:func:`corner_components`) are fitted by the weighted
    linear least squares of :func:`igl_hhj.recovery.recovery_operator` ("patch"),
    with corner weight ``w_T`` where ``ν_T · N_v > 0`` and 0 on folded corners.
    Rows of unreferenced vertices are 0.
    """
    from .recovery import recovery_operator
    e1, e2 = vertex_frames(N)
    Y, cosine = corner_components(mesh, S, N, e1, e2)
    W = np.where(cosine > 0, np.asarray(weights, dtype=np.float64)[:, None], 0.0)
    R = recovery_operator(mesh, "patch", W, N, corners=True)               # rows: vertices, cols: corners
    Y = np.where(np.isfinite(Y), Y, 0.0).reshape(-1, 3)
    return R @ Y


def transport_phases(mesh: TriangleMesh, N, e1, e2):
    """``r_e = e^{2iρ_e}`` per unique edge e = (i, j) (i < j): the deviator of j in the frame of i.

    ρ_e is the angle, in the frame of i, of e1_j carried onto the tangent plane of
    i by the minimal rotation N_j → N_i.  Returns (#E,) complex128."""
    c, s = transport_phase_components(mesh, N, e1, e2)
    return c + 1j * s


def transport_phase_components(mesh: TriangleMesh, N, e1, e2):
    """``(cos 2ρ_e, sin 2ρ_e)`` of :func:`transport_phases` without trigonometry:
    with ``(x, y)`` the frame-i coordinates of the transported e1_j (a unit vector),
    ``cos 2ρ = x² - y²`` and ``sin 2ρ = 2xy``.  Edges whose transport is undefined
    (opposite or non-finite normals) get 0, 0 (no coupling of the deviators).
    Returns two (#E,) arrays."""
    E = mesh.edges
    i, j = E[:, 0], E[:, 1]
    t = transport(e1[j], N[j], N[i])
    x = np.einsum("ma,ma->m", t, e1[i])
    y = np.einsum("ma,ma->m", t, e2[i])
    with np.errstate(invalid="ignore", divide="ignore"):
        n2 = x * x + y * y
        c, s = (x * x - y * y) / n2, 2.0 * x * y / n2
    ok = np.isfinite(c) & np.isfinite(s)
    return np.where(ok, c, 0.0), np.where(ok, s, 0.0)


def smoothing_times(mesh: TriangleMesh, radius, steps=SMOOTHING_STEPS):
    """Per-face diffusion time ``t_T = ℓ_T² / steps``, ``ℓ_T = SMOOTHING_PER_RADIUS · radius · h_T``
    (``radius`` a number or per face, (#F,)).

    ``h_T`` is the mean length of T's three edges: the smoothing length follows the
    local mesh size, so a graded mesh is smoothed over the same number of rings
    everywhere and a connected component does not depend on any other.  (#F,)."""
    from .recovery import SMOOTHING_PER_RADIUS
    hT = mesh.edge_lengths.mean(axis=1)
    return (SMOOTHING_PER_RADIUS * np.asarray(radius, dtype=np.float64) * hT) ** 2 / steps


def roughness(mesh: TriangleMesh, S, N, X, weights):
    """Roughness of the face tensors around each vertex, dimensionless, (#V,).

    ``ρ_v = h_v sqrt(Σ_{T∋v} w_T |Y_T - X_v|² / Σ_{T∋v} w_T)``: the rms distance of the
    corner components Y_T (:func:`corner_components`) from the recovered value X_v,
    weighted like the fit (:func:`recover`: the reliability weights, 0 on folded
    corners, so slivers, whose tensors the fit ignores, do not count as noise), times
    the local length h_v (mean over v's corners of the faces' mean edge length).  On a smooth mesh ρ ~ (κh)² (the O(h) discretisation error of S_h, a
    few 1e-4 to 1e-2); under normal noise of amplitude s·h it grows like ~3 s
    (measured: 0.029 at s = 0.01, 0.28 at s = 0.1 on the ellipsoid and the torus of
    ``igl_hhj.benchmarks.robustness``).  0 at unreferenced vertices."""
    e1, e2 = vertex_frames(N)
    Y, cosine = corner_components(mesh, S, N, e1, e2)
    v = mesh.F.ravel()
    d2 = ((np.where(np.isfinite(Y), Y, 0.0).reshape(-1, 3) - X[v]) ** 2).sum(axis=1)
    A = np.where(cosine > 0, np.asarray(weights, dtype=np.float64)[:, None], 0.0).ravel()
    hT = np.repeat(mesh.edge_lengths.mean(axis=1), 3)
    n = mesh.n_vertices
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.bincount(v, hT, n) / np.bincount(v, minlength=n) \
            * np.sqrt(np.bincount(v, A * d2, n) / np.bincount(v, A, n))
    return np.where(np.isfinite(r), r, 0.0)


def _ring_mean(mesh, x):
    """Area-weighted mean of the face means of a vertex field over each vertex's faces (#V,)."""
    f = x[mesh.F].mean(axis=1) * mesh.face_areas
    v = mesh.F.ravel()
    n = mesh.n_vertices
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.bincount(v, np.repeat(f, 3), n) / np.bincount(v, np.repeat(mesh.face_areas, 3), n)


def adaptive_radius(mesh: TriangleMesh, X_pilot, rough, radius):
    """Per-face smoothing radius ``r_T`` (#F,) adapted to the noise and the curvature it sees.

    ``a_v = clip(ADAPTIVE_GAIN · ρ̄_v^{1/4} / c̄_v, *ADAPTIVE_RANGE)``, ``r_T = radius ·
    mean_{v∈T} a_v``: ρ̄ the ring mean of the :func:`roughness`, ``c̄`` the ring mean of
    ``h_v (|H| + |z|)`` = h_v max|κ| of the pilot ``X_pilot`` (one implicit step at radius
    :data:`PILOT_RADIUS`).  The exponent balances the two errors of the twiced
    smoothing at length ℓ = L h: the noise left, ~ρ/(hL), against the bias,
    ~ℓ⁴|∇⁴κ| ~ (κh)⁵ L⁴/h, whose minimum is at ``L ∝ ρ^{1/5}/(κh)`` (the exponent
    1/4 and the gain were fitted on the clean, jittered, flipped and noisy families
    of ``igl_hhj.benchmarks.robustness``; ``python -m igl_hhj.benchmarks.vertex_stage``
    shows the table).  At the default radius 5, smooth meshes get r ≈ 1–9 (growing
    slowly under refinement, since ρ/(κh)⁴ ~ (κh)⁻² there), thin features (κh large)
    ``radius · ADAPTIVE_RANGE[0]`` = 1 ring, noisy scans up to ``radius ·
    ADAPTIVE_RANGE[1]`` = 25.  Non-finite values count as a = 1."""
    n = mesh.n_vertices
    kappa = np.abs(X_pilot[:, 0]) + np.hypot(X_pilot[:, 1], X_pilot[:, 2])
    hv = np.bincount(mesh.F.ravel(), np.repeat(mesh.edge_lengths.mean(axis=1), 3), n) \
        / np.maximum(np.bincount(mesh.F.ravel(), minlength=n), 1)
    c = _ring_mean(mesh, kappa * hv)
    rho = _ring_mean(mesh, rough)
    with np.errstate(invalid="ignore", divide="ignore"):
        a = np.clip(ADAPTIVE_GAIN * rho ** ADAPTIVE_POWER / np.maximum(c, 1e-3), *ADAPTIVE_RANGE)
    a = np.where(np.isfinite(a), a, 1.0)
    return float(radius) * a[mesh.F].mean(axis=1)


def connection_laplacians(mesh: TriangleMesh, C, phases):
    """Scalar and spin-2 connection Laplacians from per-face stiffness entries.

    Parameters
    ----------
    C : (#F, 3) per-face entries of the edge opposite each corner (cotangent × weights).
    phases : (#E,) complex, :func:`transport_phases`.

    Returns
    -------
    L : (#V, #V) real symmetric PSD, ``(L h)_i = Σ_j w_ij (h_i - h_j)``;
    Lc : (#V, #V) complex Hermitian PSD, ``(Lc z)_i = Σ_j w_ij (z_i - r_ij z_j)``,
    ``w_e = Σ_{T ∋ e} C[T, local index of e]``.
    """
    n = mesh.n_vertices
    w = np.zeros(mesh.n_edges)
    for s in range(2):
        f = mesh.edge_faces[:, s]
        ok = f >= 0
        w[ok] += C[f[ok], mesh.edge_local_index[ok, s]]
    i, j = mesh.edges[:, 0], mesh.edges[:, 1]
    rows, cols = np.r_[i, j], np.r_[j, i]
    D = sp.diags(np.bincount(rows, np.r_[w, w], minlength=n))
    L = sp.coo_matrix((np.r_[-w, -w], (rows, cols)), shape=(n, n)).tocsr() + D
    Lc = sp.coo_matrix((np.r_[-w * phases, -w * np.conj(phases)], (rows, cols)),
                       shape=(n, n)).tocsr() + D
    return L, Lc


def smooth(mesh: TriangleMesh, X, N, weights, radius, *, steps=SMOOTHING_STEPS, order=SMOOTHING_ORDER,
           times=None):
    """Twiced implicit diffusion of the components (h, z) (numpy reference, sparse LU).

    ``G`` is ``steps`` steps ``(M + L_t) Y = M Y_prev`` with the lumped mass M and the
    stiffness of :func:`igl_hhj.recovery.smoothing_coefficients` times the per-face
    times of :func:`smoothing_times`: the scalar Laplacian on h, the connection
    Laplacian (:func:`connection_laplacians`) on z.  Returns
    ``(I - (I - G)^order) X`` as a new (#V, 3) array (rows of unreferenced vertices 0).
    """
    import scipy.sparse.linalg as spla
    from .recovery import _kernel_coefficients, smoothing_coefficients
    if times is None and not radius > 0:
        return X.copy()
    C, m = smoothing_coefficients(mesh, weights)
    C = C * (smoothing_times(mesh, radius, steps) if times is None else times)[:, None]
    e1, e2 = vertex_frames(N)
    L, Lc = connection_laplacians(mesh, C, transport_phases(mesh, N, e1, e2))
    M = sp.diags(m)
    solve_h = spla.factorized((M + L).tocsc())
    solve_z = spla.factorized((M + Lc).tocsc())
    h, z = X[:, 0], X[:, 1] + 1j * X[:, 2]
    hs, zs = np.zeros_like(h), np.zeros_like(z)
    for c in _kernel_coefficients(order):
        for _ in range(steps):
            h, z = solve_h(m * h), solve_z(m * z)
        hs += c * h
        zs += c * z
    out = np.stack([hs, zs.real, zs.imag], axis=1)
    out[~mesh.referenced_vertices] = 0.0
    return out


def principal(X, N):
    """Principal directions and curvatures of components (h, Re z, Im z) in the frames of N.

    ``κ1,2 = h ± |z|``, ``PD1 = cos φ e1 + sin φ e2`` with ``φ = arg(z)/2``,
    ``PD2 = N × PD1``.  Returns PD1, PD2 (n, 3), PV1, PV2 (n,)."""
    e1, e2 = vertex_frames(N)
    h = X[:, 0]
    a = np.hypot(X[:, 1], X[:, 2])
    phi = 0.5 * np.arctan2(X[:, 2], X[:, 1])
    PD1 = np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2
    PD2 = np.cross(N, PD1)
    return PD1, PD2, h + a, h - a


def to_tensors(X, N):
    """(n, 3, 3) ambient tangential tensors ``h P + a (e1e1 - e2e2) + b (e1e2 + e2e1)``."""
    e1, e2 = vertex_frames(N)
    h, a, b = X[:, 0, None, None], X[:, 1, None, None], X[:, 2, None, None]
    E11 = e1[:, :, None] * e1[:, None, :]
    E22 = e2[:, :, None] * e2[:, None, :]
    E12 = e1[:, :, None] * e2[:, None, :]
    return h * (E11 + E22) + a * (E11 - E22) + b * (E12 + np.swapaxes(E12, 1, 2))


def vertex_stage_reference(mesh: TriangleMesh, S, radius, *, normals=None, weights=None):
    """Numpy reference of :func:`vertex_stage` (sparse LU instead of PCG).

    Returns X (#V, 3) components (rows of unreferenced vertices 0), N (#V, 3)."""
    from .recovery import recovery_weights
    N = mesh.vertex_normals if normals is None else normals
    w = recovery_weights(mesh) if weights is None else weights
    X = recover(mesh, S, N, w)
    if radius > 0:
        X = _smooth_reference(mesh, X, N, w, roughness(mesh, S, N, X, w), radius)
    return X, N


def _smooth_reference(mesh, X, N, w, rough, radius):
    """Pilot, adaptive radius and twiced smoothing by sparse LU (the reference and the
    fallback of :func:`vertex_stage`)."""
    pilot = smooth(mesh, X, N, w, PILOT_RADIUS, steps=1, order=1)
    r = adaptive_radius(mesh, pilot, rough, radius)
    return smooth(mesh, X, N, w, radius, times=smoothing_times(mesh, r))


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
    """The smoothing of :func:`vertex_stage` with this module's parameters, in place on
    ``X`` (#V, 3): one compiled call (:func:`igl_hhj.kernels.intrinsic_smoothing`: pilot step,
    adaptive per-face radius, twiced smoothing), every solve to :func:`smoothing_rtol` of
    the caller's ``rtol``.  ``C0, mass`` from :func:`igl_hhj.recovery.smoothing_coefficients`,
    ``phase`` from :func:`igl_hhj.kernels.transport_phases`, ``rough`` from the recovery;
    ``solve_rtol``: the relative residual of every solve instead of :func:`smoothing_rtol`
    (:func:`adaptive_smoothing_by_parts`).

    Returns ``(status, iterations, components, radius (#F,))`` (status 0: every solve converged;
    else X is unchanged)."""
    from . import kernels
    from .recovery import SMOOTHING_PER_RADIUS, _kernel_coefficients
    srtol = smoothing_rtol(rtol) if solve_rtol is None else float(solve_rtol)
    return kernels.intrinsic_smoothing(
        mesh, X, C0, mass, phase, rough, radius, per_radius=SMOOTHING_PER_RADIUS, pilot_radius=PILOT_RADIUS,
        pilot_rtol=srtol, gain=ADAPTIVE_GAIN, power=ADAPTIVE_POWER, bounds=ADAPTIVE_RANGE,
        steps=SMOOTHING_STEPS, coefficients=_kernel_coefficients(SMOOTHING_ORDER), rtol=srtol, maxiter=maxiter)


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
    from . import kernels
    from .components import split_parts
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

    # the parts are independent: on several threads at once (kernels.run_tasks; the same bits)
    its = 0
    results = kernels.run_tasks(solve, range(len(parts)), [p[0].n_vertices for p in parts])
    for (status, k, _, rf), (_, _, f, _) in zip(results, parts):
        if status != 0:
            return status, its, n, r
        r[fo[f]] = rf
        its = max(its, k)
    X[vo] = Xp
    return 0, its, n, r


def vertex_stage(mesh: TriangleMesh, S, radius, *, rtol=None, maxiter=SMOOTHING_MAXITER, info=None,
                 by_parts=False):
    """The drop-in's vertex stage, compiled: intrinsic patch recovery + twiced smoothing.

    Parameters
    ----------
    S : (#F, 3, 3) tangential face tensors (Walker's S_h), or a one-element list holding
        them, which is emptied after the recovery (so that the tensors can be freed
        before the smoothing, the memory peak of the drop-in).
    radius : float ≥ 0, smoothing scale in rings (0: recovery only).
    rtol : float, the caller's tolerance (default :data:`igl_hhj.solvers.DEFAULT_RTOL`);
        every smoothing solve runs to the relative residual :func:`smoothing_rtol` of it.
    info : dict, optional; receives ``smoothing_iterations`` and ``components``.
    by_parts : bool or (#V,) int array, default False
        True: smooth each connected component in its own compiled call
        (:func:`adaptive_smoothing_by_parts`), the same values to round-off.  An array:
        the same, each component solved to the tolerance of the scale of its group
        (``scale_groups`` of :func:`adaptive_smoothing_by_parts`; the sides of the cut of
        :mod:`igl_hhj.features`, grouped by the caller's connected parts).

    Returns
    -------
    X : (#V, 3) float64 components (h, Re z, Im z) in the frames of N (rows of
        unreferenced vertices 0).
    N : (#V, 3) the vertex normals (``mesh.vertex_normals``).
    """
    from . import kernels
    from .recovery import QUALITY_FLOOR, smoothing_coefficients
    from .solvers import DEFAULT_RTOL
    rtol = DEFAULT_RTOL if rtol is None else rtol
    N = mesh.vertex_normals
    w = kernels.recovery_weights(mesh, QUALITY_FLOOR)
    if isinstance(S, list):
        X, rough = kernels.intrinsic_patch_recovery(mesh, S.pop(), N, w)
    else:
        X, rough = kernels.intrinsic_patch_recovery(mesh, S, N, w)
    del S
    if not radius > 0:
        return X, N
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
    if status != 0:          # a solve stalled (the kernel left X unchanged): the direct reference
        X = _smooth_reference(mesh, X, N, w, rough, radius)
    return X, N
