"""Boundary data for the HHJ shape operator from exact surfaces (Walker §6).

Walker uses the nodal interpolants of the exact fields on the boundary:
``ν~ = I_h ν`` for clamped edges (saddle, §6.1) and
``κ~_n = n̂ᵀ (I_h ∇_Γν) n̂`` for simply supported edges (dumbbell, §6.2).
:func:`igl_hhj.shape_operator` interpolates vertex data linearly along each
boundary edge, so the vertex values below are exactly those interpolants.
"""
from __future__ import annotations

import numpy as np

from ..mesh import as_mesh
from .exact import ImplicitSurface

__all__ = ["exact_boundary_normals", "exact_boundary_shape_operator", "walker_boundary_data"]


def _check_surface(surface):
    if not isinstance(surface, ImplicitSurface):
        raise TypeError(f"surface must be an igl_hhj.surfaces.exact.ImplicitSurface, got {type(surface).__name__}")


def exact_boundary_normals(V, F, surface):
    """Exact unit normal ν at the boundary vertices (clamped data, Walker §6.1).

    Parameters
    ----------
    V : (#V, 3) vertices on ``surface``; F : (#F, 3) triangles (oriented like ν).
    surface : ImplicitSurface

    Returns
    -------
    N : (#V, 3) float64, ``surface.normal`` on boundary vertices, NaN elsewhere
        (so that a solver reading an interior row would fail loudly).
    """
    _check_surface(surface)
    mesh = as_mesh(V, F)
    b = mesh.boundary_vertices
    N = np.full((mesh.n_vertices, 3), np.nan)
    N[b] = surface.normal(mesh.V[b])
    return N


def exact_boundary_shape_operator(V, F, surface):
    """Exact shape operator ∇_Γν at the boundary vertices (simply supported data, Walker §6.2).

    Returns
    -------
    S : (#V, 3, 3) float64, ``surface.shape_operator`` on boundary vertices, NaN elsewhere.
    """
    _check_surface(surface)
    mesh = as_mesh(V, F)
    b = mesh.boundary_vertices
    S = np.full((mesh.n_vertices, 3, 3), np.nan)
    S[b] = surface.shape_operator(mesh.V[b])
    return S


def walker_boundary_data(V, F, surface, kind):
    """Keyword arguments of :func:`igl_hhj.shape_operator` for Walker's boundary conditions.

    Parameters
    ----------
    kind : {"clamped", "simply_supported", "plain"}
        "clamped": ``boundary_normals = I_h ν`` (eq. 5.19, Σ_c);
        "simply_supported": ``boundary_shape_operator = I_h ∇_Γν`` (eq. 5.18, Σ_s);
        "plain": no data, plain assembly (``boundary="plain"``; without the
        keyword, shape_operator would estimate the boundary normals).

    Returns
    -------
    dict
    """
    if kind == "clamped":
        return {"boundary_normals": exact_boundary_normals(V, F, surface)}
    if kind == "simply_supported":
        return {"boundary_shape_operator": exact_boundary_shape_operator(V, F, surface)}
    if kind == "plain":
        _check_surface(surface)
        return {"boundary": "plain"}
    raise ValueError(f"unknown boundary kind {kind!r}; use 'clamped', 'simply_supported' or 'plain'")
