"""Coarse meshes of closed implicit surfaces: marching cubes → remesh → projection.

Walker §6.3/§6.4 build "an initial piecewise linear triangulation of the
implicit, closed surface" (with a mesher, his ref. [37]) and then refine
uniformly, interpolating the closest-point map.  Here:

1. ``igl.marching_cubes`` of ``b`` on a grid whose origin is shifted by a
   random sub-cell offset (so the mesh has no symmetry of the surface),
2. ``gpytoolbox.remesh_botsch`` (isotropic remeshing: split / collapse /
   flip / tangential smoothing) to a target edge length chosen so that the
   triangle count is close to a requested one (Walker: torus 1904,
   genus-3 2808),
3. a small random tangential jitter, then Newton projection onto ``b = 0``
   (:meth:`ImplicitSurface.project`, to |b|/|∇b| < 1e-15), faces oriented so
   that ``(x1 - x0) × (x2 - x0)`` points along the outward normal ∇b.
"""
from __future__ import annotations

import numpy as np

from .exact import ImplicitSurface, WalkerGenus3, WalkerTorus
from .meshing import jitter_tangentially, refine

__all__ = [
    "marching_cubes_mesh", "implicit_coarse", "torus_mc_coarse", "genus3_coarse",
    "implicit_sequence", "orient_outward",
]


def marching_cubes_mesh(surface: ImplicitSurface, lo, hi, n=60, seed=0):
    """Marching-cubes triangulation of ``b = 0`` inside the box [lo, hi] with n³ grid points.

    The grid is shifted by a random fraction of a cell (seeded).

    Returns
    -------
    V : (#V, 3) float64, F : (#F, 3) int64 (orientation as produced by libigl).
    """
    import igl
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or not np.all(hi > lo):
        raise ValueError(f"lo and hi must be 3-vectors with hi > lo, got {lo} and {hi}")
    if int(n) < 4:
        raise ValueError(f"n must be at least 4 grid points per axis, got {n}")
    n = int(n)
    rng = np.random.default_rng(seed)
    off = rng.uniform(-0.5, 0.5, 3) * (hi - lo) / (n - 1)
    g = [np.linspace(lo[i], hi[i], n) + off[i] for i in range(3)]
    Z, Y, X = np.meshgrid(g[2], g[1], g[0], indexing="ij")     # x fastest, as libigl expects
    GV = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    V, F, _ = igl.marching_cubes(surface.value(GV), GV, n, n, n, 0.0)
    return np.asarray(V, dtype=np.float64), np.asarray(F, dtype=np.int64)


def orient_outward(V, F, surface: ImplicitSurface):
    """Flip faces whose normal disagrees with the exact outward normal at the projected centroid."""
    F = np.array(F, dtype=np.int64, copy=True)
    X = V[F]
    nrm = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    out = np.einsum("ij,ij->i", nrm, surface.normal(surface.project(X.mean(axis=1)))) > 0
    F[~out] = F[~out][:, [0, 2, 1]]
    return F


def _remesh(V, F, h, iterations):
    import gpytoolbox
    U, G = gpytoolbox.remesh_botsch(V, F.astype(np.int32), iterations, float(h), True)
    return np.asarray(U, dtype=np.float64), np.asarray(G, dtype=np.int64)


def implicit_coarse(surface: ImplicitSurface, lo, hi, n_faces, *, grid=60, iterations=20,
                    amount=0.15, seed=0, tries=4):
    """Coarse mesh of a closed implicit surface with about ``n_faces`` good triangles.

    Parameters
    ----------
    surface : ImplicitSurface
    lo, hi : (3,) box containing the surface.
    n_faces : int, target triangle count (hit to within a few percent).
    grid : marching-cubes grid points per axis.
    iterations : remeshing iterations.
    amount : tangential jitter (fraction of the local edge length) after remeshing.
    seed : int, grid offset and jitter.
    tries : number of edge-length corrections (h ← h √(#F / n_faces)).

    Returns
    -------
    V : (#V, 3) float64 on the surface (|b|/|∇b| < 1e-12), F : (#F, 3) int64 outward.
    """
    if int(n_faces) < 8:
        raise ValueError(f"n_faces must be at least 8, got {n_faces}")
    V0, F0 = marching_cubes_mesh(surface, lo, hi, grid, seed)
    if len(F0) == 0:
        raise ValueError("marching cubes found no surface inside the box [lo, hi]")
    V0 = surface.project(V0)
    X = V0[F0]
    area = 0.5 * np.linalg.norm(np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]), axis=1).sum()
    h = np.sqrt(4.0 * area / (np.sqrt(3.0) * n_faces))          # equilateral triangles
    best: tuple[np.ndarray, np.ndarray] | None = None
    for _ in range(int(tries)):
        V, F = _remesh(V0, F0, h, iterations)
        if best is None or abs(len(F) - n_faces) < abs(len(best[1]) - n_faces):
            best = (V, F)
        if abs(len(F) - n_faces) <= 0.01 * n_faces:
            break
        h *= np.sqrt(len(F) / n_faces)
    if best is None:
        raise ValueError(f"tries must be at least 1, got {tries}")
    V, F = best
    V = surface.project(V)
    F = orient_outward(V, F, surface)
    V = jitter_tangentially(V, F, surface, amount=amount, seed=seed)
    return V, F


def torus_mc_coarse(n_faces=1904, seed=0, **kw):
    """Walker's torus (§6.3) coarse mesh, about 1904 triangles (Walker's k = 0)."""
    s = WalkerTorus()
    return implicit_coarse(s, [-1.2, -1.2, -0.6], [1.2, 1.2, 0.6], n_faces, seed=seed, **kw)


def genus3_coarse(n_faces=2808, seed=0, a0=3.25, **kw):
    """Walker's genus-3 surface (§6.4, a0 = 3.25) coarse mesh, about 2808 triangles."""
    s = WalkerGenus3(a0)
    r = 1.2 * 3.25 / float(a0)
    return implicit_coarse(s, [-r] * 3, [r] * 3, n_faces, seed=seed, **kw)


def implicit_sequence(V0, F0, surface: ImplicitSurface, n_levels):
    """[(V_k, F_k)], k = 0..n_levels-1: k uniform refinements of (V0, F0), new vertices projected."""
    out = [(np.asarray(V0, dtype=np.float64), np.asarray(F0, dtype=np.int64))]
    for _ in range(n_levels - 1):
        out.append(refine(*out[-1], surface, 1))
    return out
