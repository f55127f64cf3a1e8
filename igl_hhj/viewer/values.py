"""The values a picture shows: quantity names and colour-bar labels, colour ranges,
direction lengths, and the check of the named choices."""
from __future__ import annotations

import numpy as np

from ..results import QUANTITIES  # noqa: F401  (the quantities the curvature pictures show)


METHODS = ("hhj", "igl", "heine")
LABELS = {"k1": "kappa1", "k2": "kappa2", "H": "mean H", "K": "Gauss K"}
LENGTH_UNIT = "1/length unit"
"""Unit of curvatures in colour-bar labels (the mesh's coordinates carry the length unit)."""
LONG_LABELS = {"k1": f"principal curvature κ1 [{LENGTH_UNIT}]", "k2": f"principal curvature κ2 [{LENGTH_UNIT}]",
               "H": f"mean curvature H [{LENGTH_UNIT}]", "K": "Gauss curvature K [1/length unit²]"}
"""Colour-bar labels of the curvature quantities (with their units)."""
METHOD_TITLES = {"HHJ": "HHJ", "libigl": "libigl quadric fit", "Heine": "Heine P1"}
"""How titles name the estimators (by their tag)."""
_TAG = {"hhj": "HHJ", "igl": "libigl", "heine": "Heine"}


def color_range(*arrays, symmetric=True, robust=None) -> tuple[float, float]:
    """One colour range for several value arrays (NaN/inf ignored).

    Parameters
    ----------
    *arrays : array_like
    symmetric : bool, default True
        Return ``(-m, m)`` with ``m`` the largest magnitude (diverging maps:
        white is 0).
    robust : float or None
        Percentile ``p`` in [0, 50): use the ``[p, 100-p]`` percentiles instead
        of min/max, ignoring outliers.

    Returns
    -------
    (lo, hi) : floats with ``lo < hi`` (``(-1, 1)`` if no finite value).
    """
    if robust is not None and not (0.0 <= float(robust) < 50.0):
        raise ValueError(f"robust must be a percentile in [0, 50), got {robust!r}")
    vals = np.concatenate([np.asarray(a, dtype=np.float64).ravel() for a in arrays]) if arrays else np.zeros(0)
    vals = vals[np.isfinite(vals)]
    if vals.size == 0:
        return (-1.0, 1.0)
    if robust is None:
        lo, hi = float(vals.min()), float(vals.max())
    else:
        lo, hi = (float(x) for x in np.percentile(vals, [float(robust), 100.0 - float(robust)]))
    if symmetric:
        m = max(abs(lo), abs(hi))
        lo, hi = -m, m
    if hi <= lo:
        pad = max(abs(hi), 1.0) * 1e-6
        lo, hi = lo - pad, hi + pad
    return lo, hi


def local_edge_length(mesh, location) -> np.ndarray:
    """Mean length of the edges of each face, or incident to each vertex.

    Parameters
    ----------
    mesh : TriangleMesh
    location : {"face", "vertex"}

    Returns
    -------
    (#F,) or (#V,) float64 (unreferenced vertices get the global mean).
    """
    if location == "face":
        return mesh.edge_lengths.mean(axis=1)
    ends = mesh.edges.ravel()
    total = np.bincount(ends, weights=np.repeat(mesh.unique_edge_lengths, 2), minlength=mesh.n_vertices)
    count = np.bincount(ends, minlength=mesh.n_vertices)
    out = np.full(mesh.n_vertices, mesh.mean_edge_length)
    np.divide(total, count, out=out, where=count > 0)
    return out


def _explicit_range(vminmax):
    """A user-given (lo, hi) colour range, checked."""
    try:
        lo, hi = (float(x) for x in vminmax)
    except (TypeError, ValueError):
        raise ValueError(f"a colour range must be (lo, hi), got {vminmax!r}") from None
    if not lo < hi:
        raise ValueError(f"a colour range must be (lo, hi) with lo < hi, got {vminmax!r}")
    return lo, hi


def _check(value, name, choices):
    if value not in choices:
        raise ValueError(f"{name} must be one of {choices}, got {value!r}")
