"""Exact test surfaces (analytic ν, ∇_Γν, projection) and mesh sequences.

Submodules: :mod:`.exact` (the surfaces) and :mod:`.meshing` (non-uniform
mesh sequences: perturbed coarse mesh + uniform refinement with projection).
"""
from .exact import (
    Ellipsoid,
    GraphSurface,
    ImplicitSurface,
    Sphere,
    WalkerGenus3,
    WalkerSaddle,
    WalkerTorus,
)
from .meshing import (
    ellipsoid_coarse,
    graph_coarse,
    icosphere,
    jitter_tangentially,
    mesh_sequence,
    refine,
    square_grid,
    STANDARD_SEQUENCES,
    standard_sequence,
    torus_coarse,
)

__all__ = [
    "ImplicitSurface", "GraphSurface", "Sphere", "Ellipsoid", "WalkerTorus", "WalkerGenus3",
    "WalkerSaddle", "refine", "mesh_sequence", "jitter_tangentially", "icosphere",
    "ellipsoid_coarse", "torus_coarse", "square_grid", "graph_coarse", "standard_sequence",
    "STANDARD_SEQUENCES",
]
