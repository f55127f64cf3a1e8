"""Walker's wavy dumbbell (Walker 2023, §6.2) and the saddle coarse mesh (§6.1).

The chart domain U is bounded by the four curves of eq. (6.2),

    (cos t + 1, sin t)                 -π/2 ≤ t ≤ π/2   (right half circle)
    (-t + 1, 0.6 + 0.4 cos πt)         0 ≤ t ≤ 2        (top wave)
    (cos t - 1, sin t)                 π/2 ≤ t ≤ 3π/2   (left half circle)
    (t - 1, -(0.8 + 0.2 cos πt))       0 ≤ t ≤ 2        (bottom wave)

(counter-clockwise; the junctions at (±1, ±1) are C¹), and the surface is the
graph χ(u, v) = (u, v, exp(-u²) sin 2v).  Meshes are built in the plane: the
coarse mesh comes from the ``triangle`` package (boundary vertices on the
curved boundary, no Steiner points on it), its interior vertices are
perturbed; the refined meshes are uniform refinements (``igl.upsample``) of
this straight coarse mesh mapped by a blended curved-element map (Walker:
"a Lenoir type map") that puts every boundary vertex on ∂U (at the curve
parameter interpolated between the coarse edge's end points), before lifting
by χ.  ``refine_planar`` (closest-point projection of the new boundary
midpoints only) is kept for comparison.
"""
from __future__ import annotations

import numpy as np

from .exact import GraphSurface

__all__ = [
    "WalkerDumbbell", "dumbbell_closest_boundary_point", "dumbbell_boundary_polyline",
    "dumbbell_coarse", "refine_planar", "dumbbell_sequence", "saddle_coarse", "saddle_sequence",
    "fix_boundary_ears", "blended_map", "curved_refinement", "dumbbell_boundary_curve",
    "dumbbell_boundary_parameter", "dumbbell_edge_curve", "curved_corner_angles",
]


class WalkerDumbbell(GraphSurface):
    """Walker §6.2: the graph ``z = exp(-u²) sin 2v`` over the wavy dumbbell domain (eq. 6.2).

    Normal ν points up (+z), ∇ν exact (``GraphSurface``)."""

    name = "dumbbell"

    def height(self, x, y):
        e = np.exp(-x * x)
        s, c = np.sin(2 * y), np.cos(2 * y)
        h = e * s
        hx = -2 * x * e * s
        hy = 2 * e * c
        hxx = (4 * x * x - 2) * e * s
        hxy = -4 * x * e * c
        hyy = -4 * e * s
        return h, (hx, hy), (hxx, hxy, hyy)


# --------------------------------------------------------------------------- boundary curve
def _top(x):
    """Top wave of eq. (6.2) as a graph y = 0.6 - 0.4 cos πx (t = 1 - x), with y', y''."""
    return 0.6 - 0.4 * np.cos(np.pi * x), 0.4 * np.pi * np.sin(np.pi * x), 0.4 * np.pi ** 2 * np.cos(np.pi * x)


def _bottom(x):
    """Bottom wave of eq. (6.2) as a graph y = -(0.8 - 0.2 cos πx) (t = x + 1), with y', y''."""
    return -0.8 + 0.2 * np.cos(np.pi * x), -0.2 * np.pi * np.sin(np.pi * x), -0.2 * np.pi ** 2 * np.cos(np.pi * x)


def _closest_on_graph(P, g, iters=30):
    """Closest point of {(x, g(x)) : |x| ≤ 1} to each row of P by Newton on x (clamped)."""
    x = np.clip(P[:, 0], -1.0, 1.0)
    for _ in range(iters):
        y, dy, ddy = g(x)
        r = y - P[:, 1]
        f1 = (x - P[:, 0]) + r * dy                  # ½ d/dx |(x, g) - P|²
        f2 = 1.0 + dy * dy + r * ddy
        step = f1 / np.where(f2 > 0.1, f2, 0.1)      # damped where the distance is not convex
        x = np.clip(x - step, -1.0, 1.0)
        if np.max(np.abs(step)) < 1e-16:
            break
    return np.column_stack([x, g(x)[0]])


def _closest_on_arc(P, cx, side):
    """Closest point of the half circle |p - (cx, 0)| = 1 with sign(x - cx) = side (or its end points)."""
    D = P - np.array([cx, 0.0])
    r = np.linalg.norm(D, axis=1, keepdims=True)
    Q = np.array([cx, 0.0]) + D / np.where(r > 0, r, 1.0)
    outside = side * D[:, 0] < 0                    # angle outside the half circle: nearest end point
    ends = np.array([[cx, 1.0], [cx, -1.0]])
    Q[outside] = ends[np.where(P[outside, 1] >= 0, 0, 1)]
    Q[r[:, 0] == 0] = ends[0]
    return Q


def dumbbell_closest_boundary_point(P):
    """Closest point on ∂U (eq. 6.2) of planar points P.

    Parameters
    ----------
    P : (n, 2) array_like of float

    Returns
    -------
    Q : (n, 2) float64, the nearest of the closest points on the four pieces.
    """
    P = np.asarray(P, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] != 2:
        raise ValueError(f"P must have shape (n, 2), got {P.shape}")
    C = np.stack([_closest_on_arc(P, 1.0, 1), _closest_on_graph(P, _top),
                  _closest_on_arc(P, -1.0, -1), _closest_on_graph(P, _bottom)])    # (4, n, 2)
    d = np.linalg.norm(C - P[None], axis=2)
    return C[np.argmin(d, axis=0), np.arange(len(P))]


def dumbbell_boundary_curve(tau):
    """Global parametrisation C(τ) of ∂U (eq. 6.2), τ ∈ [0, 4) counter-clockwise (periodic).

    [0, 1): right half circle, t = -π/2 + πτ;  [1, 2): top wave, x = 1 - 2(τ - 1);
    [2, 3): left half circle, t = π/2 + π(τ - 2);  [3, 4): bottom wave, x = -1 + 2(τ - 3).
    Continuous and piecewise smooth (the pieces meet with a common tangent
    direction at (±1, ±1)).

    Returns
    -------
    (n, 2) float64
    """
    tau = np.mod(np.asarray(tau, dtype=np.float64), 4.0)
    piece = np.minimum(np.floor(tau).astype(np.int64), 3)
    r = tau - piece
    out = np.empty(tau.shape + (2,))
    t0 = -np.pi / 2 + np.pi * r
    t2 = np.pi / 2 + np.pi * r
    x1 = 1.0 - 2.0 * r
    x3 = -1.0 + 2.0 * r
    cand = np.stack([np.stack([np.cos(t0) + 1, np.sin(t0)], -1), np.stack([x1, _top(x1)[0]], -1),
                     np.stack([np.cos(t2) - 1, np.sin(t2)], -1), np.stack([x3, _bottom(x3)[0]], -1)])
    out[...] = np.take_along_axis(cand, piece[None, ..., None], axis=0)[0]
    return out


def dumbbell_boundary_parameter(P):
    """Inverse of :func:`dumbbell_boundary_curve` for points on ∂U: (n, 2) → τ (n,) in [0, 4)."""
    P = np.asarray(P, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] != 2:
        raise ValueError(f"P must have shape (n, 2), got {P.shape}")
    C = np.stack([_closest_on_arc(P, 1.0, 1), _closest_on_graph(P, _top),
                  _closest_on_arc(P, -1.0, -1), _closest_on_graph(P, _bottom)])
    piece = np.argmin(np.linalg.norm(C - P[None], axis=2), axis=0)
    Q = C[piece, np.arange(len(P))]
    ang_r = np.arctan2(Q[:, 1], Q[:, 0] - 1.0)                     # in [-π/2, π/2]
    ang_l = np.mod(np.arctan2(Q[:, 1], Q[:, 0] + 1.0), 2 * np.pi)  # in [π/2, 3π/2]
    r = np.choose(piece, [(ang_r + np.pi / 2) / np.pi, (1.0 - Q[:, 0]) / 2.0,
                          (ang_l - np.pi / 2) / np.pi, (Q[:, 0] + 1.0) / 2.0])
    return np.mod(piece + np.clip(r, 0.0, 1.0), 4.0)


def dumbbell_edge_curve(A, B, s):
    """Points of ∂U between boundary points A and B: C((1 - s) τ_A + s τ_B) (short way round).

    Parameters
    ----------
    A, B : (n, 2) points on ∂U; s : (n,) in [0, 1].
    """
    ta = dumbbell_boundary_parameter(A)
    tb = dumbbell_boundary_parameter(B)
    d = np.mod(tb - ta + 2.0, 4.0) - 2.0
    return dumbbell_boundary_curve(ta + np.asarray(s) * d)


def dumbbell_boundary_polyline(n_per_unit=200):
    """Dense counter-clockwise sampling of ∂U (eq. 6.2), shape (m, 2), first point not repeated."""
    k_arc = max(int(np.pi * n_per_unit), 8)
    k_wave = max(int(2.2 * n_per_unit), 8)
    t = np.linspace(-np.pi / 2, np.pi / 2, k_arc, endpoint=False)
    right = np.column_stack([np.cos(t) + 1, np.sin(t)])
    x = np.linspace(1.0, -1.0, k_wave, endpoint=False)
    top = np.column_stack([x, _top(x)[0]])
    t = np.linspace(np.pi / 2, 3 * np.pi / 2, k_arc, endpoint=False)
    left = np.column_stack([np.cos(t) - 1, np.sin(t)])
    x = np.linspace(-1.0, 1.0, k_wave, endpoint=False)
    bottom = np.column_stack([x, _bottom(x)[0]])
    return np.concatenate([right, top, left, bottom])


def _sample_closed_curve(Pd, n, rng, jitter):
    """n points along the closed polyline Pd at (jittered) equal arc-length spacing."""
    seg = np.linalg.norm(np.roll(Pd, -1, axis=0) - Pd, axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    L = s[-1]
    u = (np.arange(n) + jitter * rng.uniform(-1, 1, n)) * L / n + rng.uniform(0, L / n)
    u = np.mod(np.sort(u), L)
    Pc = np.concatenate([Pd, Pd[:1]])
    x = np.interp(u, s, Pc[:, 0])
    y = np.interp(u, s, Pc[:, 1])
    return np.column_stack([x, y])


def fix_boundary_ears(P, F):
    """Flip the interior edge of every triangle whose three vertices lie on the boundary.

    Walker's Property 1 (each triangle has at most two boundary vertices) fails
    for "ears" (two boundary edges meeting at a boundary vertex); refinement
    would keep such a triangle in every level.  Each ear (a, c, b) with
    interior edge (a, c) is flipped with its neighbour (c, a, d) into
    (b, a, d), (b, d, c) when that quad is convex.

    Parameters
    ----------
    P : (#V, 2) planar positions, F : (#F, 3) counter-clockwise triangles.

    Returns
    -------
    F : (#F, 3) int64 (a copy), same vertices.
    """
    import igl
    F = np.array(F, dtype=np.int64, copy=True)
    for _ in range(4):                            # a handful of passes; each pass is vectorised
        bv = np.zeros(len(P), dtype=bool)
        bv[igl.boundary_facets(F)[0].ravel()] = True
        ears = np.flatnonzero(bv[F].all(axis=1))
        if ears.size == 0:
            break
        TT, TTi = igl.triangle_triangle_adjacency(F)
        # the interior edge of an ear: the local edge with a neighbour
        loc = np.argmax(TT[ears] >= 0, axis=1)
        nb = TT[ears, loc]
        nbi = TTi[ears, loc]
        ok = (nb >= 0) & ~np.isin(nb, ears)         # never flip two ears into each other
        _, keep = np.unique(nb[ok], return_index=True)   # one flip per neighbour per pass
        ears, loc, nb, nbi = ears[ok][keep], loc[ok][keep], nb[ok][keep], nbi[ok][keep]
        # igl's edge i of a face is (F[i], F[i+1])
        a = F[ears, loc]
        c = F[ears, (loc + 1) % 3]
        b = F[ears, (loc + 2) % 3]
        d = F[nb, (nbi + 2) % 3]

        def ccw(p, q, r):
            return (P[q, 0] - P[p, 0]) * (P[r, 1] - P[p, 1]) - (P[q, 1] - P[p, 1]) * (P[r, 0] - P[p, 0])
        # ear a→c→b and neighbour c→a→d bound the quad a→d→c→b: new diagonal b–d
        convex = (ccw(b, a, d) > 0) & (ccw(b, d, c) > 0)
        if not convex.any():
            break
        e, n_ = ears[convex], nb[convex]
        F[e] = np.column_stack([b[convex], a[convex], d[convex]])
        F[n_] = np.column_stack([b[convex], d[convex], c[convex]])
    return F


def curved_corner_angles(P, F, edge_curve):
    """Smallest corner angle of the *curved* boundary triangles (degrees).

    At each end point of a boundary edge, the angle between the boundary
    curve's tangent (towards the other end) and the triangle's other edge: the
    angle that the refined, blended meshes (:func:`curved_refinement`)
    inherit at that coarse vertex.  Straight coarse triangles can look fine
    while the curve runs almost along their interior edge (a coarse chord of
    the top wave, curvature radius 0.25, gave 1°)."""
    import igl
    F = np.asarray(F, dtype=np.int64)
    _, J, K = igl.boundary_facets(F)
    J, K = np.asarray(J), np.asarray(K)
    a, b, c = F[J, (K + 1) % 3], F[J, (K + 2) % 3], F[J, K]
    eps = 1e-7
    worst = np.inf
    for p, q in ((a, b), (b, a)):
        t = edge_curve(P[p], P[q], np.full(len(p), eps)) - P[p]
        e = P[c] - P[p]
        cos = np.einsum("ij,ij->i", t, e) / (np.linalg.norm(t, axis=1) * np.linalg.norm(e, axis=1))
        worst = min(worst, float(np.degrees(np.arccos(np.clip(cos, -1, 1))).min()))
    return worst


def _dumbbell_coarse_once(n_boundary, max_area, amount, rng):
    import triangle as tr
    B = _sample_closed_curve(dumbbell_boundary_polyline(), n_boundary, rng, 0.3)
    B = dumbbell_closest_boundary_point(B)
    nb = len(B)
    seg = np.column_stack([np.arange(nb), (np.arange(nb) + 1) % nb])
    out = tr.triangulate({"vertices": B, "segments": seg}, f"pq25Ya{max_area:.6f}")
    P, F = np.array(out["vertices"], dtype=np.float64), np.array(out["triangles"], dtype=np.int64)
    F = _orient_ccw(P, F)
    F = fix_boundary_ears(P, F)
    P = _jitter_interior(P, F, amount, rng)
    return P, F


def dumbbell_coarse(n_boundary=22, max_area=0.3, amount=0.25, seed=0, n_faces=38, min_curved_angle=20.0,
                    attempts=64):
    """Perturbed coarse planar mesh of the dumbbell domain U (eq. 6.2).

    Boundary vertices: ``n_boundary`` points on ∂U at jittered arc-length
    spacing; interior: the ``triangle`` package (``pqYa``: quality, no
    Steiner points on the boundary, area bound ``max_area``), interior
    vertices then perturbed by up to ``amount`` × their mean edge length.
    Ears (triangles with three boundary vertices) are flipped away.  Random
    draws (seeded by ``seed``) are repeated until the mesh has ``n_faces``
    triangles (Walker: 38, so that 608 = 38·4²) and its curved boundary
    triangles have corner angles ≥ ``min_curved_angle``
    (:func:`curved_corner_angles`); otherwise the best draw is returned.

    Returns
    -------
    P : (#V, 2) float64, F : (#F, 3) int64 counter-clockwise.
    """
    rng = np.random.default_rng(seed)
    best, best_key = None, None
    for _ in range(attempts):
        P, F = _dumbbell_coarse_once(n_boundary, max_area, amount, rng)
        ang = curved_corner_angles(P, F, dumbbell_edge_curve)
        ok = n_faces is None or len(F) == n_faces
        if ok and ang >= min_curved_angle:
            return P, F
        key = (ok, ang)
        if best_key is None or key > best_key:
            best, best_key = (P, F), key
    return best


def _orient_ccw(P, F):
    X = P[F]
    det = (X[:, 1, 0] - X[:, 0, 0]) * (X[:, 2, 1] - X[:, 0, 1]) - (X[:, 1, 1] - X[:, 0, 1]) * (X[:, 2, 0] - X[:, 0, 0])
    F = F.copy()
    F[det < 0] = F[det < 0][:, [0, 2, 1]]
    return F


def _jitter_interior(P, F, amount, rng):
    """Move interior vertices by up to ``amount`` × mean incident edge length (random direction);
    moves that would invert a triangle are undone."""
    import igl
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    L = np.linalg.norm(P[E[:, 0]] - P[E[:, 1]], axis=1)
    spacing = np.bincount(E.ravel(), np.repeat(L, 2), len(P)) / np.maximum(np.bincount(E.ravel(), minlength=len(P)), 1)
    interior = np.ones(len(P), dtype=bool)
    interior[igl.boundary_facets(F)[0].ravel()] = False
    ang = rng.uniform(0, 2 * np.pi, len(P))
    r = amount * spacing * rng.uniform(0, 1, len(P))
    Q = P + (interior * r)[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])
    X = Q[F]
    det = (X[:, 1, 0] - X[:, 0, 0]) * (X[:, 2, 1] - X[:, 0, 1]) - (X[:, 1, 1] - X[:, 0, 1]) * (X[:, 2, 0] - X[:, 0, 0])
    bad = np.unique(F[det <= 0].ravel())
    Q[bad] = P[bad]
    return Q


def refine_planar(P, F, boundary_projection=None, levels=1):
    """Uniform planar refinement (``igl.upsample``) with boundary midpoints projected.

    Parameters
    ----------
    P : (#V, 2) planar positions, F : (#F, 3) triangles.
    boundary_projection : callable (n, 2) → (n, 2), optional
        Closest-point map onto the curved boundary, applied to the new
        vertices on boundary edges (interior midpoints are kept).
    levels : int

    Returns
    -------
    P, F : refined mesh (old vertices keep their index).
    """
    import igl
    P = np.asarray(P, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    for _ in range(levels):
        n_old = len(P)
        V3, F = igl.upsample(np.column_stack([P, np.zeros(len(P))]), F)
        P = np.array(V3[:, :2])
        if boundary_projection is not None:
            bnd = np.unique(igl.boundary_facets(F)[0].ravel())
            new_b = bnd[bnd >= n_old]
            P[new_b] = boundary_projection(P[new_b])
    return P, np.asarray(F, dtype=np.int64)


def coarse_barycentrics(P0, F0, Q, coarse_face):
    """Where points of a straight coarse mesh lie, for the blended boundary maps.

    Parameters
    ----------
    P0 : (#V0, 2), F0 : (#F0, 3) straight coarse mesh.
    Q : (n, 2) points, coarse_face : (n,) int, a coarse face containing each point.

    Returns
    -------
    is_bnd : (#F0, 3) bool, local edge j (opposite corner j) of the face is a boundary edge
    T : (n, 3, 2) corners of each point's coarse face
    lam : (n, 3) barycentric coordinates of each point in it
    """
    import igl
    F0 = np.asarray(F0, dtype=np.int64)
    _, J, K = igl.boundary_facets(F0)
    is_bnd = np.zeros(F0.shape, dtype=bool)
    is_bnd[np.asarray(J), np.asarray(K)] = True
    T = P0[F0[coarse_face]]
    M = np.stack([T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]], axis=-1)
    l12 = np.linalg.solve(M, (Q - T[:, 0])[..., None])[..., 0]
    return is_bnd, T, np.column_stack([1.0 - l12.sum(axis=1), l12])


def blended_map(P0, F0, Q, coarse_face, edge_curve):
    """Curved-element (Zlámal / Gordon–Hall blending, "Lenoir type") map of the coarse mesh.

    A point with barycentric coordinates λ in the straight coarse triangle
    (a, b, c) whose edge ab is a boundary edge goes to

        Φ(x) = x + (λ_a + λ_b) [γ(s) - (s a + (1 - s) b)],   s = λ_a / (λ_a + λ_b),

    with γ the boundary arc from b (s = 0) to a (s = 1), ``edge_curve(b, a, s)``.
    Φ is the identity on triangles without a boundary edge and at every coarse
    vertex, continuous across coarse edges (the correction vanishes on the
    other two edges of a curved triangle), and maps coarse boundary edges onto
    ∂U.  Every level is the image under the same Φ of a uniform refinement of
    the straight coarse mesh, so the meshes converge to a smooth
    parametrisation (the "Lenoir type map" of Walker §6.2).  γ is the
    curve's own parametrisation between the edge's end points, not the
    closest point of the chord, which is not smooth where a coarse chord is
    farther from the curve than its curvature radius (the top wave has
    radius 0.25 at x = 0).  Shape regularity in the limit is governed by
    :func:`curved_corner_angles` of the coarse mesh (measured: a coarse mesh
    with a 1° curved corner angle gave min angles 22° → 15° → 7.8° → 4.4°
    over levels 1–4; the default one keeps ≈ 19–25°).

    Parameters
    ----------
    P0 : (#V0, 2), F0 : (#F0, 3) straight coarse mesh.
    Q : (n, 2) points of the straight coarse mesh.
    coarse_face : (n,) int, a coarse face containing each point.
    edge_curve : callable (A (m, 2), B (m, 2), s (m,)) → (m, 2)
        The boundary arc between boundary points A (s = 0) and B (s = 1),
        e.g. :func:`dumbbell_edge_curve`.

    Returns
    -------
    X : (n, 2) float64
    """
    is_bnd, T, lam = coarse_barycentrics(P0, F0, Q, coarse_face)
    X = np.array(Q, dtype=np.float64, copy=True)
    for j in range(3):                              # the 3 local edges, vectorised over points
        a, b = (j + 1) % 3, (j + 2) % 3
        w = lam[:, a] + lam[:, b]
        sel = is_bnd[coarse_face, j] & (w > 1e-14)
        if not sel.any():
            continue
        s = lam[sel, a] / w[sel]
        chord = s[:, None] * T[sel, a] + (1.0 - s[:, None]) * T[sel, b]
        X[sel] += w[sel, None] * (edge_curve(T[sel, b], T[sel, a], s) - chord)
    return X


def curved_refinement(P0, F0, levels, edge_curve):
    """``levels`` uniform refinements of the straight coarse mesh, mapped by :func:`blended_map`.

    Returns
    -------
    P : (#V, 2) float64, F : (#F, 3) int64 (``igl.upsample`` connectivity:
    the children of coarse face f are rows f·4^levels … (f+1)·4^levels - 1).
    """
    import igl
    P0 = np.asarray(P0, dtype=np.float64)
    V = np.column_stack([P0, np.zeros(len(P0))])
    F = np.asarray(F0, dtype=np.int64)
    for _ in range(levels):
        V, F = igl.upsample(V, F)
    F = np.asarray(F, dtype=np.int64)
    coarse = np.arange(len(F)) // 4 ** levels
    vf = np.zeros(len(V), dtype=np.int64)
    vf[F.ravel()] = np.repeat(np.arange(len(F)), 3)
    return blended_map(P0, F0, np.asarray(V)[:, :2], coarse[vf], edge_curve), F


def dumbbell_sequence(n_levels, pre_refine=2, seed=0, surface=None, **coarse_kw):
    """Walker's dumbbell mesh sequence: [(V_k, F_k)], k = 0..n_levels-1, lifted by χ.

    Level k is the straight coarse mesh (:func:`dumbbell_coarse`, 38
    triangles) refined ``pre_refine + k`` times and mapped by the blended
    curved-element map (:func:`blended_map`, Walker's "Lenoir type map"), so
    Walker's k = 0 has 608·4^k triangles.  Boundary vertices lie on χ(∂U)
    (to 1e-15), every vertex on the graph, and the vertices of
    level k keep their positions at level k + 1."""
    surface = WalkerDumbbell() if surface is None else surface
    P0, F0 = dumbbell_coarse(seed=seed, **coarse_kw)
    out = []
    for k in range(n_levels):
        P, F = curved_refinement(P0, F0, pre_refine + k, dumbbell_edge_curve)
        out.append((surface.lift(P), F))
    return out


# --------------------------------------------------------------------------- saddle (§6.1)
def saddle_coarse(n_side=4, n_interior=7, amount=0.3, seed=0):
    """Perturbed coarse planar mesh of [0, 1]² for Walker's saddle (§6.1).

    ``n_side - 1`` jittered points inside each side plus the corners on the
    boundary, ``n_interior`` jittered interior points, constrained Delaunay
    (``triangle``, no Steiner points), ears flipped so that every triangle has
    an interior vertex.  Defaults: 16 boundary + 7 interior vertices →
    2·7 + 16 - 2 = 28 triangles, Walker's coarse size (448 = 28·4²).

    Returns
    -------
    P : (#V, 2) float64, F : (#F, 3) int64 counter-clockwise.
    """
    import triangle as tr
    rng = np.random.default_rng(seed)
    s = (np.arange(1, n_side) + amount * rng.uniform(-1, 1, (4, n_side - 1))) / n_side   # (4, n-1)
    bottom = np.column_stack([s[0], np.zeros(n_side - 1)])
    right = np.column_stack([np.ones(n_side - 1), s[1]])
    top = np.column_stack([1 - s[2], np.ones(n_side - 1)])
    left = np.column_stack([np.zeros(n_side - 1), 1 - s[3]])
    corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)
    B = np.concatenate([corners[:1], bottom, corners[1:2], right, corners[2:3], top, corners[3:], left])
    nb = len(B)
    # interior: a jittered well-spread set (Halton-like stratification in x, random y)
    xi = (np.arange(n_interior) + 0.5 + 0.6 * amount * rng.uniform(-1, 1, n_interior)) / n_interior
    yi = 0.15 + 0.7 * np.mod(np.arange(n_interior) * 0.618034 + rng.uniform(0, 1), 1.0)
    I = np.column_stack([0.1 + 0.8 * xi, yi])
    seg = np.column_stack([np.arange(nb), (np.arange(nb) + 1) % nb])
    out = tr.triangulate({"vertices": np.concatenate([B, I]), "segments": seg}, "pY")
    P, F = np.array(out["vertices"], dtype=np.float64), np.array(out["triangles"], dtype=np.int64)
    F = _orient_ccw(P, F)
    return P, fix_boundary_ears(P, F)


def saddle_sequence(n_levels, pre_refine=2, seed=0, surface=None):
    """Walker's saddle mesh sequence (448·4^k triangles by default), lifted onto the graph."""
    from .exact import WalkerSaddle
    surface = WalkerSaddle() if surface is None else surface
    P, F = saddle_coarse(seed=seed)
    P, F = refine_planar(P, F, None, pre_refine)
    out = [(surface.lift(P), F)]
    for _ in range(n_levels - 1):
        P, F = refine_planar(P, F, None, 1)
        out.append((surface.lift(P), F))
    return out
