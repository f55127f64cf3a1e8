"""Exact metrics and meshes for the Regge layer's tests and benchmark.

The §4 example of Gopalakrishnan et al. 2024 (after Gawlik): the metric of the graph of
``f(x, y) = (x² + y²)/2 - (x⁴ + y⁴)/12`` on the quarter domain ``(0, 1)²``,
right and bottom sides Dirichlet, left and top Neumann.  Mesh recipe and
random perturbation exactly as in the design note ``regge.md`` (seed 0).
"""
from __future__ import annotations

import numpy as np

__all__ = ["structured_square", "graph_metric", "graph_gauss_curvature",
           "graph_boundary_geodesic_curvature", "graph_dirichlet", "graph_densitized_curvature",
           "graph_gauss_curvature_gradient", "graph_densitized_curvature_gradient", "sphere_metric",
           "euclidean_metric", "polynomial_metric"]


def structured_square(l, seed=0, perturb=True):
    """Perturbed structured mesh of ``(0, 1)²`` with ``2^(2l+1)`` triangles.

    Vertex ``(i, j)`` sits at ``(i/N, j/N)``, ``N = 2^l``, with index ``j(N+1)+i``;
    cell → ``[p00, p10, p11]``, ``[p00, p11, p01]``; interior vertices (increasing
    index order) are shifted by ``default_rng(seed).uniform(-d, d, (n_int, 2))``,
    ``d = 2^-l / 4 = h / 2^2.5``.

    Returns
    -------
    P : (#V, 2) float64, F : (#F, 3) int64 (counter-clockwise)
    """
    N = 2 ** int(l)
    i, j = np.meshgrid(np.arange(N + 1), np.arange(N + 1), indexing="xy")
    P = np.stack([i.ravel() / N, j.ravel() / N], axis=1).astype(np.float64)
    ci, cj = np.meshgrid(np.arange(N), np.arange(N), indexing="xy")
    p00 = (cj * (N + 1) + ci).ravel()
    p10, p11, p01 = p00 + 1, p00 + N + 2, p00 + N + 1
    F = np.concatenate([np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)], axis=0)
    F = F.reshape(2, -1, 3).transpose(1, 0, 2).reshape(-1, 3).astype(np.int64)
    if perturb:
        interior = np.flatnonzero((P > 0).all(1) & (P < 1).all(1))
        d = 2.0 ** (-l) / 4.0
        P[interior] += np.random.default_rng(seed).uniform(-d, d, size=(interior.size, 2))
    return P, F


def _fx(x):
    return x - x ** 3 / 3.0


def graph_metric(X):
    """``ḡ = I + ∇f ∇fᵀ`` for ``f = (x²+y²)/2 - (x⁴+y⁴)/12``; ``(N, 2) -> (N, 2, 2)``."""
    X = np.asarray(X, dtype=np.float64)
    fx, fy = _fx(X[:, 0]), _fx(X[:, 1])
    return np.stack([np.stack([1 + fx * fx, fx * fy], -1),
                     np.stack([fx * fy, 1 + fy * fy], -1)], -2)


def graph_gauss_curvature(X):
    """``K̄ = 81(1-x²)(1-y²) / (9 + x²(x²-3)² + y²(y²-3)²)²``."""
    x, y = np.asarray(X, dtype=np.float64).T
    return 81 * (1 - x * x) * (1 - y * y) / (9 + x * x * (x * x - 3) ** 2 + y * y * (y * y - 3) ** 2) ** 2


def graph_boundary_geodesic_curvature(X, t=None):
    """``κ̄`` on the Neumann sides of the quarter domain: 0 on ``x = 0``, the paper's
    formula on ``y = 1`` (inward-normal convention, counter-clockwise traversal)."""
    x, y = np.asarray(X, dtype=np.float64).T
    a = x * x * (x * x - 3) ** 2
    b = y * y * (y * y - 3) ** 2
    top = -27 * (x * x - 1) * y * (y * y - 3) / ((a + 9) ** 1.5 * np.sqrt(a + b + 9))
    return np.where(np.abs(y - 1) < 1e-12, top, 0.0)


def graph_dirichlet(mid):
    """Dirichlet part of the §4 example: right (x = 1) and bottom (y = 0) sides."""
    mid = np.asarray(mid)
    return (np.abs(mid[:, 0] - 1) < 1e-12) | (np.abs(mid[:, 1]) < 1e-12)


def sphere_metric(R=1.0):
    """Round sphere of radius ``R`` in stereographic coordinates:
    ``g = 4R⁴ / (R² + |x|²)² I`` (constant ``K = 1/R²``)."""
    def metric(X):
        X = np.asarray(X, dtype=np.float64)
        c = 4 * R ** 4 / (R * R + (X ** 2).sum(1)) ** 2
        return c[:, None, None] * np.eye(2)[None]
    return metric


def euclidean_metric(X):
    X = np.asarray(X)
    return np.broadcast_to(np.eye(2), (X.shape[0], 2, 2)).copy()


def polynomial_metric(k, seed=0):
    """A random symmetric metric whose components are polynomials of degree ``k``
    (positive definite on ``[0, 1]²``)."""
    rng = np.random.default_rng(seed)
    exps = [(a, d - a) for d in range(k + 1) for a in range(d + 1)]
    # |non-constant part| ≤ 0.5 on [0, 1]²: diagonal ≥ 1.5, |off-diagonal| ≤ 0.8 → SPD
    C = rng.uniform(-0.5, 0.5, size=(3, len(exps))) / len(exps)
    C[:, 0] = [2.0, 0.3, 2.0]

    def metric(X):
        X = np.asarray(X, dtype=np.float64)
        mono = np.stack([X[:, 0] ** a * X[:, 1] ** b for a, b in exps], 1)
        c = mono @ C.T
        return np.stack([np.stack([c[:, 0], c[:, 1]], -1), np.stack([c[:, 1], c[:, 2]], -1)], -2)
    return metric


def graph_densitized_curvature(X):
    """``K̄ ω̄ = K̄ √det ḡ`` (the target of the densitized lifting, Remark 3.3)."""
    X = np.asarray(X, dtype=np.float64)
    fx, fy = _fx(X[:, 0]), _fx(X[:, 1])
    return graph_gauss_curvature(X) * np.sqrt(1 + fx * fx + fy * fy)


def _graph_D(x, y):
    """``D = 9 + x²(x²-3)² + y²(y²-3)² = 9 det ḡ`` and ``∂_x D, ∂_y D``."""
    D = 9 + x * x * (x * x - 3) ** 2 + y * y * (y * y - 3) ** 2
    return D, 6 * x * (x * x - 3) * (x * x - 1), 6 * y * (y * y - 3) * (y * y - 1)


def graph_gauss_curvature_gradient(X):
    """``∇K̄`` of :func:`graph_gauss_curvature`; ``(N, 2) -> (N, 2)`` (for the H¹_h error,
    Corollary 3.9)."""
    x, y = np.asarray(X, dtype=np.float64).T
    D, Dx, Dy = _graph_D(x, y)
    A, B = 1 - x * x, 1 - y * y
    return np.stack([81 * B * (-2 * x * D - 2 * A * Dx) / D ** 3,
                     81 * A * (-2 * y * D - 2 * B * Dy) / D ** 3], 1)


def graph_densitized_curvature_gradient(X):
    """``∇(K̄ ω̄)`` of :func:`graph_densitized_curvature` (``ω̄ = √D / 3``); ``(N, 2) -> (N, 2)``
    (for the H¹_h error of Corollary 3.2)."""
    X = np.asarray(X, dtype=np.float64)
    x, y = X.T
    D, Dx, Dy = _graph_D(x, y)
    om = np.sqrt(D) / 3.0
    K = graph_gauss_curvature(X)
    dK = graph_gauss_curvature_gradient(X)
    return dK * om[:, None] + K[:, None] * np.stack([Dx, Dy], 1) / (6.0 * np.sqrt(D))[:, None]
