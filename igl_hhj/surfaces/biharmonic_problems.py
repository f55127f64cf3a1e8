"""Exact biharmonic test problems ``Δ²u = f`` on surfaces, with mesh generators.

The problems of Stein, Grinspun, Jacobson and Wardetzky (2022), §6, plus the
closed case of §5.3 and flat-plate / inhomogeneous checks.  Every problem gives,
at points near its surface (mapped to the surface by :meth:`closest_point`),

* ``u(X)``            the exact solution,
* ``u2(X)``           ``-Δ_Γ u`` (the second unknown of the mixed method),
* ``f(X)``            ``Δ_Γ² u``, in closed form,
* ``grad(X)``         the surface gradient ``∇_Γ u`` (n, 3), for H1 errors,
* ``conormal_derivative(X)`` ``∂u/∂n`` on the boundary (inhomogeneous data),

and a ``meshes(n_levels, ...)`` generator of non-uniform mesh sequences (a
jittered coarse mesh refined uniformly, new vertices projected onto the surface
and new boundary vertices onto the boundary curve), so ``h`` halves per level.

Laplacians in closed form
-------------------------
* unit sphere, u = u(θ) (θ = colatitude): ``Δg = (1/sin θ) ∂θ(sin θ ∂θ g)
  = g'' + cot θ g'`` and, with ``c = cot θ``,
  ``Δ²u = u'''' + 2c u''' - (2 + c²) u'' + c(1 + c²) u'``.
* unit sphere, harmonic homogeneous polynomial ``U_l`` of degree l:
  ``Δ_Γ U_l = -l(l+1) U_l``, ``∇_Γ U_l = ∇U_l - l U_l x``.
* cylinder of radius 1, u = cos φ p(z): ``Δu = cos φ (p'' - p)``,
  ``Δ²u = cos φ (p'''' - 2p'' + p)``.
* flat disk, radial: ``Δ²(1 - r²)² = 64``.
"""
from __future__ import annotations

import numpy as np

from .meshing import refine

__all__ = [
    "BiharmonicProblem", "SphericalCapProblem", "Hemisphere", "SphereHarmonicsProblem",
    "LanternProblem", "DiskPlateProblem", "disk_mesh", "cap_mesh",
    "schwarz_lantern", "lantern_sequence", "biharmonic_errors",
]


# ---------------------------------------------------------------- meshing helpers
def _disk_parameter_mesh(rings=3, amount=0.25, seed=0):
    """Jittered Delaunay mesh of the unit disk: a centre point and rings k = 1..K
    of 6k points at radius k/K (boundary ring exactly on the circle, jittered
    along it).  Counter-clockwise triangles.

    Returns
    -------
    P : (#V, 2) float64, F : (#F, 3) int64
    """
    from scipy.spatial import Delaunay
    if not (isinstance(rings, (int, np.integer)) and rings >= 1):
        raise ValueError(f"rings must be a positive integer, got {rings!r}")
    if not (0.0 <= amount < 0.5):
        raise ValueError(f"amount must be in [0, 0.5), got {amount!r}")
    rng = np.random.default_rng(seed)
    K = int(rings)
    k = np.repeat(np.arange(1, K + 1), 6 * np.arange(1, K + 1))
    i = np.concatenate([np.arange(6 * j) for j in range(1, K + 1)])
    offset = rng.uniform(0, 1, K + 1)[k]
    phi = 2 * np.pi * (i + offset) / (6 * k)
    rho = k / K
    on_b = k == K
    phi = phi + np.where(on_b, amount * 2 * np.pi / (6 * k) * rng.uniform(-1, 1, len(k)), 0.0)
    P = np.column_stack([rho * np.cos(phi), rho * np.sin(phi)])
    d = amount / K * rng.uniform(-1, 1, P.shape)
    P[~on_b] += d[~on_b]
    P = np.vstack([amount / K * rng.uniform(-1, 1, (1, 2)), P])
    F = Delaunay(P).simplices.astype(np.int64)
    X = P[F]
    cross = (X[:, 1, 0] - X[:, 0, 0]) * (X[:, 2, 1] - X[:, 0, 1]) \
        - (X[:, 1, 1] - X[:, 0, 1]) * (X[:, 2, 0] - X[:, 0, 0])
    F[cross < 0] = F[cross < 0][:, [0, 2, 1]]
    return P, F


def disk_mesh(levels=0, rings=3, amount=0.25, seed=0, radius=1.0):
    """Non-uniform mesh of the flat disk ``x² + y² ≤ radius²`` in the plane z = 0.

    A jittered coarse Delaunay mesh (see ``rings``) refined ``levels`` times; new
    boundary vertices are projected onto the circle.  Normals point to +z.

    Returns
    -------
    V : (#V, 3) float64, F : (#F, 3) int64
    """
    P, F = _disk_parameter_mesh(rings, amount, seed)
    V = np.column_stack([radius * P, np.zeros(len(P))])

    def to_circle(X):
        X = X.copy()
        X[:, :2] *= radius / np.linalg.norm(X[:, :2], axis=1, keepdims=True)
        X[:, 2] = 0.0
        return X

    return refine(V, F, lambda X: X, levels, project_boundary=to_circle)


def cap_mesh(theta0=np.pi / 2, levels=0, rings=3, amount=0.25, seed=0):
    """Non-uniform mesh of the spherical cap ``θ ≤ θ0`` of the unit sphere (θ = colatitude).

    The coarse mesh is a jittered Delaunay disk mapped by ``θ = θ0 ρ`` (azimuthal
    equidistant chart), vertices on the sphere; refinement projects new
    interior vertices radially onto the sphere and new boundary vertices onto
    the circle ``θ = θ0`` (boundary edges stay straight chords, Stein et al. 2022 §6.1).
    Outward normals.

    Returns
    -------
    V : (#V, 3) float64, F : (#F, 3) int64
    """
    if not (0 < theta0 < np.pi):
        raise ValueError(f"theta0 must be in (0, pi), got {theta0!r}")
    P, F = _disk_parameter_mesh(rings, amount, seed)
    rho = np.linalg.norm(P, axis=1)
    phi = np.arctan2(P[:, 1], P[:, 0])
    th = theta0 * rho
    V = np.column_stack([np.sin(th) * np.cos(phi), np.sin(th) * np.sin(phi), np.cos(th)])

    def to_sphere(X):
        return X / np.linalg.norm(X, axis=1, keepdims=True)

    def to_circle(X):
        r = np.linalg.norm(X[:, :2], axis=1, keepdims=True)
        return np.column_stack([np.sin(theta0) * X[:, :2] / r,
                                np.full(len(X), np.cos(theta0))])

    return refine(V, F, to_sphere, levels, project_boundary=to_circle)


LANTERN_PERTURBATIONS = ("cube", "normal")


def schwarz_lantern(m, n, perturbation=0.0, seed=0, radius=1.0, height=1.0, mode="cube"):
    """Schwarz lantern: ``n`` rings of ``m`` vertices on the cylinder
    ``x² + y² = radius²``, ``z ∈ [0, height]``, each ring rotated by half a step
    against the previous one, 2m(n-1) triangles, outward normals.

    Parameters
    ----------
    m : int ≥ 3
        Vertices around the axis (on every ring).
    n : int ≥ 2
        Vertices along the axis (rings).
    perturbation : float
        Size ``c`` of the perturbation ``c · ℓ̄²`` with ``ℓ̄`` the mean edge length
        (Stein et al. 2022, Fig. 4: "perturbed on the order of (mean edge length)²");
        boundary rings stay in their planes.
    seed : int
        Seed of the perturbation.
    mode : {"cube", "normal"}
        ``"cube"``: every vertex moves by ``c ℓ̄² ξ``, ``ξ`` uniform in [-1, 1]³;
        ``"normal"``: every vertex moves along the cylinder's normal (radially) by
        ``± c ℓ̄²``, random signs (the whole perturbation off the surface, none within).

    Returns
    -------
    V : (m n, 3) float64, F : (2 m (n-1), 3) int64
    """
    for name, val, lo in (("m", m, 3), ("n", n, 2)):
        if not (isinstance(val, (int, np.integer)) and val >= lo):
            raise ValueError(f"{name} must be an integer >= {lo}, got {val!r}")
    if mode not in LANTERN_PERTURBATIONS:
        raise ValueError(f"mode must be one of {LANTERN_PERTURBATIONS}, got {mode!r}")
    m, n = int(m), int(n)
    j, i = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    phi = 2 * np.pi * (i + 0.5 * j) / m
    z = height * j / (n - 1)
    V = np.column_stack([radius * np.cos(phi).ravel(), radius * np.sin(phi).ravel(), z.ravel()])
    jj, ii = np.meshgrid(np.arange(n - 1), np.arange(m), indexing="ij")
    jj, ii = jj.ravel(), ii.ravel()
    v = lambda a, b: a * m + (b % m)  # noqa: E731
    T1 = np.stack([v(jj, ii), v(jj, ii + 1), v(jj + 1, ii)], axis=1)
    T2 = np.stack([v(jj, ii + 1), v(jj + 1, ii + 1), v(jj + 1, ii)], axis=1)
    F = np.concatenate([T1, T2]).astype(np.int64)
    X = V[F]
    nrm = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    c = X.mean(axis=1)
    out = nrm[:, 0] * c[:, 0] + nrm[:, 1] * c[:, 1] > 0
    F[~out] = F[~out][:, [0, 2, 1]]
    if perturbation:
        E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
        E = np.unique(np.sort(E, axis=1), axis=0)
        lbar = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1).mean()
        rng = np.random.default_rng(seed)
        if mode == "cube":
            d = perturbation * lbar ** 2 * rng.uniform(-1, 1, V.shape)
        else:
            r = np.hypot(V[:, 0], V[:, 1])[:, None]
            radial = np.column_stack([V[:, :2] / r, np.zeros(len(V))])
            d = perturbation * lbar ** 2 * rng.choice([-1.0, 1.0], len(V))[:, None] * radial
        d[(j.ravel() == 0) | (j.ravel() == n - 1), 2] = 0.0
        V = V + d
    return V, F


def lantern_sequence(regime="m~n", n_levels=4, perturbation=1.0, seed=0, base=2, mode="cube"):
    """Schwarz-lantern sequences with ``h`` roughly halving per level.

    Parameters
    ----------
    regime : {"m~n", "m~n^2", "n~m^2"}
        ``"m~n"``: m = 6·base·2^k around, n = base·2^k + 1 along the axis
        (shape regular); ``"m~n^2"``: n - 1 = base·2^k, m = 3 (n - 1)² (needles:
        base 2π/m ≪ height); ``"n~m^2"``: m = 2·base·2^k, n - 1 = m²/2 (flat,
        obtuse triangles whose normals do not converge; the surface area of the
        lantern does not converge, Morvan 2008 §3.1.3).

    mode : {"cube", "normal"}
        Direction of the perturbation (:func:`schwarz_lantern`).

    Returns
    -------
    list of (V, F, m, n)
    """
    out = []
    for k in range(n_levels):
        s = base * 2 ** k
        if regime == "m~n":
            m, n = 6 * s, s + 1
        elif regime == "m~n^2":
            m, n = 3 * s * s, s + 1
        elif regime == "n~m^2":
            m = 2 * s
            n = m * m // 2 + 1
        else:
            raise ValueError(f"regime must be 'm~n', 'm~n^2' or 'n~m^2', got {regime!r}")
        V, F = schwarz_lantern(m, n, perturbation=perturbation, seed=seed + k, mode=mode)
        out.append((V, F, m, n))
    return out


# ---------------------------------------------------------------- problems
class BiharmonicProblem:
    """Base class: exact ``u``, ``u2 = -Δu``, ``f = Δ²u``, ``∇_Γ u``, boundary data.

    Subclasses set ``name``, ``bc`` and implement :meth:`closest_point`,
    :meth:`u`, :meth:`u2`, :meth:`f`, :meth:`grad`, :meth:`meshes`.
    """

    name = "problem"
    bc = "clamped"

    def closest_point(self, X):  # pragma: no cover - abstract
        raise NotImplementedError

    def u(self, X):  # pragma: no cover - abstract
        raise NotImplementedError

    def u2(self, X):  # pragma: no cover - abstract
        raise NotImplementedError

    def f(self, X):  # pragma: no cover - abstract
        raise NotImplementedError

    def grad(self, X):  # pragma: no cover - abstract
        raise NotImplementedError

    def conormal(self, X):  # pragma: no cover - abstract
        """(n, 3) outward unit conormal of the smooth boundary at boundary points."""
        raise NotImplementedError

    def conormal_derivative(self, X):
        """(n,) ``∂u/∂n = ∇_Γ u · n`` at (boundary) points."""
        return np.einsum("ij,ij->i", self.grad(X), self.conormal(X))

    def meshes(self, n_levels, **kw):  # pragma: no cover - abstract
        raise NotImplementedError


def _sph(X):
    """θ (colatitude), φ and the unit vectors e_θ, e_φ of the closest sphere point."""
    P = X / np.linalg.norm(X, axis=1, keepdims=True)
    rxy = np.hypot(P[:, 0], P[:, 1])
    th = np.arctan2(rxy, P[:, 2])
    ph = np.arctan2(P[:, 1], P[:, 0])
    e_th = np.column_stack([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), -np.sin(th)])
    e_ph = np.column_stack([-np.sin(ph), np.cos(ph), np.zeros_like(ph)])
    return th, ph, e_th, e_ph


class SphericalCapProblem(BiharmonicProblem):
    """Clamped cap ``θ ≤ θ0`` of the unit sphere, ``u = (θ0 - θ)² θ⁵`` (Stein et al. 2022, §6.1).

    ``u = ∂u/∂n = 0`` at θ = θ0 (double root).  θ0 = π/2 is the hemisphere of
    Fig. 2, θ0 = π/4 the cap of Fig. 3.
    """

    bc = "clamped"

    def __init__(self, theta0=np.pi / 4):
        if not (0 < theta0 <= np.pi / 2):
            raise ValueError(f"theta0 must be in (0, pi/2], got {theta0!r}")
        self.theta0 = float(theta0)
        self.name = "hemisphere" if np.isclose(theta0, np.pi / 2) else f"cap θ≤{theta0:.4g}"
        P = np.polynomial.Polynomial
        self._d = [P([0, 0, 0, 0, 0, theta0 ** 2, -2 * theta0, 1.0])]   # (θ0-θ)²θ⁵
        for _ in range(4):
            self._d.append(self._d[-1].deriv())

    def closest_point(self, X):
        return X / np.linalg.norm(X, axis=1, keepdims=True)

    def _theta(self, X):
        return _sph(X)[0]

    def u(self, X):
        return self._d[0](self._theta(X))

    def _cot(self, th):
        small = th < 1e-8
        ts = np.where(small, 1.0, th)
        return small, 1.0 / np.tan(ts)

    def u2(self, X):
        """-Δu = -(u'' + cot θ u'); → 0 at the pole."""
        th = self._theta(X)
        small, c = self._cot(th)
        val = -(self._d[2](th) + c * self._d[1](th))
        return np.where(small, 0.0, val)

    def f(self, X):
        """Δ²u = u'''' + 2 cot θ u''' - (2 + cot²θ) u'' + cot θ (1 + cot²θ) u'; → 0 at the pole."""
        th = self._theta(X)
        small, c = self._cot(th)
        d = [p(th) for p in self._d]
        val = d[4] + 2 * c * d[3] - (2 + c * c) * d[2] + c * (1 + c * c) * d[1]
        return np.where(small, 0.0, val)

    def grad(self, X):
        th, _, e_th, _ = _sph(X)
        return self._d[1](th)[:, None] * e_th

    def conormal(self, X):
        return _sph(X)[2]

    def meshes(self, n_levels, rings=3, amount=0.25, seed=0, pre_refine=1):
        """[(V_k, F_k)]: :func:`cap_mesh` with ``pre_refine + k`` refinements."""
        return [cap_mesh(self.theta0, pre_refine + k, rings, amount, seed) for k in range(n_levels)]


def Hemisphere():
    """Stein et al. 2022, Fig. 2: clamped hemisphere, ``u = (π/2 - θ)² θ⁵``."""
    return SphericalCapProblem(np.pi / 2)


# harmonic homogeneous polynomials U_l on R³: (degree l, U, ∇U)
_HARMONICS = {
    "z": (1, lambda x, y, z: z, lambda x, y, z: np.stack([0 * x, 0 * x, 1 + 0 * x], 1)),
    "x2-y2": (2, lambda x, y, z: x * x - y * y, lambda x, y, z: np.stack([2 * x, -2 * y, 0 * z], 1)),
    "xz": (2, lambda x, y, z: x * z, lambda x, y, z: np.stack([z, 0 * y, x], 1)),
    "xyz": (3, lambda x, y, z: x * y * z, lambda x, y, z: np.stack([y * z, x * z, x * y], 1)),
    "x4": (4, lambda x, y, z: x ** 4 - 6 * x * x * y * y + y ** 4,
           lambda x, y, z: np.stack([4 * x ** 3 - 12 * x * y * y, 4 * y ** 3 - 12 * x * x * y, 0 * z], 1)),
}


class SphereHarmonicsProblem(BiharmonicProblem):
    """``u = Σ c_l U_l`` (harmonic homogeneous polynomials restricted to the unit sphere).

    ``-Δ_Γ u = Σ c_l l(l+1) U_l``, ``f = Σ c_l l²(l+1)² U_l``; with degrees ≥ 1
    ``u`` and ``f`` have zero mean.  ``bc="closed"``: the whole sphere (paper
    001 §5.3, rate h²); ``bc="clamped"``: the northern hemisphere with the
    inhomogeneous data ``g = u``, ``q = ∂u/∂n`` (``n = e_θ`` on the equator).
    """

    def __init__(self, terms=(("z", 0.5), ("x2-y2", 1.0), ("xyz", 2.0), ("x4", 0.25)), bc="closed"):
        if bc not in ("closed", "clamped"):
            raise ValueError(f"bc must be 'closed' or 'clamped', got {bc!r}")
        for key, _ in terms:
            if key not in _HARMONICS:
                raise ValueError(f"unknown harmonic {key!r}; choose from {sorted(_HARMONICS)}")
        self.terms = tuple(terms)
        self.bc = bc
        self.name = "sphere (closed)" if bc == "closed" else "hemisphere, inhomogeneous"

    def closest_point(self, X):
        return X / np.linalg.norm(X, axis=1, keepdims=True)

    def _sum(self, X, weight):
        P = self.closest_point(X)
        x, y, z = P.T
        return sum(c * weight(_HARMONICS[k][0]) * _HARMONICS[k][1](x, y, z) for k, c in self.terms)

    def u(self, X):
        return self._sum(X, lambda l: 1.0)

    def u2(self, X):
        return self._sum(X, lambda l: l * (l + 1.0))

    def f(self, X):
        return self._sum(X, lambda l: (l * (l + 1.0)) ** 2)

    def grad(self, X):
        P = self.closest_point(X)
        x, y, z = P.T
        G = np.zeros_like(P)
        for k, c in self.terms:
            deg, U, dU = _HARMONICS[k]
            G += c * (dU(x, y, z) - deg * U(x, y, z)[:, None] * P)
        return G

    def conormal(self, X):
        return _sph(X)[2]

    def meshes(self, n_levels, amount=0.25, seed=0, pre_refine=1, rings=3):
        """Closed: jittered icosphere refined with projection; clamped: hemisphere :func:`cap_mesh`."""
        if self.bc == "clamped":
            return [cap_mesh(np.pi / 2, pre_refine + k, rings, amount, seed) for k in range(n_levels)]
        from .exact import Sphere
        from .meshing import icosphere, jitter_tangentially, mesh_sequence
        S = Sphere(1.0)
        V0, F0 = icosphere(1)
        V0 = jitter_tangentially(V0, F0, S, amount, seed)
        return mesh_sequence(V0, F0, S, n_levels, pre_refine)


class LanternProblem(BiharmonicProblem):
    """Cylinder of radius 1, z ∈ [0, 1], ``u = cos φ p(z)`` (Stein et al. 2022, §6.2).

    ``profile="clamped"``: ``p = sin(πz) z(1 - z)`` (u = ∂u/∂n = 0 at z = 0, 1; the
    paper's case); ``profile="navier"``: ``p = sin(πz)`` (u = Δu = 0 at z = 0, 1).
    """

    def __init__(self, profile="clamped"):
        if profile not in ("clamped", "navier"):
            raise ValueError(f"profile must be 'clamped' or 'navier', got {profile!r}")
        self.bc = profile
        self.name = f"Schwarz lantern ({profile})"
        P = np.polynomial.Polynomial
        self._q = P([0.0, 1.0, -1.0]) if profile == "clamped" else P([1.0])

    def closest_point(self, X):
        r = np.hypot(X[:, 0], X[:, 1])
        return np.column_stack([X[:, 0] / r, X[:, 1] / r, X[:, 2]])

    def _p(self, z, k):
        """k-th derivative of p = sin(πz) q(z), by Leibniz."""
        from math import comb
        out = np.zeros_like(z)
        for j in range(k + 1):
            s = np.pi ** j * np.sin(np.pi * z + j * np.pi / 2)   # (sin πz)^(j)
            out += comb(k, j) * s * self._q.deriv(k - j)(z) if k - j > 0 else comb(k, j) * s * self._q(z)
        return out

    def _phi_z(self, X):
        return np.arctan2(X[:, 1], X[:, 0]), X[:, 2]

    def u(self, X):
        ph, z = self._phi_z(X)
        return np.cos(ph) * self._p(z, 0)

    def u2(self, X):
        ph, z = self._phi_z(X)
        return np.cos(ph) * (self._p(z, 0) - self._p(z, 2))

    def f(self, X):
        ph, z = self._phi_z(X)
        return np.cos(ph) * (self._p(z, 4) - 2 * self._p(z, 2) + self._p(z, 0))

    def grad(self, X):
        ph, z = self._phi_z(X)
        e_ph = np.column_stack([-np.sin(ph), np.cos(ph), np.zeros_like(ph)])
        g = -np.sin(ph)[:, None] * self._p(z, 0)[:, None] * e_ph
        g[:, 2] += np.cos(ph) * self._p(z, 1)
        return g

    def conormal(self, X):
        z = X[:, 2]
        n = np.zeros_like(X)
        n[:, 2] = np.where(z < 0.5, -1.0, 1.0)
        return n

    def meshes(self, n_levels, regime="m~n", perturbation=1.0, seed=0, base=2, mode="cube"):
        """[(V_k, F_k)] from :func:`lantern_sequence`."""
        return [(V, F) for V, F, _, _ in lantern_sequence(regime, n_levels, perturbation, seed, base, mode)]


class DiskPlateProblem(BiharmonicProblem):
    """Flat unit disk, ``f = 64``: clamped plate ``u = (1 - r²)²`` or, with
    ``bc="navier"``, the simply supported plate ``u = (1 - r²)(3 - r²)``."""

    def __init__(self, bc="clamped"):
        if bc not in ("clamped", "navier"):
            raise ValueError(f"bc must be 'clamped' or 'navier', got {bc!r}")
        self.bc = bc
        self.name = f"flat disk ({bc})"

    def closest_point(self, X):
        P = np.array(X, dtype=np.float64)
        P[:, 2] = 0.0
        return P

    def _r2(self, X):
        return X[:, 0] ** 2 + X[:, 1] ** 2

    def u(self, X):
        r2 = self._r2(X)
        return (1 - r2) ** 2 if self.bc == "clamped" else (1 - r2) * (3 - r2)

    def u2(self, X):
        r2 = self._r2(X)
        return 8 - 16 * r2 if self.bc == "clamped" else 16 - 16 * r2

    def f(self, X):
        return np.full(len(X), 64.0)

    def grad(self, X):
        r2 = self._r2(X)
        s = -4 * (1 - r2) if self.bc == "clamped" else 4 * r2 - 8
        return np.column_stack([s * X[:, 0], s * X[:, 1], np.zeros(len(X))])

    def conormal(self, X):
        P = self.closest_point(X)
        return P / np.linalg.norm(P, axis=1, keepdims=True)

    def meshes(self, n_levels, rings=3, amount=0.25, seed=0, pre_refine=1):
        """[(V_k, F_k)]: :func:`disk_mesh` with ``pre_refine + k`` refinements."""
        return [disk_mesh(pre_refine + k, rings, amount, seed) for k in range(n_levels)]


# ---------------------------------------------------------------- errors
def biharmonic_errors(V, F, u1, u2, problem):
    """Errors of a mixed solution against the exact one (Stein et al. 2022, §6).

    As in the paper, the exact solution is interpolated at the vertices
    (``I_h u``) and compared in the finite-element norms of the mesh:
    ``‖e‖_L2² = eᵀ M e`` (consistent P1 mass), ``|e|_H1² = eᵀ K e``.
    ``u1_H1_grad`` instead compares ``∇_h u1`` with the exact surface gradient
    ``P_T ∇_Γ u(Ψ(x))`` (edge-midpoint quadrature, exact for quadratics).

    Returns
    -------
    dict with ``h`` (longest edge), ``n_vertices``, ``u1_L2``, ``u1_H1``,
    ``u1_H1_grad``, ``u2_L2``, ``u2_H1`` (``|u2 - I_h u2|_H1``, no convergence expected:
    Stein et al. 2022 §6.1), ``u1_L2_rel`` (``‖e‖ / ‖I_h u‖``), ``u2_L2_rel``.
    """
    from ..mesh import as_mesh
    mesh = as_mesh(V, F)
    from ..biharmonic import mass_matrix, stiffness_matrix
    K = stiffness_matrix(mesh)
    M = mass_matrix(mesh, "full")
    ok = mesh.referenced_vertices
    U = np.where(ok, problem.u(mesh.V), 0.0)
    U2 = np.where(ok, problem.u2(mesh.V), 0.0)
    e1 = np.where(ok, u1 - U, 0.0)
    e2 = np.where(ok, u2 - U2, 0.0)
    nrm = lambda A, x: float(np.sqrt(max(x @ (A @ x), 0.0)))  # noqa: E731
    # exact-gradient H1 error
    G = mesh.barycentric_gradients                             # (#F, 3, 3)
    gh = np.einsum("fi,fik->fk", np.where(ok, u1, 0.0)[mesh.F], G)
    X = mesh.V[mesh.F]
    mids = 0.5 * (X[:, [1, 2, 0]] + X[:, [2, 0, 1]])            # (#F, 3, 3)
    P = problem.closest_point(mids.reshape(-1, 3))
    ge = problem.grad(P).reshape(-1, 3, 3)
    nu = mesh.face_normals[:, None, :]
    ge = ge - np.einsum("fqk,fqk->fq", ge, np.broadcast_to(nu, ge.shape))[:, :, None] * nu
    d2 = ((gh[:, None, :] - ge) ** 2).sum(axis=2).mean(axis=1)
    return {
        "h": mesh.max_edge_length,
        "n_vertices": int(ok.sum()),
        "u1_L2": nrm(M, e1),
        "u1_H1": nrm(K, e1),
        "u1_H1_grad": float(np.sqrt(np.sum(mesh.face_areas * d2))),
        "u2_L2": nrm(M, e2),
        "u2_H1": nrm(K, e2),
        "u1_L2_rel": nrm(M, e1) / max(nrm(M, U), 1e-300),
        "u2_L2_rel": nrm(M, e2) / max(nrm(M, U2), 1e-300),
    }
