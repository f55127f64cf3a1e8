"""Gauss quadrature rules of arbitrary order on the unit interval and the
reference triangle.

The Regge interpolant (eq. 3.1 of Gopalakrishnan–Neunteufel–Schöberl–Wardetzky)
must reproduce the edge and cell moments *exactly*; curvature amplifies metric
errors by ~1/h², so a fixed low-order rule produces an error floor at k = 3
(design note ``regge.md``).  These rules are exact to round-off for polynomials
of the requested degree.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = ["gauss_legendre", "triangle_rule"]


def _check_degree(degree):
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)):
        raise TypeError(f"quadrature degree must be an integer, got {type(degree).__name__}")
    if degree < 0:
        raise ValueError(f"quadrature degree must be >= 0, got {degree}")
    return int(degree)


@lru_cache(maxsize=64)
def _gl(n):
    x, w = np.polynomial.legendre.leggauss(n)
    s = 0.5 * (x + 1.0)
    w = 0.5 * w
    s.setflags(write=False)
    w.setflags(write=False)
    return s, w


def gauss_legendre(degree):
    """Gauss–Legendre rule on ``[0, 1]`` exact for polynomials of ``degree``.

    Returns
    -------
    s : (n,) float64 nodes in (0, 1)
    w : (n,) float64 weights, summing to 1
    """
    degree = _check_degree(degree)
    return _gl(degree // 2 + 1)


@lru_cache(maxsize=64)
def _tri(degree):
    from scipy.special import roots_jacobi

    n = degree // 2 + 1
    # collapsed (Duffy) rule: ξ = u, η = v (1 - u), dξ dη = (1 - u) du dv
    xj, wj = roots_jacobi(n, 1.0, 0.0)         # weight (1 - x) on [-1, 1]
    u = 0.5 * (xj + 1.0)
    wu = wj / 4.0                               # ∫_0^1 f(u)(1-u) du
    v, wv = _gl(n)
    U, Vv = np.meshgrid(u, v, indexing="ij")
    WU, WV = np.meshgrid(wu, wv, indexing="ij")
    xi = U.ravel()
    eta = (Vv * (1.0 - U)).ravel()
    pts = np.stack([xi, eta], axis=1)
    w = (WU * WV).ravel()
    pts.setflags(write=False)
    w.setflags(write=False)
    return pts, w


def triangle_rule(degree):
    """Collapsed Gauss rule on the reference triangle ``{ξ, η ≥ 0, ξ + η ≤ 1}``.

    Exact for polynomials of total degree ``degree``; ``((degree//2 + 1)**2)``
    points, all strictly inside the triangle.

    Returns
    -------
    points : (n, 2) float64 reference coordinates ``(ξ, η)``
    weights : (n,) float64, summing to 1/2 (the reference area)
    """
    degree = _check_degree(degree)
    return _tri(degree)
