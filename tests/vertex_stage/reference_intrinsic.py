"""The numpy reference of the intrinsic vertex stage's recovery half (only the tests use it):
the face tensors seen from each corner's vertex frame, their weighted linear patch fit, the
roughness, the principal values of the components, and the whole stage with the sparse-LU
smoothing of :mod:`igl_hhj.intrinsic_numpy`.  Compared with the compiled kernels
(:func:`igl_hhj.kernels.intrinsic_patch_recovery`, :func:`igl_hhj.kernels.principal_hz`,
:func:`igl_hhj.intrinsic.vertex_stage`) in tests/vertex_stage."""
import numpy as np

from igl_hhj.intrinsic_numpy import smooth_reference, transport, vertex_frames
from igl_hhj.mesh import TriangleMesh
from igl_hhj.recovery import recovery_operator, recovery_weights


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
    e1, e2 = vertex_frames(N)
    Y, cosine = corner_components(mesh, S, N, e1, e2)
    W = np.where(cosine > 0, np.asarray(weights, dtype=np.float64)[:, None], 0.0)
    R = recovery_operator(mesh, "patch", W, N, corners=True)               # rows: vertices, cols: corners
    Y = np.where(np.isfinite(Y), Y, 0.0).reshape(-1, 3)
    return R @ Y


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


def vertex_stage_reference(mesh: TriangleMesh, S, radius, *, normals=None, weights=None):
    """Numpy reference of :func:`vertex_stage` (sparse LU instead of PCG).

    Returns X (#V, 3) components (rows of unreferenced vertices 0), N (#V, 3)."""
    N = mesh.vertex_normals if normals is None else normals
    w = recovery_weights(mesh) if weights is None else weights
    X = recover(mesh, S, N, w)
    if radius > 0:
        X = smooth_reference(mesh, X, N, w, roughness(mesh, S, N, X, w), radius)
    return X, N


def principal_from_shape_operator_reference(S, normals):
    """The readable numpy reference of :func:`principal_from_shape_operator` (``eigh``)."""
    N = normals
    # Tangent frame: e1 ⟂ N from the coordinate axis least aligned with N.
    ax = np.eye(3)[np.argmin(np.abs(N), axis=1)]
    e1 = np.cross(N, ax)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(N, e1)
    E = np.stack([e1, e2], axis=2)                      # (n, 3, 2)
    S2 = np.einsum("nai,nab,nbj->nij", E, S, E)
    S2 = 0.5 * (S2 + np.swapaxes(S2, 1, 2))
    w, U = np.linalg.eigh(S2)                           # ascending
    PV1, PV2 = w[:, 1], w[:, 0]
    PD1 = np.einsum("nai,ni->na", E, U[:, :, 1])
    PD1 /= np.linalg.norm(PD1, axis=1, keepdims=True)
    PD2 = np.cross(N, PD1)
    return PD1, PD2, PV1, PV2
