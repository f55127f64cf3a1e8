"""Degree-0 Regge metrics: a triangle mesh's squared edge lengths.

The lowest-order Regge space ``Reg_h^0`` is spanned by one DOF per edge,
``g(t, t) = ℓ_E²``: a triangle mesh — embedded ``(V, F)`` or purely intrinsic
(edge lengths and connectivity, no coordinates) — *is* a degree-0 Regge
metric.  The metric is constant on each triangle, so the element Gauss
curvature and the geodesic curvature of the (straight, hence geodesic) edges
vanish, and the distributional densitized Gauss curvature (Gopalakrishnan et al. 2024,
eq. 2.5) reduces to the angle deficits ``Θ_V = 2π - Σ_T θ_V^T``.  Its P1 lifting
(Definition 2.3 with ``k = 0``, lifting degree 1) solves ``M K_h = Θ``.

Conventions
-----------
* ``l_sq`` per face corner is gpytoolbox's ``(#F, 3)`` layout: ``l_sq[f, i]`` is
  the squared length of the edge *opposite* corner ``i`` (from ``F[f, i+1]`` to
  ``F[f, i+2]``), the same order as ``igl.edge_lengths``.
* ``l_sq`` per unique edge is ``(#E,)`` in the order of ``uE`` returned by
  ``igl.unique_edge_map(F)`` (also :attr:`igl_hhj.mesh.TriangleMesh.edges`).
* Boundary treatment (``boundary=``), per boundary vertex ``V``:
  ``"natural"`` (default) load ``0``: the Neumann data of Definition 2.3 is the
  boundary's own discrete geodesic curvature ``π - Σθ``, so only interior
  sources are lifted (no exact metric is known on a mesh);
  ``"geodesic"`` load ``π - Σθ``: Neumann data of a geodesic boundary
  (``κ̄ = 0``, ``ā_V = π``), total curvature ``2πχ``;
  ``"defect"`` load ``2π - Σθ``: eq. (2.5) without Neumann data, i.e.
  ``igl.gaussian_curvature``.  On closed meshes all three coincide.
* ``mass="consistent"`` (default, ``igl.massmatrix`` FULL: ``|T|/12 (1 + δ_ij)``)
  or ``"lumped"`` (barycentric, ``|T|/3``; then ``K_h = Θ / (A/3)``).
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..mesh import _as_array, as_mesh, validate_faces

__all__ = ["gauss_curvature", "gauss_curvature_intrinsic", "squared_edge_lengths",
           "intrinsic_angles", "intrinsic_areas", "angle_defect", "intrinsic_mass_matrix"]

TWO_PI = 2.0 * np.pi
MAX_INDEX_SLACK = 16
"""``gauss_curvature_intrinsic`` sizes K by ``F.max() + 1``; more than this many indices
per face corner (beyond 65 536) is refused instead of allocating."""
_BOUNDARY = ("natural", "geodesic", "defect")
_MASS = ("consistent", "lumped")


def squared_edge_lengths(V, F):
    """Regge DOFs of an embedded mesh: squared lengths per unique edge.

    Returns
    -------
    l_sq : (#E,) float64, ordered as ``uE``
    uE : (#E, 2) int64, ``igl.unique_edge_map(F)[1]``
    """
    m = as_mesh(V, F)
    return m.unique_edge_lengths ** 2, m.edges.astype(np.int64)     # a copy: mesh.edges is int32


def _topology(F, nV=None):
    import igl
    F = _as_array(F, "F")
    if F.ndim == 2 and F.shape[1] == 3 and F.size and np.issubdtype(F.dtype, np.integer):
        n = int(F.max()) + 1 if nV is None else nV
    else:
        n = 1 if nV is None else nV
    F = validate_faces(F, n)
    if nV is None and n > MAX_INDEX_SLACK * 3 * F.shape[0] + (1 << 16):
        n_used = np.unique(F).size
        raise ValueError(f"F's largest vertex index is {n - 1} but F uses only {n_used} vertices: "
                         f"K (one value per index 0..{n - 1}) would need {8 * n / 2**30:.3g} GB. "
                         f"Compact the indices first: used, F = np.unique(F, return_inverse=True); "
                         f"F = F.reshape(-1, 3) (then K[i] belongs to vertex used[i])")
    E, uE, EMAP, uEC, uEE = igl.unique_edge_map(F)
    count = np.diff(uEC)
    if (count > 2).any():
        e = int(np.flatnonzero(count > 2)[0])
        raise ValueError(f"mesh has non-manifold edges (more than two incident faces); first is "
                         f"edge {e} between vertices {uE[e].tolist()}")
    FE = np.ascontiguousarray(EMAP.reshape(3, F.shape[0]).T)
    return F, n, np.asarray(uE, dtype=np.int64), FE, count


def _face_l_sq(l_sq, F, FE, nE, rtol=1e-10):
    L = _as_array(l_sq, "l_sq")
    if L.dtype == object or not (np.issubdtype(L.dtype, np.floating) or np.issubdtype(L.dtype, np.integer)):
        raise TypeError(f"l_sq must hold real numbers, got dtype {L.dtype}")
    L = np.asarray(L, dtype=np.float64)
    if L.shape == (nE,):
        Lf = L[FE]
    elif L.shape == (F.shape[0], 3):
        Lf = L
    else:
        raise ValueError(f"l_sq must have shape (#F, 3) = ({F.shape[0]}, 3) (per face, opposite "
                         f"each corner) or (#E,) = ({nE},) (per unique edge), got {L.shape}")
    bad = ~np.isfinite(Lf).all(1) | (Lf <= 0).any(1)
    if bad.any():
        f = int(np.flatnonzero(bad)[0])
        raise ValueError(f"l_sq must be finite and positive; first bad face {f}: {Lf[f]}")
    l = np.sqrt(Lf)
    s = l.sum(1)
    bad = (s - 2 * l.max(1)) <= 1e-12 * s
    if bad.any():
        f = int(np.flatnonzero(bad)[0])
        raise ValueError(f"l_sq violates the strict triangle inequality (degenerate or impossible "
                         f"triangle); first at face {f}: lengths {l[f]}")
    if L.shape == (F.shape[0], 3):
        # a Regge metric is tt-continuous: both sides of an edge must agree
        lo = np.full(nE, np.inf)
        hi = np.full(nE, -np.inf)
        np.minimum.at(lo, FE.ravel(), Lf.ravel())
        np.maximum.at(hi, FE.ravel(), Lf.ravel())
        bad = hi - lo > rtol * hi
        if bad.any():
            e = int(np.flatnonzero(bad)[0])
            raise ValueError(f"l_sq gives different lengths to the two sides of edge {e} "
                             f"({lo[e]:.17g} vs {hi[e]:.17g}): not a Regge metric")
    return Lf


def intrinsic_areas(l_sq_face):
    """Triangle areas from squared edge lengths ``(#F, 3)`` (Kahan's stable Heron)."""
    l = np.sort(np.sqrt(l_sq_face), axis=1)[:, ::-1]     # a ≥ b ≥ c
    a, b, c = l[:, 0], l[:, 1], l[:, 2]
    return 0.25 * np.sqrt(np.maximum((a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c)), 0))


def intrinsic_angles(l_sq_face):
    """Corner angles ``(#F, 3)`` (corner i opposite edge i) of the constant metric
    with the given squared edge lengths: ``θ_i = atan2(4|T|, l_j² + l_k² - l_i²)``."""
    A = intrinsic_areas(l_sq_face)
    L = l_sq_face
    th = np.empty_like(L)
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        th[:, i] = np.arctan2(4 * A, L[:, j] + L[:, k] - L[:, i])
    return th


def angle_defect(l_sq, F, boundary="defect"):
    """Distributional densitized Gauss curvature of a degree-0 Regge metric
    tested with the P1 hat functions: ``Θ_V = 2π - Σ_T θ_V^T`` (eq. 2.5), with the
    boundary convention ``boundary`` (module docstring).  ``(#V,)``."""
    F, nV, uE, FE, count = _topology(F)
    Lf = _face_l_sq(l_sq, F, FE, uE.shape[0])
    return _loads(Lf, F, nV, uE, count, boundary)


def _loads(Lf, F, nV, uE, count, boundary):
    if boundary not in _BOUNDARY:
        raise ValueError(f"boundary must be one of {_BOUNDARY}, got {boundary!r}")
    th = intrinsic_angles(Lf)
    theta = np.bincount(F.ravel(), weights=th.ravel(), minlength=nV)
    bv = np.zeros(nV, dtype=bool)
    bv[uE[count == 1].ravel()] = True
    full = {"defect": TWO_PI, "geodesic": np.pi, "natural": None}[boundary]
    Theta = TWO_PI - theta
    if full is None:
        Theta[bv] = 0.0
    else:
        Theta[bv] = full - theta[bv]
    return Theta


def intrinsic_mass_matrix(l_sq_face, F, nV, mass="consistent"):
    """P1 mass matrix of the metric: consistent ``|T|/12 (1 + δ_ij)`` or lumped ``|T|/3``."""
    import igl
    if mass not in _MASS:
        raise ValueError(f"mass must be one of {_MASS}, got {mass!r}")
    kind = igl.MASSMATRIX_TYPE_FULL if mass == "consistent" else igl.MASSMATRIX_TYPE_BARYCENTRIC
    M = igl.massmatrix_intrinsic(np.sqrt(l_sq_face), F, kind)
    if M.shape[0] < nV:
        import scipy.sparse as sp
        M = sp.block_diag([M, sp.csr_matrix((nV - M.shape[0], nV - M.shape[0]))])
    return M.tocsr()


def _lift(Lf, F, nV, uE, count, boundary, mass):
    from ..solvers import mass_solver
    Theta = _loads(Lf, F, nV, uE, count, boundary)
    M = intrinsic_mass_matrix(Lf, F, nV, mass)
    used = np.zeros(nV, dtype=bool)
    used[F.ravel()] = True
    K = np.full(nV, np.nan)
    idx = np.flatnonzero(used)
    Mu = M[idx][:, idx]
    if mass == "lumped":
        K[idx] = Theta[idx] / Mu.diagonal()
    else:
        # compiled PCG preconditioned by the lumped mass (spectrum in [1/4, 1] on any mesh)
        ml = np.asarray(Mu.sum(axis=1)).ravel()
        K[idx] = mass_solver(Mu, 1.0 / ml, rtol=1e-13)(Theta[idx])
    return K


def gauss_curvature_intrinsic(l_sq, F, *, boundary="natural", mass="consistent"):
    """P1 lifting ``K_h`` of the distributional Gauss curvature of the degree-0
    Regge metric given by squared edge lengths (Gopalakrishnan et al. 2024, Def. 2.1/2.3, k = 0).

    Solves ``M K_h = Θ`` with ``M`` the P1 mass matrix of the metric and ``Θ`` the
    angle deficits (boundary convention ``boundary``, see module docstring).
    Needs no coordinates.

    Parameters
    ----------
    l_sq : (#F, 3) squared lengths opposite each corner (gpytoolbox layout), or
        (#E,) per unique edge in ``igl.unique_edge_map(F)`` order
    F : (#F, 3) int
    boundary : {"natural", "geodesic", "defect"}
    mass : {"consistent", "lumped"}

    Returns
    -------
    K : (#V,) float64 with ``#V = F.max() + 1``; NaN at unreferenced vertices.
        ``Σ_V (M K)_V = Σ_V Θ_V`` (= 2πχ on closed meshes: Gauss–Bonnet).
    """
    F, nV, uE, FE, count = _topology(F)
    Lf = _face_l_sq(l_sq, F, FE, uE.shape[0])
    return _lift(Lf, F, nV, uE, count, boundary, mass)


def gauss_curvature(V: Any, F: Any = None, *, boundary: str = "natural",
                    mass: str = "consistent") -> NDArray[np.float64]:
    """P1 lifting of the distributional Gauss curvature of the edge-length
    (degree-0 Regge) metric of an embedded mesh.

    Equivalent to ``gauss_curvature_intrinsic(squared_edge_lengths(V, F)[0], F)``;
    with ``boundary="defect", mass="lumped"`` it equals
    ``igl.gaussian_curvature(V, F) / diag(igl.massmatrix(V, F, BARYCENTRIC))``.
    Invariant under rigid motions (it depends on edge lengths only).

    Parameters
    ----------
    V : (#V, 3), F : (#F, 3) a manifold, consistently oriented mesh
    boundary, mass : see :func:`gauss_curvature_intrinsic`

    Returns
    -------
    K : (#V,) float64 (NaN at unreferenced vertices)
    """
    m = as_mesh(V, F)
    F, nV = m.F, m.n_vertices
    Lf = m.edge_lengths ** 2
    return _lift(Lf, F, nV, m.edges, m.edge_face_count, boundary, mass)
