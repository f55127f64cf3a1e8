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

__all__ = ["HeineA", "HeineB", "heine_surfaces", "heine_coarse", "heine_sequence"]


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
