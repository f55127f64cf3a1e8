"""Non-uniform, non-symmetric mesh sequences of exact surfaces.

Walker §6: "to avoid spurious results", meshes come from a *perturbed* coarse
mesh, then uniform refinement (``igl.upsample``, 1 → 4 triangles) with every
new vertex projected onto the exact surface.  All generators are seeded.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .exact import Ellipsoid, GraphSurface, ImplicitSurface, Sphere, WalkerSaddle, WalkerTorus

__all__ = [
    "refine", "boundary_vertex_mask", "mesh_sequence", "jitter_tangentially", "icosphere",
    "ellipsoid_coarse", "torus_coarse", "square_grid", "graph_coarse",
]


def boundary_vertex_mask(F, n_vertices):
    """(#V,) bool: vertices on an edge used by exactly one face (vectorised, no validation)."""
    F = np.asarray(F, dtype=np.int64)
    E = np.sort(np.concatenate([F[:, [1, 2]], F[:, [2, 0]], F[:, [0, 1]]]), axis=1)
    uE, count = np.unique(E, axis=0, return_counts=True)
    mask = np.zeros(n_vertices, dtype=bool)
    mask[uE[count == 1].ravel()] = True
    return mask


def refine(V, F, surface, levels=1, project_boundary=None):
    """``levels`` uniform refinements (``igl.upsample``, 1 → 4 triangles) with
    the new vertices projected.

    Parameters
    ----------
    V, F : the mesh (its vertices are assumed to lie on the surface already).
    surface : ImplicitSurface or callable
        New vertices are mapped by ``surface.project`` (or by ``surface`` itself
        when it is a callable ``(n, 3) -> (n, 3)``).
    levels : int
    project_boundary : callable, optional
        If given, new vertices on the boundary are mapped by it instead (e.g.
        onto a curved boundary), the others by ``surface``.

    Old vertices keep their index and position (``igl.upsample`` appends the
    edge midpoints), so only the appended ones are moved.
    """
    import igl
    project = surface.project if hasattr(surface, "project") else surface
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    for _ in range(levels):
        n_old = len(V)
        V, F = igl.upsample(V, F)
        V = np.array(V)
        F = np.asarray(F, dtype=np.int64)
        new = np.zeros(len(V), dtype=bool)
        new[n_old:] = True
        if project_boundary is None:
            V[new] = project(V[new])
            continue
        bnd = boundary_vertex_mask(F, len(V))
        if (new & ~bnd).any():
            V[new & ~bnd] = project(V[new & ~bnd])
        if (new & bnd).any():
            V[new & bnd] = project_boundary(V[new & bnd])
    return V, F


def mesh_sequence(V0, F0, surface: ImplicitSurface, n_levels, pre_refine=0):
    """[(V_k, F_k) for k = 0..n_levels-1]: ``pre_refine`` + k refinements of (V0, F0)."""
    V, F = refine(V0, F0, surface, pre_refine) if pre_refine else (np.asarray(V0, float), np.asarray(F0))
    out = [(V, F)]
    for _ in range(n_levels - 1):
        V, F = refine(V, F, surface, 1)
        out.append((V, F))
    return out


def _vertex_spacing(V, F):
    """(#V,) mean length of the edges incident to each vertex."""
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    L = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    s = np.bincount(E.ravel(), weights=np.repeat(L, 2), minlength=len(V))
    c = np.bincount(E.ravel(), minlength=len(V))
    return s / np.maximum(c, 1)


def jitter_tangentially(V, F, surface: ImplicitSurface, amount=0.2, seed=0, fixed=None):
    """Move every vertex by up to ``amount`` × its mean incident edge length in a
    random tangent direction, then project back onto ``surface``.

    ``fixed`` (#V bool) marks vertices that must not move."""
    rng = np.random.default_rng(seed)
    V = np.asarray(V, dtype=np.float64)
    nu = surface.normal(V)
    d = rng.normal(size=V.shape)
    d -= np.einsum("ij,ij->i", d, nu)[:, None] * nu
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    r = amount * _vertex_spacing(V, F) * rng.uniform(0.0, 1.0, size=len(V))
    W = V + r[:, None] * d
    if fixed is not None:
        W[fixed] = V[fixed]
    W = surface.project(W)
    if fixed is not None:
        W[fixed] = V[fixed]
    return W


def icosphere(subdivisions: int = 1) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Unit icosphere: ``igl.icosahedron`` with ``subdivisions`` normalised upsamplings."""
    import igl
    V, F = igl.icosahedron()
    V = V / np.linalg.norm(V, axis=1, keepdims=True)
    return refine(V, F, Sphere(1.0), subdivisions)


def ellipsoid_coarse(surface=None, subdivisions=1, amount=0.25, seed=0):
    """Perturbed coarse mesh of an ellipsoid (icosphere scaled by the semi-axes, jittered)."""
    surface = Ellipsoid() if surface is None else surface
    V, F = icosphere(subdivisions)
    V = surface.project(V * surface.axes)
    return jitter_tangentially(V, F, surface, amount, seed), F


def torus_coarse(n_phi=24, n_t=12, amount=0.25, seed=0, surface=None):
    """Perturbed coarse mesh of Walker's torus: a (phi, t) grid whose quads are
    split along randomly chosen diagonals, jittered in parameter space."""
    surface = WalkerTorus() if surface is None else surface
    rng = np.random.default_rng(seed)
    i, j = np.meshgrid(np.arange(n_phi), np.arange(n_t), indexing="ij")
    phi = 2 * np.pi * (i + amount * rng.uniform(-1, 1, i.shape)) / n_phi
    t = 2 * np.pi * (j + amount * rng.uniform(-1, 1, j.shape)) / n_t
    V = surface.project(surface.parametrize(t.ravel(), phi.ravel()))
    idx = lambda a, b: (a % n_phi) * n_t + (b % n_t)  # noqa: E731
    a, b = i.ravel(), j.ravel()
    v00, v10, v11, v01 = idx(a, b), idx(a + 1, b), idx(a + 1, b + 1), idx(a, b + 1)
    flip = rng.uniform(size=a.shape) < 0.5
    T1 = np.where(flip[:, None], np.stack([v00, v10, v11], 1), np.stack([v00, v10, v01], 1))
    T2 = np.where(flip[:, None], np.stack([v00, v11, v01], 1), np.stack([v10, v11, v01], 1))
    F = np.concatenate([T1, T2])
    # orient outward: compare face normal with the exact normal at the centroid
    X = V[F]
    nrm = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    out = np.einsum("ij,ij->i", nrm, surface.normal(surface.project(X.mean(axis=1)))) > 0
    F[~out] = F[~out][:, [0, 2, 1]]
    return V, F


def square_grid(n, amount=0.25, seed=0, lo=0.0, hi=1.0):
    """Planar mesh of the square [lo, hi]² with n×n cells, random diagonals and
    jittered vertices (interior in both directions, edge vertices along their
    side, corners fixed).  Counter-clockwise triangles.

    Returns
    -------
    P : ((n+1)², 2) float64, F : (2n², 3) int64
    """
    rng = np.random.default_rng(seed)
    g = np.linspace(lo, hi, n + 1)
    X, Y = np.meshgrid(g, g, indexing="ij")
    P = np.column_stack([X.ravel(), Y.ravel()])
    h = (hi - lo) / n
    d = amount * h * rng.uniform(-1, 1, size=P.shape)
    on_x = np.isclose(P[:, 0], lo) | np.isclose(P[:, 0], hi)
    on_y = np.isclose(P[:, 1], lo) | np.isclose(P[:, 1], hi)
    d[on_x, 0] = 0.0
    d[on_y, 1] = 0.0
    P = P + d
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a, b = i.ravel(), j.ravel()
    idx = lambda p, q: p * (n + 1) + q  # noqa: E731
    v00, v10, v11, v01 = idx(a, b), idx(a + 1, b), idx(a + 1, b + 1), idx(a, b + 1)
    flip = rng.uniform(size=a.shape) < 0.5
    T1 = np.where(flip[:, None], np.stack([v00, v10, v11], 1), np.stack([v00, v10, v01], 1))
    T2 = np.where(flip[:, None], np.stack([v00, v11, v01], 1), np.stack([v10, v11, v01], 1))
    return P, np.concatenate([T1, T2]).astype(np.int64)


def graph_coarse(surface: GraphSurface, n=4, amount=0.25, seed=0):
    """Perturbed coarse mesh of a graph surface over [0, 1]² (upward normals)."""
    P, F = square_grid(n, amount, seed)
    return surface.lift(P), F


STANDARD_SEQUENCES = ("ellipsoid", "torus", "saddle", "sphere")
"""Names of :func:`standard_sequence`."""


def standard_sequence(name, levels):
    """The non-uniform mesh sequences of the rate tests and of the Hessian benchmark:
    ``(surface, [(V, F), ...])`` with ``levels`` meshes, each refined uniformly from a
    perturbed coarse mesh and projected onto the exact surface.

    ``"ellipsoid"`` (icosahedral, 2 subdivisions, 20 % perturbation), ``"torus"``
    (Walker's torus from a 16 × 8 grid, 20 %), ``"saddle"`` (Walker's saddle graph, a 6 × 6
    grid, 20 %), ``"sphere"`` (icosphere(1) jittered tangentially by 0.3 h)."""
    if name == "ellipsoid":
        s = Ellipsoid()
        return s, mesh_sequence(*ellipsoid_coarse(s, subdivisions=2, amount=0.2), s, levels)
    if name == "torus":
        s = WalkerTorus()
        return s, mesh_sequence(*torus_coarse(n_phi=16, n_t=8, amount=0.2), s, levels)
    if name == "saddle":
        s = WalkerSaddle()
        return s, mesh_sequence(*graph_coarse(s, n=6, amount=0.2), s, levels)
    if name == "sphere":
        s = Sphere()
        V, F = icosphere(1)
        return s, mesh_sequence(jitter_tangentially(V, F, s, 0.3, seed=1), F, s, levels)
    raise ValueError(f"unknown sequence {name!r}; one of {STANDARD_SEQUENCES}")
