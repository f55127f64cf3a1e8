"""The smoothing of the intrinsic vertex stage in numpy/scipy (sparse LU): the fallback of the
compiled smoothing, and its readable reference.

:func:`igl_hhj.intrinsic.vertex_smoothing` runs the smoothing in one compiled call
(:func:`igl_hhj.kernels.intrinsic_smoothing`); should one of its PCG solves stall, the
drop-in finishes with :func:`smooth_reference` here, which factorises instead.  The same
functions are the readable version of that kernel (``tests/vertex_stage`` compares them):

* the vertex frames and the minimal rotations between tangent planes (:func:`vertex_frames`,
  :func:`transport`), the spin-2 transport of each edge (:func:`transport_phases`);
* the scalar and the spin-2 connection Laplacians (:func:`connection_laplacians`) with the
  stiffness of :func:`igl_hhj.recovery.smoothing_coefficients` times per-face diffusion times
  (:func:`smoothing_times`);
* the twiced implicit diffusion (:func:`smooth`), the adaptive per-face radius
  (:func:`adaptive_radius`) from a pilot step.

:func:`to_tensors` turns the components (h, Re z, Im z) back into ambient tensors
(:func:`igl_hhj.curvature.vertex_shape_operator`).  The numpy reference of the recovery
half (corner components, patch fit, roughness) is only used by the tests:
``tests/vertex_stage/reference_intrinsic.py``.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .constants import (ADAPTIVE_GAIN, ADAPTIVE_POWER, ADAPTIVE_RANGE, PILOT_RADIUS, SMOOTHING_ORDER,
                        SMOOTHING_PER_RADIUS, SMOOTHING_STEPS)
from .mesh import TriangleMesh
from .recovery import kernel_coefficients, smoothing_coefficients

__all__ = [
    "vertex_frames", "transport", "transport_phases", "transport_phase_components", "smoothing_times",
    "adaptive_radius", "connection_laplacians", "smooth", "smooth_reference", "to_tensors",
]


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
    hT = mesh.edge_lengths.mean(axis=1)
    return (SMOOTHING_PER_RADIUS * np.asarray(radius, dtype=np.float64) * hT) ** 2 / steps


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
    mean_{v∈T} a_v``: ρ̄ the ring mean of the roughness ρ of the recovery
    (:func:`igl_hhj.kernels.intrinsic_patch_recovery`), ``c̄`` the ring mean of
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
    for c in kernel_coefficients(order):
        for _ in range(steps):
            h, z = solve_h(m * h), solve_z(m * z)
        hs += c * h
        zs += c * z
    out = np.stack([hs, zs.real, zs.imag], axis=1)
    out[~mesh.referenced_vertices] = 0.0
    return out


def to_tensors(X, N):
    """(n, 3, 3) ambient tangential tensors ``h P + a (e1e1 - e2e2) + b (e1e2 + e2e1)``."""
    e1, e2 = vertex_frames(N)
    h, a, b = X[:, 0, None, None], X[:, 1, None, None], X[:, 2, None, None]
    E11 = e1[:, :, None] * e1[:, None, :]
    E22 = e2[:, :, None] * e2[:, None, :]
    E12 = e1[:, :, None] * e2[:, None, :]
    return h * (E11 + E22) + a * (E11 - E22) + b * (E12 + np.swapaxes(E12, 1, 2))


def smooth_reference(mesh, X, N, w, rough, radius):
    """The whole smoothing of the vertex stage by sparse LU: the pilot step, the adaptive
    radius, the twiced smoothing (the fallback of :func:`igl_hhj.intrinsic.vertex_smoothing`
    when a compiled solve stalls, and the reference of
    :func:`igl_hhj.kernels.intrinsic_smoothing`).  ``rough`` (#V,): the roughness the
    recovery measured.  Returns a new (#V, 3) array."""
    pilot = smooth(mesh, X, N, w, PILOT_RADIUS, steps=1, order=1)
    r = adaptive_radius(mesh, pilot, rough, radius)
    return smooth(mesh, X, N, w, radius, times=smoothing_times(mesh, r))
