"""An exact surface with creases: the closed cylinder with flat caps.

``x² + y² = R², |z| ≤ L/2`` plus the two discs ``|z| = L/2, x² + y² ≤ R²``.  With
outward normals the side has κ1 = 1/R, κ2 = 0, H = 1/(2R); the caps are flat; the two
rims are convex creases of dihedral angle π/2, so ``∫_crease θ ds = 2 · (π/2) · 2πR``.

:func:`capped_cylinder` gives a non-uniform mesh sequence: a jittered coarse mesh
(the caps are the jittered Delaunay discs of
:func:`igl_hhj.surfaces.biharmonic_problems.disk_mesh`, the side a jittered grid whose
top and bottom rows are the caps' rims) refined uniformly 1 → 4 with every new vertex
of a side edge projected radially onto the cylinder (midpoints of cap edges stay in the
cap plane; midpoints of rim edges go to the rim circle).
"""
from __future__ import annotations

import numpy as np

__all__ = ["capped_cylinder", "CappedCylinder", "half_ellipsoid", "HalfEllipsoid"]


class CappedCylinder:
    """The exact capped cylinder of radius ``radius`` and height ``height`` (centred at 0)."""

    def __init__(self, radius=1.0, height=1.5):
        self.radius = float(radius)
        self.height = float(height)

    @property
    def crease_integral(self):
        """∫_crease θ ds = 2 rims × (π/2) × 2πR."""
        return 2 * (np.pi / 2) * 2 * np.pi * self.radius

    def side_mean_curvature(self):
        """H on the side, 1/(2R) (outward normals)."""
        return 0.5 / self.radius

    def mean_curvature_of_faces(self, face_normals):
        """(#F,) exact H of the patch a face lies on: 0 on caps (|ν_z| > 1/2), 1/(2R) on the side."""
        return np.where(np.abs(face_normals[:, 2]) > 0.5, 0.0, self.side_mean_curvature())


def _subdivide(V, F, on_side, R):
    """One 1 → 4 midpoint subdivision; midpoints of edges with both ends on the cylinder
    (side and rim edges) are projected radially onto it.  Old vertices keep their index."""
    nV = len(V)
    H = np.concatenate([F[:, [1, 2]], F[:, [2, 0]], F[:, [0, 1]]])     # half-edge opposite corner k
    uE, inv = np.unique(np.sort(H, axis=1), axis=0, return_inverse=True)
    inv = inv.ravel()
    M = 0.5 * (V[uE[:, 0]] + V[uE[:, 1]])
    side = on_side[uE[:, 0]] & on_side[uE[:, 1]]
    M[side, :2] *= R / np.linalg.norm(M[side, :2], axis=1, keepdims=True)
    m = (nV + inv).reshape(3, len(F)).T                                # m[:, k] midpoint opposite k
    F2 = np.concatenate([
        np.column_stack([F[:, 0], m[:, 2], m[:, 1]]),
        np.column_stack([F[:, 1], m[:, 0], m[:, 2]]),
        np.column_stack([F[:, 2], m[:, 1], m[:, 0]]),
        m,
    ])
    return np.vstack([V, M]), F2, np.concatenate([on_side, side])


def capped_cylinder(levels=0, rings=3, amount=0.25, seed=0, radius=1.0, height=1.5):
    """Non-uniform closed mesh of the capped cylinder (:class:`CappedCylinder`), outward normals.

    Parameters
    ----------
    levels : int, uniform refinements of the coarse mesh (h halves per level).
    rings : int, rings of the coarse cap discs (6·rings vertices around).
    amount : float in [0, 0.5), jitter relative to the local spacing.
    seed : int

    Returns
    -------
    V : (#V, 3) float64, F : (#F, 3) int64, on_side : (#V,) bool (vertices on the cylinder,
        rims included)
    """
    from .biharmonic_problems import _disk_parameter_mesh
    R, L = float(radius), float(height)
    rng = np.random.default_rng(seed)
    n = 6 * rings
    caps = []
    for k, z in enumerate((-0.5 * L, 0.5 * L)):
        P, Fd = _disk_parameter_mesh(rings, amount, seed + 1 + k)
        Vd = np.column_stack([R * P, np.full(len(P), z)])
        rim = np.arange(len(P) - n, len(P))                            # the boundary ring, by angle
        if z < 0:
            Fd = Fd[:, [0, 2, 1]]                                      # bottom cap: normal -z
        caps.append((Vd, Fd, rim))
    m = max(2, int(round(L * n / (2 * np.pi * R))))                    # side rows
    rows = []
    for j in range(1, m):
        phi = 2 * np.pi * (np.arange(n) + rng.uniform(0, 1)) / n \
            + amount * 2 * np.pi / n * rng.uniform(-1, 1, n)
        z = -0.5 * L + (j + amount * rng.uniform(-1, 1, n)) * L / m
        rows.append(np.column_stack([R * np.cos(phi), R * np.sin(phi), z]))
    (Vb, Fb, rb), (Vt, Ft, rt) = caps
    off_t = len(Vb)
    off_s = off_t + len(Vt)
    V = np.vstack([Vb, Vt] + rows)
    ring_index = [rb] + [off_s + (j - 1) * n + np.arange(n) for j in range(1, m)] + [off_t + rt]
    quads = []
    for lo, hi in zip(ring_index[:-1], ring_index[1:]):
        a, b = lo, np.roll(lo, -1)
        c, d = np.roll(hi, -1), hi
        quads.append(np.column_stack([a, b, c]))
        quads.append(np.column_stack([a, c, d]))
    F = np.vstack([Fb, Ft + off_t] + quads).astype(np.int64)
    on_side = np.zeros(len(V), dtype=bool)
    on_side[np.concatenate(ring_index)] = True
    for _ in range(levels):
        V, F, on_side = _subdivide(V, F, on_side, R)
    return V, F, on_side


class HalfEllipsoid:
    """The upper half ``z ≥ 0`` of the ellipsoid ``(x/a)² + (y/b)² + (z/c)² = 1`` closed by
    the flat ellipse ``z = 0``: a closed surface whose curved part has varying curvature,
    with one convex crease, the rim ellipse, of dihedral angle π/2 everywhere (the
    ellipsoid's normal is horizontal at z = 0)."""

    def __init__(self, axes=(1.0, 0.7, 0.8)):
        from .exact import Ellipsoid
        self.ellipsoid = Ellipsoid(axes)
        self.axes = self.ellipsoid.axes

    @property
    def crease_integral(self):
        """∫_crease θ ds = (π/2) × the ellipse's perimeter (numerical quadrature)."""
        a, b = self.axes[:2]
        t = np.linspace(0.0, 2 * np.pi, 200001)
        speed = np.hypot(a * np.sin(t), b * np.cos(t))
        return 0.5 * np.pi * float(np.sum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t)))

    def mean_curvature_of_faces(self, face_normals, face_centres):
        """(#F,) exact H of the patch a face lies on, at the face's centre projected onto it:
        0 on the flat bottom (ν_z < -1/2), the ellipsoid's H elsewhere."""
        X = self.ellipsoid.project(face_centres)
        return np.where(face_normals[:, 2] < -0.5, 0.0, self.ellipsoid.mean_curvature(X))

    def mean_curvature_at(self, X, on_bottom):
        """(n,) exact H at points ``X`` of the surface: 0 where ``on_bottom``."""
        return np.where(on_bottom, 0.0, self.ellipsoid.mean_curvature(X))


def half_ellipsoid(levels=0, rings=3, amount=0.25, seed=0, axes=(1.0, 0.7, 0.8)):
    """Non-uniform closed mesh of :class:`HalfEllipsoid`, outward normals.

    One jittered Delaunay disc (:func:`igl_hhj.surfaces.biharmonic_problems.disk_mesh`,
    ``levels`` refinements, boundary on the circle) mapped twice: onto the dome by
    ``(r, φ) ↦ (a sin θ cos φ, b sin θ sin φ, c cos θ)``, θ = πr/2, and onto the bottom by
    ``(r, φ) ↦ (a r cos φ, b r sin φ, 0)``; the two rims coincide and are shared.

    Returns
    -------
    V : (#V, 3) float64, F : (#F, 3) int64, on_bottom : (#V,) bool (bottom vertices, rim included)
    """
    from .biharmonic_problems import disk_mesh
    from .meshing import boundary_vertex_mask
    a, b, c = (float(x) for x in axes)
    P, Fd = disk_mesh(levels, rings, amount, seed)
    r = np.minimum(np.hypot(P[:, 0], P[:, 1]), 1.0)
    phi = np.arctan2(P[:, 1], P[:, 0])
    rim = boundary_vertex_mask(Fd, len(P))
    r[rim] = 1.0
    th = 0.5 * np.pi * r
    top = np.column_stack([a * np.sin(th) * np.cos(phi), b * np.sin(th) * np.sin(phi), c * np.cos(th)])
    top[rim, 2] = 0.0
    inner = np.flatnonzero(~rim)
    bottom = np.column_stack([a * r[inner] * np.cos(phi[inner]), b * r[inner] * np.sin(phi[inner]),
                              np.zeros(len(inner))])
    index = np.arange(len(P))
    index[inner] = len(P) + np.arange(len(inner))
    V = np.vstack([top, bottom])
    F = np.vstack([Fd, index[Fd][:, ::-1]]).astype(np.int64)      # the bottom faces down
    on_bottom = np.zeros(len(V), dtype=bool)
    on_bottom[len(P):] = True
    on_bottom[np.flatnonzero(rim)] = True
    return V, F, on_bottom
