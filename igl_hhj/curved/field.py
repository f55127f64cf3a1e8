"""Tensor fields on curved surfaces: evaluation at points, curvatures, per-node values."""
from __future__ import annotations

import numpy as np

from .reference import lagrange_nodes

__all__ = ["CurvedField"]


class CurvedField:
    """A shape-operator field on a :class:`~igl_hhj.curved.LagrangeSurface`.

    ``field(faces, bary) -> (n, 3, 3)``: the approximate shape operator at the
    points with barycentric coordinates ``bary`` (n, 3) of faces ``faces`` (n,).

    kind "hhj": S_h = -Σ_k ν̂^k σ_h^k (Walker eq. 5.12) from HHJ DOFs;
    symmetric and tangential to :meth:`LagrangeSurface.normals`.
    kind "lagrange": a per-node (continuous) tensor field interpolated by the
    degree-γ Lagrange basis (Heine's Π_h); ``field`` returns its symmetric
    tangential part P sym(Π_h) P (P from the curved normal).
    """

    def __init__(self, space, coefficients, kind="hhj", raw=None):
        self.space = space
        self.surface = space.surface
        self.coefficients = coefficients
        self.kind = kind
        self.raw = raw

    def __call__(self, faces, bary):
        faces = np.asarray(faces)
        bary = np.asarray(bary, dtype=np.float64)
        nu = self.surface.normals(faces, bary)
        if self.kind == "hhj":
            sig = self.space.tensors(self.coefficients, faces, bary)      # (n, 3, 3, 3): σ^k
            S = -np.einsum("nk,nkij->nij", nu, sig)
        else:
            Pi = self.space.evaluate(self.coefficients, faces, bary).reshape(-1, 3, 3)
            P = np.eye(3)[None] - nu[:, :, None] * nu[:, None, :]
            S = P @ (0.5 * (Pi + np.swapaxes(Pi, 1, 2))) @ P
        return 0.5 * (S + np.swapaxes(S, 1, 2))

    # -------------------------------------------------------------- derived
    def mean_curvature(self, faces, bary):
        """(n,) H = tr S / 2."""
        return 0.5 * np.trace(self(faces, bary), axis1=1, axis2=2)

    def additive_curvature(self, faces, bary):
        """(n,) κ^a = tr S (Walker eq. 6.1)."""
        return np.trace(self(faces, bary), axis1=1, axis2=2)

    def gaussian_curvature(self, faces, bary):
        """(n,) κ^g = det(S + ν̂ ⊗ ν̂) (Walker eq. 6.1)."""
        nu = self.surface.normals(faces, bary)
        return np.linalg.det(self(faces, bary) + nu[:, :, None] * nu[:, None, :])

    def principal(self, faces, bary):
        """Principal curvatures and directions at points.

        Returns k1 (n,), k2 (n,) with k1 ≥ k2, d1 (n, 3), d2 (n, 3): the two
        tangential eigenpairs of S (the normal eigenvalue is shifted away)."""
        S = self(faces, bary)
        nu = self.surface.normals(faces, bary)
        big = np.abs(S).sum(axis=(1, 2)) + 1.0
        w, U = np.linalg.eigh(S - big[:, None, None] * nu[:, :, None] * nu[:, None, :])
        return w[:, 2], w[:, 1], U[:, :, 2], U[:, :, 1]

    def node_values(self):
        """Per-node values for viewers: the average over the elements containing
        each node of the field at that node.

        Returns dict with ``S`` (#N, 3, 3), ``H``, ``K``, ``k1``, ``k2`` (#N,)."""
        surf = self.surface
        xi = lagrange_nodes(surf.order)
        bary = np.column_stack([1 - xi.sum(1), xi])
        nF, nb = surf.elements.shape
        faces = np.repeat(np.arange(nF), nb)
        B = np.tile(bary, (nF, 1))
        S = self(faces, B)
        nu = surf.normals(faces, B)
        idx = surf.elements.ravel()
        cnt = np.bincount(idx, minlength=surf.n_nodes).astype(float)
        Sn = np.zeros((surf.n_nodes, 9))
        np.add.at(Sn, idx, S.reshape(-1, 9))
        nn = np.zeros((surf.n_nodes, 3))
        np.add.at(nn, idx, nu)
        with np.errstate(invalid="ignore", divide="ignore"):
            Sn = (Sn / cnt[:, None]).reshape(-1, 3, 3)
            nn /= np.linalg.norm(nn, axis=1, keepdims=True)
        H = 0.5 * np.trace(Sn, axis1=1, axis2=2)
        K = np.linalg.det(Sn + nn[:, :, None] * nn[:, None, :])
        disc = np.sqrt(np.maximum(H * H - K, 0.0))
        return {"S": Sn, "H": H, "K": K, "k1": H + disc, "k2": H - disc}
