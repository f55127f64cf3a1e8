"""Heine's test surfaces (Heine 2006, eq. 5.1a–5.1d) with exact geometry and coarse meshes.

(5.1a) ``(x - z²)² + y² + z² - 1 = 0``            :class:`HeineA`
(5.1b) ``(x - z²)² + (y - z²)² + z² - 1 = 0``     :class:`HeineB`
(5.1c) ``x² + (2y)² + (2z/3)² - 1 = 0``           ``Ellipsoid()`` (default axes (1, 1/2, 3/2))
(5.1d) ``x² + y² + z² - 1 = 0``                   ``Sphere(1)``

(5.1a) and (5.1b) are images of the unit sphere under the shears
``(x, y, z) ↦ (x + z², y, z)`` and ``(x + z², y + z², z)``, so their coarse
meshes are *exact* images of a jittered icosphere (all vertices on the
surface); refinement projects new vertices with Newton steps (``project``).
The level-set functions are ``b`` as written (negative inside), so ``ν = ∇b/|∇b|``
is outward and the sign convention is the library's (sphere: +1/R).
"""
from __future__ import annotations

import numpy as np

from .exact import Ellipsoid, ImplicitSurface, Sphere

__all__ = ["HeineA", "HeineB", "heine_surfaces", "heine_coarse", "heine_sequence", "heine_adaptive_sequence"]


class HeineA(ImplicitSurface):
    """Heine (5.1a): ``b = (x - z²)² + y² + z² - 1``."""

    name = "heine_a"

    def value(self, X):
        x, y, z = X.T
        return (x - z * z) ** 2 + y * y + z * z - 1.0

    def gradient(self, X):
        x, y, z = X.T
        q = x - z * z
        return np.stack([2 * q, 2 * y, -4 * z * q + 2 * z], axis=1)

    def hessian(self, X):
        x, y, z = X.T
        H = np.zeros((len(X), 3, 3))
        H[:, 0, 0] = 2.0
        H[:, 1, 1] = 2.0
        H[:, 0, 2] = H[:, 2, 0] = -4 * z
        H[:, 2, 2] = -4 * x + 12 * z * z + 2.0
        return H

    @staticmethod
    def from_sphere(P):
        """Map unit-sphere points (n, 3) exactly onto the surface."""
        P = np.asarray(P, dtype=np.float64)
        return np.column_stack([P[:, 0] + P[:, 2] ** 2, P[:, 1], P[:, 2]])


class HeineB(ImplicitSurface):
    """Heine (5.1b): ``b = (x - z²)² + (y - z²)² + z² - 1``."""

    name = "heine_b"

    def value(self, X):
        x, y, z = X.T
        return (x - z * z) ** 2 + (y - z * z) ** 2 + z * z - 1.0

    def gradient(self, X):
        x, y, z = X.T
        p, q = x - z * z, y - z * z
        return np.stack([2 * p, 2 * q, -4 * z * (p + q) + 2 * z], axis=1)

    def hessian(self, X):
        x, y, z = X.T
        H = np.zeros((len(X), 3, 3))
        H[:, 0, 0] = 2.0
        H[:, 1, 1] = 2.0
        H[:, 0, 2] = H[:, 2, 0] = -4 * z
        H[:, 1, 2] = H[:, 2, 1] = -4 * z
        H[:, 2, 2] = -4 * (x + y) + 24 * z * z + 2.0
        return H

    @staticmethod
    def from_sphere(P):
        """Map unit-sphere points (n, 3) exactly onto the surface."""
        P = np.asarray(P, dtype=np.float64)
        z2 = P[:, 2] ** 2
        return np.column_stack([P[:, 0] + z2, P[:, 1] + z2, P[:, 2]])


def heine_surfaces():
    """dict label → surface for (5.1a)–(5.1d)."""
    c, d = Ellipsoid(), Sphere(1.0)
    return {"5.1a": HeineA(), "5.1b": HeineB(), "5.1c": c, "5.1d": d}


def heine_coarse(label, subdivisions=1, amount=0.25, seed=0):
    """Perturbed coarse mesh of a Heine surface, outward oriented.

    An icosphere with ``subdivisions`` levels (Heine's macro triangulation is
    an icosahedron), jittered tangentially by up to ``amount`` × the local
    edge length on the unit sphere, then mapped exactly onto the surface.

    Parameters
    ----------
    label : {"5.1a", "5.1b", "5.1c", "5.1d"}

    Returns
    -------
    V : (#V, 3) float64, F : (#F, 3) int64, surface : ImplicitSurface
    """
    from .meshing import icosphere, jitter_tangentially
    surfaces = heine_surfaces()
    if label not in surfaces:
        raise ValueError(f"unknown Heine surface {label!r}; use one of {sorted(surfaces)}")
    surface = surfaces[label]
    V, F = icosphere(subdivisions)
    V = jitter_tangentially(V, F, Sphere(1.0), amount, seed)
    if label == "5.1a":
        V = HeineA.from_sphere(V)
    elif label == "5.1b":
        V = HeineB.from_sphere(V)
    elif label == "5.1c":
        V = surface.project(V * surface.axes)
    return V, np.asarray(F, dtype=np.int64), surface


def heine_sequence(label, n_levels, pre_refine=1, subdivisions=1, amount=0.25, jitter=0.0, seed=0):
    """Non-uniform mesh sequence of a Heine surface, built on the unit sphere and mapped.

    The perturbed icosphere of :func:`heine_coarse` is refined on the unit
    sphere (``igl.upsample`` + radial projection); with ``jitter > 0`` every
    level is then moved tangentially by up to ``jitter`` × the local edge
    length (seeded, re-projected onto the sphere), so no parallelogram
    structure survives refinement.  Finally the vertices are mapped onto the
    surface: exactly by the shear for (5.1a)/(5.1b), by scaling + Newton
    projection for (5.1c), identity for (5.1d).  (Newton projection of jittered
    points straight onto (5.1a)/(5.1b) can leave the tubular neighbourhood on
    coarse meshes; the sphere map cannot.)

    Returns
    -------
    levels : list of (V, F), coarse to fine; surface : ImplicitSurface
    """
    from .meshing import jitter_tangentially, mesh_sequence
    surfaces = heine_surfaces()
    if label not in surfaces:
        raise ValueError(f"unknown Heine surface {label!r}; use one of {sorted(surfaces)}")
    surface = surfaces[label]
    from .meshing import icosphere
    sph = Sphere(1.0)
    V, F = icosphere(subdivisions)
    V = jitter_tangentially(V, F, sph, amount, seed)
    out = []
    for k, (Vk, Fk) in enumerate(mesh_sequence(V, F, sph, n_levels, pre_refine)):
        if jitter > 0:
            Vk = jitter_tangentially(Vk, Fk, sph, jitter, seed + 1 + k)
        if label == "5.1a":
            Vk = HeineA.from_sphere(Vk)
        elif label == "5.1b":
            Vk = HeineB.from_sphere(Vk)
        elif label == "5.1c":
            Vk = surface.project(Vk * surface.axes)
        out.append((Vk, np.asarray(Fk, dtype=np.int64)))
    return out, surface


# ------------------------------------------------------------ Heine's mesh family (§5)
def _to_surface(label, surface, P):
    """Unit-sphere points onto the Heine surface (as :func:`heine_sequence`)."""
    if label == "5.1a":
        return HeineA.from_sphere(P)
    if label == "5.1b":
        return HeineB.from_sphere(P)
    if label == "5.1c":
        return surface.project(P * surface.axes)
    return P


def _bisect(P, F, marked_edges_of):
    """Newest-vertex bisection with closure on the unit sphere.

    ``F`` (#F, 3): corner 0 is the newest vertex, the refinement edge is (F[:,1], F[:,2]).
    ``marked_edges_of(F)`` → (#F,) bool: faces that must be bisected once.  Neighbours are
    bisected as needed until the mesh is conforming (closure).  A face [a, b, c] with
    midpoint m of bc becomes [m, a, b] and [m, c, a] (orientation kept, refinement edges
    ab and ca).  New vertices are edge midpoints pushed back onto the unit sphere.

    Returns
    -------
    P : (#V', 3), F : (#F', 3) int64
    """
    P = np.asarray(P, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    want = marked_edges_of(F)
    # edges to split: refinement edges of wanted faces, closed under "a split edge of a face
    # forces the split of that face's refinement edge"
    key = lambda a, b: np.minimum(a, b) * (1 << 32) + np.maximum(a, b)   # noqa: E731
    split = np.unique(key(F[want, 1], F[want, 2]))
    while True:                                   # closure: a face holding a split edge splits its own
        E = np.stack([key(F[:, 1], F[:, 2]), key(F[:, 2], F[:, 0]), key(F[:, 0], F[:, 1])], 1)
        hit = np.isin(E, split)
        need = hit.any(1) & ~hit[:, 0]
        if not need.any():
            break
        split = np.union1d(split, E[need, 0])
    mid_keys = np.zeros(0, dtype=np.int64)        # sorted edge keys → midpoint vertex ids
    mid_ids = np.zeros(0, dtype=np.int64)
    while True:                                   # bisect until no face holds a split edge
        E0 = key(F[:, 1], F[:, 2])
        todo = np.isin(E0, split)
        if not todo.any():
            break
        a, b, c = F[todo, 0], F[todo, 1], F[todo, 2]
        uk, first, inv = np.unique(E0[todo], return_index=True, return_inverse=True)
        ids = np.full(len(uk), -1, dtype=np.int64)
        if len(mid_keys):
            pos = np.minimum(np.searchsorted(mid_keys, uk), len(mid_keys) - 1)
            known = mid_keys[pos] == uk
            ids[known] = mid_ids[pos[known]]
        new = ids < 0
        if new.any():
            M = 0.5 * (P[b[first[new]]] + P[c[first[new]]])
            M /= np.linalg.norm(M, axis=1, keepdims=True)
            ids[new] = len(P) + np.arange(new.sum())
            P = np.concatenate([P, M])
            order = np.argsort(np.concatenate([mid_keys, uk[new]]))
            mid_keys = np.concatenate([mid_keys, uk[new]])[order]
            mid_ids = np.concatenate([mid_ids, ids[new]])[order]
        m = ids[inv]
        # a split edge stays in ``split``: a face on its other side still holds it (as its
        # refinement edge once its own refinement edge is split) and reuses the midpoint
        F = np.concatenate([F[~todo], np.stack([m, a, b], 1), np.stack([m, c, a], 1)])
    return P, F


def heine_adaptive_sequence(label, n_levels, degree=2, tolerance=0.005, max_adaptive=40,
                            theta=0.5):
    """Heine's mesh family (§5): adaptive refinement of the icosahedron until the L2 distance
    of the degree-γ surface to the exact one is below ``tolerance`` (0.005 in the paper),
    then ``n_levels - 1`` global refinements "by doubly bisecting the elements".

    Refinement is newest-vertex bisection with closure (:func:`_bisect`, as ALBERT's) built on
    the unit sphere and mapped onto the surface as :func:`heine_sequence`; the adaptive
    steps mark the faces carrying the largest local errors ``∫_T dist(x, Γ)²`` until they hold
    the fraction ``theta`` of the total (Dörfler marking).  The geometric error is measured on
    the degree-``degree`` nodal interpolant (:class:`igl_hhj.curved.LagrangeSurface`); while
    that interpolant folds (too coarse a mesh for the surface), every face is bisected.

    Returns
    -------
    levels : list of (V, F), surface, info : dict (``adaptive_steps``, ``geometric_error`` per level)
    """
    from ..curved import LagrangeSurface
    from .meshing import icosphere
    surfaces = heine_surfaces()
    if label not in surfaces:
        raise ValueError(f"unknown Heine surface {label!r}; use one of {sorted(surfaces)}")
    if not (isinstance(n_levels, (int, np.integer)) and n_levels >= 1):
        raise ValueError(f"n_levels must be an integer >= 1, got {n_levels!r}")
    if not tolerance > 0:
        raise ValueError(f"tolerance must be > 0, got {tolerance!r}")
    surface = surfaces[label]
    P, F = icosphere(0)
    P = P / np.linalg.norm(P, axis=1, keepdims=True)
    F = np.asarray(F, dtype=np.int64)
    # initial refinement edge: the longest edge of each face, moved opposite corner 0
    L = np.stack([np.linalg.norm(P[F[:, (i + 1) % 3]] - P[F[:, (i + 2) % 3]], axis=1) for i in range(3)], 1)
    r = np.argmax(L + 1e-9 * np.arange(3), axis=1)
    F = np.stack([F[np.arange(len(F)), (r + j) % 3] for j in range(3)], 1)

    def geometric(P, F):
        V = _to_surface(label, surface, P)
        try:
            surf = LagrangeSurface.from_projection(V, F, degree, surface.project, interpolant="nodal")
        except ValueError:                        # too coarse: a curved element folds; refine all
            return np.inf, np.ones(len(F))
        faces, bary, w = surf.quadrature()
        X = surf.points(faces, bary)
        d2 = ((X - surface.project(X)) ** 2).sum(1)
        local = np.bincount(faces, weights=w * d2, minlength=len(F))
        return float(np.sqrt(local.sum())), local

    info = {"adaptive_steps": 0, "geometric_error": []}
    err, local = geometric(P, F)
    while err > tolerance and info["adaptive_steps"] < max_adaptive:
        order = np.argsort(local)[::-1]
        k = int(np.searchsorted(np.cumsum(local[order]), theta * local.sum())) + 1
        mark = np.zeros(len(F), dtype=bool)
        mark[order[:k]] = True
        P, F = _bisect(P, F, lambda G, m=mark, n=len(F): np.pad(m, (0, len(G) - n)))
        info["adaptive_steps"] += 1
        err, local = geometric(P, F)
    out = []
    for lev in range(n_levels):
        if lev:
            for _ in range(2):                    # "doubly bisecting the elements"
                P, F = _bisect(P, F, lambda G: np.ones(len(G), dtype=bool))
            err, _ = geometric(P, F)
        info["geometric_error"].append(err)
        out.append((_to_surface(label, surface, P), F.copy()))
    return out, surface, info
