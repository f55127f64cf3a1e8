"""Exact surfaces with analytic normal ν, shape operator ∇_Γν and a projection.

Every surface here is the zero level set of a smooth function ``b`` whose
solid ``{b < 0}`` lies inside, so ``ν = ∇b/|∇b|`` is the *outward* normal and

    ∇_Γν = P (∇²b) P / |∇b|,   P = I - ν ⊗ ν        (on b = 0),

which gives a sphere of radius R the shape operator P/R (principal
curvatures +1/R): the sign convention of Walker (2023) and libigl.
Graphs ``z = h(x, y)`` use ``b = z - h`` (normal pointing up, +z) and project
vertically so that the chart domain is preserved.
"""
from __future__ import annotations

import numpy as np

__all__ = [
    "ImplicitSurface", "GraphSurface", "Sphere", "Ellipsoid", "WalkerTorus",
    "WalkerGenus3", "WalkerSaddle",
]


class ImplicitSurface:
    """Level set ``b(x) = 0`` with exact first and second derivatives.

    Subclasses implement :meth:`value`, :meth:`gradient` and :meth:`hessian`
    for points ``X`` of shape (n, 3).
    """

    name = "implicit"

    def value(self, X):  # pragma: no cover - abstract
        raise NotImplementedError

    def gradient(self, X):  # pragma: no cover - abstract
        raise NotImplementedError

    def hessian(self, X):  # pragma: no cover - abstract
        raise NotImplementedError

    # ------------------------------------------------------------ geometry
    def project(self, X, tol=1e-15, maxiter=60):
        """Map points near the surface onto ``b = 0`` by Newton steps along ∇b.

        ``x ← x - b(x) ∇b(x) / |∇b(x)|²`` (a foot point, not exactly the
        closest point); converges quadratically from within the tubular
        neighbourhood.  Returns a new (n, 3) array."""
        X = np.array(X, dtype=np.float64, copy=True)
        for _ in range(maxiter):
            b = self.value(X)
            g = self.gradient(X)
            g2 = np.einsum("ij,ij->i", g, g)
            step = (b / g2)[:, None] * g
            X -= step
            if np.max(np.abs(b) / np.sqrt(g2)) < tol:
                break
        return X

    def normal(self, X):
        """(n, 3) outward unit normal ν = ∇b / |∇b| at points on the surface."""
        g = self.gradient(X)
        return g / np.linalg.norm(g, axis=1, keepdims=True)

    def shape_operator(self, X):
        """(n, 3, 3) exact shape operator ∇_Γν = P ∇²b P / |∇b| at points on the surface."""
        g = self.gradient(X)
        gn = np.linalg.norm(g, axis=1)
        nu = g / gn[:, None]
        P = np.eye(3)[None] - nu[:, :, None] * nu[:, None, :]
        return P @ self.hessian(X) @ P / gn[:, None, None]

    def principal_curvatures(self, X):
        """(n,), (n,): κ1 ≥ κ2 at points on the surface."""
        H = self.mean_curvature(X)
        K = self.gauss_curvature(X)
        disc = np.sqrt(np.maximum(H ** 2 - K, 0.0))
        return H + disc, H - disc

    def mean_curvature(self, X):
        """(n,) H = (κ1 + κ2)/2."""
        return 0.5 * np.trace(self.shape_operator(X), axis1=1, axis2=2)

    def gauss_curvature(self, X):
        """(n,) K = κ1 κ2 = det(∇_Γν + ν⊗ν)."""
        nu = self.normal(X)
        return np.linalg.det(self.shape_operator(X) + nu[:, :, None] * nu[:, None, :])

    def principal_directions(self, X):
        """(n, 3), (n, 3): unit directions of κ1 and κ2 (tangent to the surface)."""
        S = self.shape_operator(X)
        nu = self.normal(X)
        # shift the normal eigenvalue out of the way (below κ2)
        big = np.abs(S).sum(axis=(1, 2)) + 1.0
        w, U = np.linalg.eigh(S - big[:, None, None] * nu[:, :, None] * nu[:, None, :])
        return U[:, :, 2], U[:, :, 1]


class Sphere(ImplicitSurface):
    """Sphere of radius R centred at the origin: ``b = (|x|² - R²) / (2R)``."""

    def __init__(self, radius=1.0):
        self.R = float(radius)
        self.name = "sphere" if self.R == 1.0 else f"sphere(R={self.R:g})"

    def value(self, X):
        return (np.einsum("ij,ij->i", X, X) - self.R ** 2) / (2 * self.R)

    def gradient(self, X):
        return X / self.R

    def hessian(self, X):
        return np.broadcast_to(np.eye(3) / self.R, (len(X), 3, 3)).copy()

    def project(self, X, tol=1e-15, maxiter=60):
        X = np.asarray(X, dtype=np.float64)
        return self.R * X / np.linalg.norm(X, axis=1, keepdims=True)


class Ellipsoid(ImplicitSurface):
    """Ellipsoid ``(x/a)² + (y/b)² + (z/c)² = 1``; default the paper's
    ``x² + (2y)² + (2z/3)² = 1`` (a, b, c) = (1, 1/2, 3/2) (Heine (5.1c))."""

    def __init__(self, axes=(1.0, 0.5, 1.5)):
        self.axes = np.asarray(axes, dtype=np.float64)
        self.w = 1.0 / self.axes ** 2
        self.name = "ellipsoid"

    def value(self, X):
        return X ** 2 @ self.w - 1.0

    def gradient(self, X):
        return 2.0 * X * self.w

    def hessian(self, X):
        return np.broadcast_to(np.diag(2.0 * self.w), (len(X), 3, 3)).copy()


class WalkerTorus(ImplicitSurface):
    """Walker §6.3: ``(x² + y² - 0.6)² + 1.5 z² - 0.25 = 0``."""

    name = "torus"

    def value(self, X):
        x, y, z = X.T
        return (x * x + y * y - 0.6) ** 2 + 1.5 * z * z - 0.25

    def gradient(self, X):
        x, y, z = X.T
        q = x * x + y * y - 0.6
        return np.stack([4 * x * q, 4 * y * q, 3 * z], axis=1)

    def hessian(self, X):
        x, y, z = X.T
        q = x * x + y * y - 0.6
        H = np.zeros((len(X), 3, 3))
        H[:, 0, 0] = 4 * q + 8 * x * x
        H[:, 1, 1] = 4 * q + 8 * y * y
        H[:, 0, 1] = H[:, 1, 0] = 8 * x * y
        H[:, 2, 2] = 3.0
        return H

    def parametrize(self, t, phi):
        """Points on the torus for angles t (around the tube) and phi (around the axis)."""
        rho = np.sqrt(0.6 + 0.5 * np.cos(t))
        z = np.sqrt(0.25 / 1.5) * np.sin(t)
        return np.stack([rho * np.cos(phi), rho * np.sin(phi), z], axis=-1)


class WalkerGenus3(ImplicitSurface):
    """Walker §6.4 genus-3 surface, ``a0 = 3.25``:

    b = Σ_i (a0 x_i - 2)²(a0 x_i + 2)² + 3 a0⁴ (x²y² + x²z² + y²z²)
        + 6 a0³ xyz - 10 a0² |x|² + 11.5.
    """

    name = "genus3"

    def __init__(self, a0=3.25):
        self.a = float(a0)

    def value(self, X):
        a = self.a
        x, y, z = X.T
        q = ((a * x) ** 2 - 4) ** 2 + ((a * y) ** 2 - 4) ** 2 + ((a * z) ** 2 - 4) ** 2
        return (q + 3 * a ** 4 * (x * x * y * y + x * x * z * z + y * y * z * z)
                + 6 * a ** 3 * x * y * z - 10 * a * a * (x * x + y * y + z * z) + 11.5)

    def gradient(self, X):
        a = self.a
        r2 = np.einsum("ij,ij->i", X, X)[:, None]
        prod = np.stack([X[:, 1] * X[:, 2], X[:, 0] * X[:, 2], X[:, 0] * X[:, 1]], axis=1)
        return (4 * a * a * X * ((a * X) ** 2 - 4) + 6 * a ** 4 * X * (r2 - X ** 2)
                + 6 * a ** 3 * prod - 20 * a * a * X)

    def hessian(self, X):
        a = self.a
        r2 = np.einsum("ij,ij->i", X, X)
        H = 12 * a ** 4 * X[:, :, None] * X[:, None, :]
        for i in range(3):  # 3 diagonal / off-diagonal slots, vectorised over points
            H[:, i, i] = 12 * a ** 4 * X[:, i] ** 2 - 16 * a * a + 6 * a ** 4 * (r2 - X[:, i] ** 2) - 20 * a * a
            j, k = (i + 1) % 3, (i + 2) % 3
            H[:, j, k] += 6 * a ** 3 * X[:, i]
            H[:, k, j] += 6 * a ** 3 * X[:, i]
        return H


class GraphSurface(ImplicitSurface):
    """Graph ``z = h(x, y)`` over a planar domain, as ``b = z - h(x, y)``.

    Subclasses implement ``height(x, y)`` returning h, (h_x, h_y) and
    (h_xx, h_xy, h_yy).  :meth:`project` is vertical (keeps (x, y))."""

    def height(self, x, y):  # pragma: no cover - abstract
        raise NotImplementedError

    def value(self, X):
        h, _, _ = self.height(X[:, 0], X[:, 1])
        return X[:, 2] - h

    def gradient(self, X):
        _, (hx, hy), _ = self.height(X[:, 0], X[:, 1])
        return np.stack([-hx, -hy, np.ones_like(hx)], axis=1)

    def hessian(self, X):
        _, _, (hxx, hxy, hyy) = self.height(X[:, 0], X[:, 1])
        H = np.zeros((len(X), 3, 3))
        H[:, 0, 0] = -hxx
        H[:, 0, 1] = H[:, 1, 0] = -hxy
        H[:, 1, 1] = -hyy
        return H

    def project(self, X, tol=None, maxiter=None):
        X = np.array(X, dtype=np.float64, copy=True)
        X[:, 2] = self.height(X[:, 0], X[:, 1])[0]
        return X

    def lift(self, P):
        """Points (n, 2) of the chart domain → (n, 3) points on the graph."""
        P = np.asarray(P, dtype=np.float64)
        return np.column_stack([P[:, 0], P[:, 1], self.height(P[:, 0], P[:, 1])[0]])


class WalkerSaddle(GraphSurface):
    """Walker §6.1: ``z = 0.5 (sin(3.5(u - 0.5)) + cos(4.2(v - 0.5)))`` on [0, 1]²."""

    name = "saddle"

    def height(self, x, y):
        a, b = 3.5 * (x - 0.5), 4.2 * (y - 0.5)
        h = 0.5 * (np.sin(a) + np.cos(b))
        hx = 0.5 * 3.5 * np.cos(a)
        hy = -0.5 * 4.2 * np.sin(b)
        hxx = -0.5 * 3.5 ** 2 * np.sin(a)
        hyy = -0.5 * 4.2 ** 2 * np.cos(b)
        return h, (hx, hy), (hxx, np.zeros_like(x), hyy)
