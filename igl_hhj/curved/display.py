"""Flat display meshes of curved surfaces (polyscope has no curved elements).

:func:`display_mesh` refines every curved triangle into ``subdivisions²`` flat
triangles through points of the element map, merges the duplicated points of
shared edges (``igl.remove_duplicate_vertices``) and returns per-vertex values of a
:class:`CurvedField` (averaged where elements meet) that
:func:`igl_hhj.viewer.register_scalars` can show (:func:`igl_hhj.viewer.show_curved_field`
does both).
"""
from __future__ import annotations

import numpy as np

__all__ = ["display_mesh"]


def _lattice(s):
    pts, idx = [], {}
    for i in range(s + 1):
        for j in range(s + 1 - i):
            idx[(i, j)] = len(pts)
            pts.append((i / s, j / s))
    tris = []
    for i in range(s):
        for j in range(s - i):
            tris.append((idx[(i, j)], idx[(i + 1, j)], idx[(i, j + 1)]))
            if i + j < s - 1:
                tris.append((idx[(i + 1, j)], idx[(i + 1, j + 1)], idx[(i, j + 1)]))
    return np.array(pts), np.array(tris, dtype=np.int64)


def display_mesh(surface, field=None, subdivisions=4, exact=None):
    """Flat refinement of a curved surface with per-vertex field values.

    Parameters
    ----------
    surface : LagrangeSurface
    field : CurvedField, optional
    subdivisions : int ≥ 1, sub-triangles per curved edge.
    exact : ImplicitSurface, optional: adds ``|H error|`` against it.

    Returns
    -------
    V : (#V, 3), F : (#F, 3) int64 (oriented like the surface),
    values : dict name → (#V,) (``H``, ``K``, ``k1``, ``k2`` [, ``|H error|``]; empty without field).
    """
    import igl
    s = int(subdivisions)
    if s < 1:
        raise ValueError(f"subdivisions must be at least 1, got {subdivisions}")
    xi, T = _lattice(s)
    nF, q = surface.n_faces, len(xi)
    faces = np.repeat(np.arange(nF), q)
    bary = np.tile(np.column_stack([1 - xi.sum(1), xi]), (nF, 1))
    X = surface.points(faces, bary)
    F = (T[None] + q * np.arange(nF)[:, None, None]).reshape(-1, 3)
    h = surface.h
    SV, SVI, SVJ, SF = igl.remove_duplicate_vertices(X, F, 1e-9 * h)
    SVJ = np.asarray(SVJ).ravel()
    values = {}
    if field is not None:
        k1, k2, _, _ = field.principal(faces, bary)
        raw = {"H": 0.5 * (k1 + k2), "K": k1 * k2, "k1": k1, "k2": k2}
        if exact is not None:
            raw["|H error|"] = np.abs(raw["H"] - exact.mean_curvature(exact.project(X)))
        cnt = np.bincount(SVJ, minlength=len(SV)).astype(float)
        for k, v in raw.items():
            values[k] = np.bincount(SVJ, weights=v, minlength=len(SV)) / cnt
    return np.asarray(SV), np.asarray(SF, dtype=np.int64), values
