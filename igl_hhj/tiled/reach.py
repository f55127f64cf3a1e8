"""How far the drop-in's value at a vertex depends on the mesh: the overlap rule.

A tile grown by ``k`` vertex rings around its core has a cut at ``k`` rings from
every core vertex (:mod:`igl_hhj.tiled.rings`); the drop-in treats the cut as an
open boundary, and the values in the core feel it through two chains of solves:

* **the HHJ solve.**  Walker's S_h is the solution of a mass-matrix system (one
  unknown per edge, coupled through faces); the inverse of such a matrix decays
  exponentially with the graph distance.  The change of S_h caused by the cut,
  relative to the largest |S_h|, falls by at least :data:`HHJ_DECADES_PER_RING`
  decades per ring (measured: ``python -m igl_hhj.benchmarks.tiled_decay``), so
  after ``k_S = ⌈log10(A/ε) / HHJ_DECADES_PER_RING⌉`` rings a change of A × max(abs(κ))
  at the cut is below ε (A = :data:`CUT_AMPLITUDE`).
* **the vertex stage's smoothing.**  ``steps × order`` implicit diffusion solves
  ``(M + t L)⁻¹ M`` with ``t = ℓ_T² / steps``, ``ℓ_T = SMOOTHING_PER_RADIUS · r_T · h_T``
  (:mod:`igl_hhj.intrinsic`; ``r_T`` the per-face radius the stage chooses).  Across
  a cut (a line source) each solve is the 1-D resolvent, whose Green's function is
  ``e^{-|x|/a} / 2a`` with ``a = √t``; the composition of ``n`` of them decays like
  the tail of a Gamma(n) law, ``Q_n(x/a) = e^{-x/a} Σ_{j<n} (x/a)^j / j!``, for a unit
  perturbation at the cut.  A change of A × max(abs(κ)) at the cut is therefore below ε
  after a distance ``x_n(ε/A) · a``, ``Q_n(x_n(ε/A)) = ε/A``; in rings, with
  :data:`RING_SPACING` mean edge lengths per ring, ``k_L = ⌈x_n(ε/A) ·
  SMOOTHING_PER_RADIUS · r_max · b / (√steps · RING_SPACING)⌉`` with ``r_max`` the largest radius on the faces between the core and
  the ``k_S`` rings next to the cut (there the cut perturbs S_h, and with it the radius
  the stage chooses: 6.5 instead of 1.3 on the cut's ring of an icosphere; that zone is
  the ``k_S`` term's) and ``b`` :data:`igl_hhj.recovery.BOUNDARY_LENGTH_FACTOR` when those faces
  touch a real open boundary (the stage smooths twice as far along it), 1 otherwise.

The rule is ``k = k_S + k_L`` (:func:`overlap_rings`).  Both terms bound a
perturbation of :data:`CUT_AMPLITUDE` × max(abs(κ)) at the cut (measured: at most 2.6).
Its inputs follow the stage: the
constants are read from :mod:`igl_hhj.intrinsic` and :mod:`igl_hhj.recovery`, and the
radius is the one the stage reports for each tile (:func:`igl_hhj.tiled.runner`
regrows a tile whose reported radius needs more rings than it was given).
"""
from __future__ import annotations

import math

__all__ = ["overlap_rings", "radius_bound", "hhj_rings", "smoothing_rings", "gamma_tail_root",
           "HHJ_DECADES_PER_RING", "RING_SPACING", "DEFAULT_TOLERANCE"]

DEFAULT_TOLERANCE = 1e-6
"""Default ε: the cut changes a core value by at most ε · max(abs(κ)) (solver tolerances aside)."""

HHJ_DECADES_PER_RING = 0.4
"""Slowest measured decay of the cut's effect on S_h, in decades per vertex ring (direct
solves, half-space cuts; ``python -m igl_hhj.benchmarks.tiled_decay``): 0.86–0.89 on
jittered and noisy ellipsoids, 0.5–1.4 on real meshes, 0.40 on ``beetle.off`` (a scan
with slivers, the slowest of the 15 measured)."""

CUT_AMPLITUDE = 10.0
"""The largest change at the cut the rule allows for, in units of max(abs(κ)): both terms
bound a perturbation of this size (measured at the cut: 0.03 × max(abs(κ)) on a jittered
ellipsoid, 1.3 on noisy ellipsoids, 2.6 on a noisy open scan with slivers)."""

RING_SPACING = math.sqrt(3.0) / 2.0
"""Distance gained per vertex ring, in mean edge lengths: the row height of a
regular triangulation (a ring across a straight cut advances by ``√3/2 h`` in the
worst direction, by ``h`` in the best)."""


def gamma_tail_root(n: int, eps: float) -> float:
    """``x`` with ``Q_n(x) = e^{-x} Σ_{j<n} x^j / j! = eps`` (bisection; Q_n decreases from 1)."""
    if not 0.0 < eps < 1.0:
        raise ValueError(f"tolerance must be in (0, 1), got {eps}")

    def q(x):
        term, total = 1.0, 1.0
        for j in range(1, n):
            term *= x / j
            total += term
        return math.exp(-x) * total

    lo, hi = 0.0, 1.0
    while q(hi) > eps:
        lo, hi = hi, 2.0 * hi
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if q(mid) > eps else (lo, mid)
    return hi


def hhj_rings(eps: float = DEFAULT_TOLERANCE) -> int:
    """Rings after which the cut changes S_h by less than ``eps`` (relative)."""
    return math.ceil(math.log10(CUT_AMPLITUDE / eps) / HHJ_DECADES_PER_RING)


def smoothing_rings(radius: float, eps: float = DEFAULT_TOLERANCE, *, boundary: bool = False) -> int:
    """Rings after which the cut changes the smoothed values by less than ``eps``.

    ``radius``: the largest per-face radius r_T of the vertex stage between the cut and
    the core (0: no smoothing); ``boundary``: those faces touch a real open boundary."""
    from ..constants import SMOOTHING_ORDER, SMOOTHING_STEPS
    from ..constants import BOUNDARY_LENGTH_FACTOR, SMOOTHING_PER_RADIUS
    if not radius > 0:
        return 0
    n = SMOOTHING_STEPS * SMOOTHING_ORDER
    a = SMOOTHING_PER_RADIUS * float(radius) / math.sqrt(SMOOTHING_STEPS)   # √t in mean edge lengths
    if boundary:
        a *= BOUNDARY_LENGTH_FACTOR
    return math.ceil(gamma_tail_root(n, eps / CUT_AMPLITUDE) * a / RING_SPACING)


def overlap_rings(radius: float, eps: float = DEFAULT_TOLERANCE, *, boundary: bool = False) -> int:
    """The overlap rule ``k = k_S + k_L`` (module docstring): rings of overlap after which
    the cut changes a core value by less than ``eps`` times max(abs(κ)).

    Parameters
    ----------
    radius : float
        Largest smoothing radius r_T (in rings, the vertex stage's per-face radius) on
        the faces between the cut and the core.
    eps : float, default :data:`DEFAULT_TOLERANCE`
    boundary : bool
        Those faces touch a real open boundary of the mesh.

    Examples
    --------
    >>> from igl_hhj.tiled.reach import overlap_rings
    >>> overlap_rings(1.0), overlap_rings(5.0), overlap_rings(25.0)
    (22, 38, 116)
    """
    return hhj_rings(eps) + smoothing_rings(radius, eps, boundary=boundary)


def radius_bound(radius: float) -> float:
    """The largest per-face radius the vertex stage can choose at the caller's ``radius``
    (``radius × ADAPTIVE_RANGE[1]``: 25 rings at the default 5)."""
    from ..constants import ADAPTIVE_RANGE
    return float(radius) * float(ADAPTIVE_RANGE[1])
