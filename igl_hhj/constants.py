"""Every constant of the drop-in :func:`igl_hhj.principal_curvature`, in one place.

These numbers decide what the drop-in accepts, which solver it uses and how it smooths;
the compiled small-mesh path (:mod:`igl_hhj.small_mesh`, ``_core/small_mesh.cpp``)
receives the same values from here.  Each is also importable from the module that uses
it (``igl_hhj.mesh.DEGENERATE_AREA_RTOL``, ``igl_hhj.solvers.AUTO_DIRECT_MAX``,
``igl_hhj.recovery.SMOOTHING_PER_RADIUS``, ...), under the same name.

This module imports nothing of igl_hhj: every layer may read it.
"""
from __future__ import annotations

import numpy as np

__all__ = [
    # mesh validation
    "DEGENERATE_AREA_RTOL", "COORDINATE_MAX", "MIN_MESH_SIZE", "FOLDED_NORMAL_RTOL",
    # linear solvers
    "DEFAULT_RTOL", "AUTO_DIRECT_MAX", "DIRECT_MAX", "PROBE_ITER", "CG_MAXITER", "SLIVER_ANGLE",
    "SLIVER_MAX_FRACTION", "LDL_MAX", "ENVELOPE_MAX", "DIRECT_RESIDUAL_RTOL",
    "SPD_AUTO_DIRECT_MAX", "SPD_AUTO_CG_MAXITER",
    # boundary treatment
    "BOUNDARY_TREATMENTS", "FIT_RINGS", "SIDE_DOT_MIN",
    # vertex stage
    "QUALITY_FLOOR", "SMOOTHING_PER_RADIUS", "BOUNDARY_LENGTH_FACTOR", "BOUNDARY_BAND_RINGS",
    "SMOOTHING_STEPS", "SMOOTHING_ORDER", "ADAPTIVE_GAIN", "ADAPTIVE_POWER", "ADAPTIVE_RANGE",
    "SMOOTHING_MAXITER", "PILOT_RADIUS", "SPLIT_MIN_VERTICES",
]

# --------------------------------------------------------------------------- mesh validation
# (igl_hhj.mesh: the numerical-robustness policy of its module docstring)
DEGENERATE_AREA_RTOL = 1e-7
"""A face with ``2|T| ≤ DEGENERATE_AREA_RTOL × (longest edge)²`` (smallest angle
below ~1e-7 rad) is rejected: libigl's edge-length formulas lose all accuracy
about a decade below (:mod:`igl_hhj.mesh`)."""

COORDINATE_MAX = 1e75
"""Largest accepted ``|coordinate|`` (squared areas overflow float64 beyond ~1e77)."""

MIN_MESH_SIZE = 1e-60
"""Smallest accepted longest edge (squared areas underflow towards subnormals below)."""

FOLDED_NORMAL_RTOL = float(np.sqrt(np.finfo(np.float64).eps))
"""A vertex has no tangent plane when ``|Σ_T |T| ν_T| ≤ FOLDED_NORMAL_RTOL Σ_T |T|``
(the normalised direction would carry less than half the digits of float64)."""

# --------------------------------------------------------------------------- linear solvers
# (igl_hhj.solvers: the strategy of its module docstring)
DEFAULT_RTOL = 1e-6
"""Relative residual of the HHJ solves of the public curvature functions, tied to the
discretisation error (``python -m igl_hhj.benchmarks.speed --rtol-study``)."""

AUTO_DIRECT_MAX = 3_000
"""HHJ system, ``solver="auto"``: factorise without trying PCG up to this many unknowns
(everything is instant there); also the size up to which
:func:`igl_hhj.components.solve_groups` solves components together, directly."""

DIRECT_MAX = 700_000
"""HHJ system, ``"auto"``: never factorise above this many unknowns (fill and memory):
PCG runs to convergence."""

PROBE_ITER = 20
"""HHJ system, ``"auto"``: PCG extrapolates its remaining iterations this often."""

CG_MAXITER = 5000
"""HHJ system: iteration cap of the PCG."""

SLIVER_ANGLE = 20.0
"""Faces with a smallest angle below this (degrees) form the sliver subdomain of the
two-level preconditioner (an exact sparse solve on their DOFs); chosen by ``python -m
igl_hhj.benchmarks.speed --sliver-study`` (0°-25° on camelhead, the bunny upsampled
twice, an open scan and a jittered ellipsoid: 15-20° was fastest on all four;
re-measured with the QDLDL sliver solve inside the PCG, 15°-30°: 20° is fastest or
within 8 % of 25° on all four, 30° up to 1.6x slower)."""

SLIVER_MAX_FRACTION = 0.4
"""Above this fraction of sliver DOFs ``"auto"`` factorises A itself: the two-level's
subdomain factorisation then costs a good part of the full one, with the PCG on top
(open scan, 52 % sliver DOFs: S_h direct 0.12 s, two-level PCG 0.15 s in ``speed``;
camelhead, 26 %: 0.06 / 0.06 s)."""

LDL_MAX = 200_000
"""Up to this many unknowns the direct solver is QDLDL (AMD ordering + simplicial LDLᵀ),
above CHOLMOD (cholespy).  Measured on the HHJ matrices (``python -m
igl_hhj.benchmarks.speed --factor-study``): QDLDL factorises 10k–167k unknowns 1.6–3.4x
faster than CHOLMOD and 1.6–4x faster than SuperLU-MMD; CHOLMOD wins at 393k (2.8 s
against 4.0 s).  QDLDL's solves are 2–3x slower than CHOLMOD's."""

ENVELOPE_MAX = 700
"""Direct solves up to this many unknowns run the compiled dense envelope LDLᵀ
(:func:`igl_hhj.kernels.envelope_ldl_solve`) on the fixed-width rows, without scipy
sparse matrices or a QDLDL factor object: on tiny meshes their construction cost 10-20x
the factorisation (a 12-face cube: 0.25 ms of a 0.57 ms drop-in call).  Also the size
limit of the small-mesh path (:data:`igl_hhj.small_mesh.MAX_EDGES`)."""

DIRECT_RESIDUAL_RTOL = 1e-8
"""A direct solve without pivoting is accepted when ``‖A X - R‖ ≤ this × ‖R‖`` per
column; otherwise (tiny pivots of a numerically semi-definite A) pivoted LU solves again."""

SPD_AUTO_DIRECT_MAX = 50_000
"""Generic SPD systems (:func:`igl_hhj.solvers.solve_spd`: mass matrices, the curved HHJ
systems of :mod:`igl_hhj.curved`, the numpy reference :class:`igl_hhj.hhj.HHJProjection`),
``method="auto"``: direct up to this many unknowns, above PCG with a switch to the
direct solver.  Not the HHJ system of the drop-in, whose ``"auto"`` threshold is
:data:`AUTO_DIRECT_MAX` with a cost model behind it."""

SPD_AUTO_CG_MAXITER = 600
"""Generic SPD systems, ``method="auto"``: the PCG switches to the direct solver as soon as
its measured rate predicts more iterations than this (well-shaped meshes need 50–250;
meshes full of slivers can need thousands)."""

# --------------------------------------------------------------------------- boundary treatment
# (igl_hhj.boundary, igl_hhj.boundary_estimation)
BOUNDARY_TREATMENTS = ("estimate", "plain")
"""``boundary=`` values: "estimate" (clamped with estimated O(h²) normals, the default
without boundary data) and "plain" (Walker's plain assembly: the face normal stands in
for the boundary normal)."""

FIT_RINGS = 3
"""Default fit neighbourhood of :func:`igl_hhj.boundary_estimation.estimate_boundary_normals` in rings."""

SIDE_DOT_MIN = 0.05
"""An estimated boundary normal must have ``N·ν_T > SIDE_DOT_MIN`` with every boundary
face T of the vertex (else the faces' mean normal, else none)."""

# --------------------------------------------------------------------------- vertex stage
# (igl_hhj.recovery: weights and smoothing coefficients; igl_hhj.intrinsic: the stage)
QUALITY_FLOOR = 0.1
"""Faces whose (neighbourhood) shape quality is below this get a recovery weight that
falls off linearly (:func:`igl_hhj.recovery.recovery_weights`)."""

SMOOTHING_PER_RADIUS = 0.2
"""The smoothing length per unit of ``radius``, in edge lengths: ``ℓ_T =
SMOOTHING_PER_RADIUS · r_T · h_T`` (the intrinsic stage; the ambient comparison uses the
global ``ℓ = SMOOTHING_PER_RADIUS · radius · h̄``).  Measured by ``python -m
igl_hhj.benchmarks.robustness --sweep`` (error vs radius on clean, jittered and noisy
meshes)."""

BOUNDARY_LENGTH_FACTOR = 2.0
"""Near an open boundary (faces touching the :data:`BOUNDARY_BAND_RINGS`-ring band) the
smoothing length is this many times longer: the diffusion sees half a neighbourhood
there (natural boundary condition), so with the same ℓ the band keeps twice the noise."""

BOUNDARY_BAND_RINGS = 2
"""Width in rings of the boundary band of :data:`BOUNDARY_LENGTH_FACTOR`."""

SMOOTHING_STEPS = 2
"""Implicit diffusion steps per application of the smoothing kernel G."""

SMOOTHING_ORDER = 2
"""Bias-reduction order of the smoothing kernel ``I - (I - G)^order``: 1 plain diffusion
G, 2 Tukey's twicing ``2G - G²``, 3 ``3G - 3G² + G³``."""

ADAPTIVE_GAIN = 0.3
"""Gain of the adaptive radius ``r = radius · clip(0.3 ρ^{1/4} / (κh), ADAPTIVE_RANGE)``
(:func:`igl_hhj.intrinsic_numpy.adaptive_radius`; fitted, see there)."""

ADAPTIVE_POWER = 0.25
"""Power of the roughness ρ in the adaptive radius."""

ADAPTIVE_RANGE = (0.2, 5.0)
"""Bounds of the factor of the adaptive radius (radius 5: 1 to 25 rings)."""

SMOOTHING_MAXITER = 500
"""Iteration cap of each compiled smoothing solve (a solve that reaches it sends the
vertex stage to the sparse-LU smoothing of :mod:`igl_hhj.intrinsic_numpy`)."""

PILOT_RADIUS = 5
"""Radius of the pilot smoothing (one implicit step) whose curvature sets the scale."""

SPLIT_MIN_VERTICES = 64
"""Smoothing by parts (:func:`igl_hhj.intrinsic.adaptive_smoothing_by_parts`): components
with fewer vertices are smoothed together in one call (a call's fixed cost would
outweigh their iterations)."""
