"""The drop-in :func:`igl_hhj.principal_curvature` and :func:`igl_hhj.shape_operator`, top to bottom.

The public functions (:mod:`igl_hhj.curvature`, with the docstrings) call
:func:`principal_curvature` and :func:`shape_operator` here.  The drop-in is one sequence:

1. **checks** of the arguments (:func:`check_principal_curvature_args`, :func:`check_rtol`);
2. **small-mesh path**: a small clean mesh with the default options runs the whole sequence
   below in one compiled call (:mod:`igl_hhj.small_mesh`, ``_core/small_mesh.cpp``: the same
   kernels in the same order, the same bits), else
3. **mesh | repair**: the validated :class:`~igl_hhj.mesh.TriangleMesh` (read-only views of
   ``V``, ``F``), or, for a defect libigl accepts, the same sequence on the repaired mesh
   (:mod:`igl_hhj.repair`) mapped back to the caller's rows;
4. **crease cut** (only with ``feature_angle`` / ``crease_edges``): the mesh cut along its
   creases (:mod:`igl_hhj.creases`), each side its own open boundary;
5. **boundary treatment** of an open mesh (:mod:`igl_hhj.boundary`);
6. **S_h per solve group**: Walker's HHJ shape operator, one solve per group of connected
   components (:func:`face_shape_operator`, :mod:`igl_hhj.components`, :mod:`igl_hhj.solvers`);
7. **vertex stage**: intrinsic recovery, then adaptive smoothing (:mod:`igl_hhj.intrinsic`);
   the face tensors are freed between the two (the call's memory peak is the solve);
8. **principal values and NaN rows**: ``κ1,2 = H ± |z|`` and the directions, NaN rows at
   unreferenced vertices and vertices without a tangent plane.

Each stage's comment below names the section of ``_core/small_mesh.cpp``
that does the same for a small mesh.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from . import components, creases, intrinsic, kernels, repair, small_mesh
from .boundary import (boundary_partition, boundary_rhs, normalised_boundary_normals, resolve_boundary,
                       simply_supported_values)
from .constants import BOUNDARY_TREATMENTS, DEFAULT_RTOL
from .errors import SolverError
from .mesh import MeshDefectError, as_mesh, mark_bad_vertices
from .solvers import HHJSystem

__all__ = ["Options", "principal_curvature", "shape_operator", "checked_shape_operator", "dropin_on_mesh",
           "dropin_vertex_values", "face_shape_operator", "side_values", "on_repaired_mesh",
           "check_principal_curvature_args", "check_rtol", "no_named_creases_on_repair"]


@dataclass(frozen=True)
class Options:
    """The keyword options of the drop-in and of :func:`igl_hhj.shape_operator` (see there)."""

    boundary: Any = "estimate"
    boundary_normals: Any = None
    boundary_shape_operator: Any = None
    simply_supported: Any = None
    solver: Any = "auto"
    rtol: Any = DEFAULT_RTOL
    feature_angle: Any = None
    crease_edges: Any = None

    @property
    def data(self):
        """The caller's boundary data (per vertex): ``(boundary_normals, boundary_shape_operator,
        simply_supported)``."""
        return self.boundary_normals, self.boundary_shape_operator, self.simply_supported

    def data_dict(self):
        """:attr:`data` by name."""
        return dict(boundary_normals=self.boundary_normals, boundary_shape_operator=self.boundary_shape_operator,
                    simply_supported=self.simply_supported)

    @property
    def creases(self):
        """Whether the surface is cut along creases (``feature_angle`` or ``crease_edges``)."""
        return self.feature_angle is not None or self.crease_edges is not None

    def on_repaired(self, data):
        """These options with the per-vertex data ``data`` (a dict) of the repaired mesh."""
        return replace(self, **data)


# --------------------------------------------------------------------------- 1. checks
def check_principal_curvature_args(radius, useKring):
    """Validate the ``radius`` / ``useKring`` arguments of ``igl.principal_curvature``'s signature."""
    if isinstance(radius, (bool, np.bool_)) or not isinstance(radius, (int, np.integer)):
        raise TypeError(f"radius must be an int (as in igl.principal_curvature), got {type(radius).__name__}")
    if not radius > 0:
        raise ValueError(f"radius must be positive, got {radius}")
    if radius > 10**6:      # a smoothing scale / k-ring beyond any mesh; 10**300 overflowed
        raise ValueError(f"radius must be <= 10**6 (a smoothing scale in rings), got {radius:.3g}")
    if not isinstance(useKring, (bool, np.bool_)):
        raise TypeError(f"useKring must be a bool (as in igl.principal_curvature), got {type(useKring).__name__}")


def check_rtol(rtol):
    """``rtol`` as a float in (0, 1), else TypeError / ValueError."""
    if isinstance(rtol, (bool, np.bool_)) or not isinstance(rtol, (int, float, np.floating, np.integer)):
        raise TypeError(f"rtol must be a float, got {type(rtol).__name__}")
    rtol = float(rtol)
    if not 0.0 < rtol < 1.0:
        raise ValueError(f"rtol must be in (0, 1), got {rtol}")
    return rtol


def no_named_creases_on_repair(crease_edges, exc):
    """Named creases refer to the caller's vertices, which a repair renumbers: refused."""
    if crease_edges is not None:
        raise ValueError(f"crease_edges cannot be used on a mesh that needs repair ({exc}); repair "
                         f"it first (igl_hhj.repair.repair_mesh) and name the creases on the "
                         f"repaired mesh") from exc


# --------------------------------------------------------------------------- the drop-in
def principal_curvature(V, F, radius, useKring, opts: Options, *, repair_defects=True):
    """:func:`igl_hhj.principal_curvature` (the docstring is there): stages 1-8.

    ``repair_defects=False``: a repairable defect raises (the call on a repaired mesh)."""
    check_principal_curvature_args(radius, useKring)                       # 1. checks
    out = _small_mesh_path(V, F, radius, opts)                             # 2. small-mesh path
    if out is not None:
        return out
    try:                                           # 3. mesh, views of V, F (small_mesh.cpp, "stage 3")
        mesh = as_mesh(V, F, copy=False)
    except MeshDefectError as exc:                                         # 3. | repair
        if not repair_defects:
            raise
        no_named_creases_on_repair(opts.crease_edges, exc)
        return _repaired_dropin(exc, V, F, radius, useKring, opts)
    if opts.creases:                                                       # 4. crease cut
        _, _, _, sides = side_values(mesh, radius, opts)
        return _primary_sides(mesh.n_vertices, *sides)
    return dropin_on_mesh(mesh, radius, opts.boundary, opts.boundary_normals, opts.boundary_shape_operator,
                          opts.simply_supported, opts.solver, opts.rtol, release=True)


def _small_mesh_path(V, F, radius, opts):
    """The drop-in's values from :func:`igl_hhj.small_mesh.try_dropin`, or None (the options are
    not the defaults it covers, or the mesh is not a small clean one)."""
    if opts.creases or any(d is not None for d in opts.data) \
            or not (isinstance(opts.solver, str) and opts.solver in ("auto", "direct")) \
            or not (isinstance(opts.boundary, str) and opts.boundary in BOUNDARY_TREATMENTS):
        return None
    return small_mesh.try_dropin(V, F, radius, check_rtol(opts.rtol), opts.boundary)


def dropin_on_mesh(mesh, radius, boundary, boundary_normals, boundary_shape_operator, simply_supported,
                   solver, rtol, groups_of=None, release=False, by_parts=False):
    """Stages 5-8 on a validated mesh (also the cut mesh of stage 4, with ``groups_of`` the
    uncut mesh and ``by_parts`` the caller's part of every side, see :func:`side_values`).

    ``release``: the mesh's face cross products (24 B/face) are dropped before the solve, the
    call's memory peak (a mesh private to the call).  Returns ``(PD1, PD2, PV1, PV2, bad)``."""
    # 5. boundary treatment (small_mesh.cpp, "stage 5, boundary treatment")
    boundary_normals, treatment = resolve_boundary(mesh, boundary, boundary_normals, boundary_shape_operator)
    rtol = check_rtol(rtol)
    if release:      # the vertex stage's normals now; the default path never reads the products again
        mesh.vertex_normals
        mesh.release_face_cross_products()
    # 6. S_h per solve group (small_mesh.cpp, "stage 6, S_h": a small mesh is one direct solve)
    S = face_shape_operator(mesh, boundary_normals, boundary_shape_operator, simply_supported, solver, rtol,
                            estimated=treatment == "estimate", groups_of=groups_of)
    # 7. vertex stage (small_mesh.cpp, "stage 7"): S is freed between recovery and smoothing
    X, rough, N, w = intrinsic.vertex_recovery(mesh, S)
    del S
    X = intrinsic.vertex_smoothing(mesh, X, N, w, rough, radius, rtol, by_parts=by_parts)
    # 8. principal values and NaN rows (small_mesh.cpp, "stage 8")
    PD1, PD2, PV1, PV2 = kernels.principal_hz(X, N)
    del X
    return _nan_rows(mesh, PD1, PD2, PV1, PV2)


def dropin_vertex_values(mesh, S, radius, rtol=DEFAULT_RTOL, by_parts=False):
    """Stages 7-8 on given face tensors ``S`` (#F, 3, 3) (not freed: the caller holds them).

    Returns ``(PD1, PD2, PV1, PV2, bad_vertices)`` as :func:`igl_hhj.principal_curvature`."""
    X, N = intrinsic.vertex_stage(mesh, S, radius, rtol=rtol, by_parts=by_parts)
    PD1, PD2, PV1, PV2 = kernels.principal_hz(X, N)
    del X
    return _nan_rows(mesh, PD1, PD2, PV1, PV2)


def _nan_rows(mesh, PD1, PD2, PV1, PV2):
    """NaN rows at unreferenced vertices and at vertices without a tangent plane (or a
    non-finite value), listed (:func:`igl_hhj.mesh.mark_bad_vertices`); C-contiguous."""
    ref = mesh.referenced_vertices
    if not ref.all():
        for A in (PD1, PD2, PV1, PV2):
            A[~ref] = np.nan
    PD1, PD2, PV1, PV2, bad = mark_bad_vertices(mesh, PD1, PD2, PV1, PV2, copy=False)
    return (np.ascontiguousarray(PD1), np.ascontiguousarray(PD2),
            np.ascontiguousarray(PV1), np.ascontiguousarray(PV2), bad)


def side_values(mesh, radius, opts: Options):
    """Stage 4: the mesh cut along its creases, then stages 5-8 on the cut.

    Each side's boundary is clamped with its own estimated normals; the S_h solve groups are
    the caller's connected parts (the sides of one part are one solve), and the smoothing runs
    one compiled call per side, each solved to the scale of its part
    (:func:`igl_hhj.intrinsic.adaptive_smoothing_by_parts`).  Returns ``(crease, cut, cut
    TriangleMesh, (PD1, PD2, PV1, PV2, bad))`` with one row per side."""
    crease, cut, cm = creases.prepare_cut(mesh, opts.feature_angle, opts.crease_edges, opts.boundary, opts.data)
    parts = kernels.vertex_components(mesh)[0][cut.parent]
    sides = dropin_on_mesh(cm, radius, "estimate", None, None, None, opts.solver, opts.rtol,
                           groups_of=mesh, by_parts=parts)
    return crease, cut, cm, sides


def _primary_sides(nV, PD1, PD2, PV1, PV2, bad):
    """The drop-in's rows: each vertex's primary side (rows 0..#V-1 of the cut)."""
    return (np.ascontiguousarray(PD1[:nV]), np.ascontiguousarray(PD2[:nV]),
            np.ascontiguousarray(PV1[:nV]), np.ascontiguousarray(PV2[:nV]), [b for b in bad if b < nV])


def _repaired_dropin(exc, V, F, radius, useKring, opts):
    """Stage 3's repair: the drop-in on the repaired mesh, mapped back to the caller's rows
    (:func:`igl_hhj.repair.vertex_values_to_caller`); vertices without a value are NaN and listed."""
    R, out = on_repaired_mesh(exc, V, F, opts.data_dict(), lambda V2, F2, data: principal_curvature(
        V2, F2, radius, useKring, opts.on_repaired(data), repair_defects=False),
        "principal curvatures", count_lost=True, stacklevel=6)
    PD1, PD2, PV1, PV2, bad = repaired_values_to_caller(R, out)
    return PD1, PD2, PV1, PV2, np.flatnonzero(bad).tolist()


def repaired_values_to_caller(R, out):
    """The principal values computed on the repaired mesh ``R`` (``out[:4]``, None when every
    face was dropped) on the caller's rows: ``(PD1, PD2, PV1, PV2, bad (#V,) bool)``.  The
    vertices of a two-sided patch get no value (no side is "out" there: no sign), nor do
    caller vertices that lost every face; their rows are NaN."""
    PD1, PD2, PV1, PV2 = out[:4] if out is not None else (np.zeros((0, 3)),) * 2 + (np.zeros(0),) * 2
    two_sided = repair.two_sided_vertices(R)
    if two_sided.any():
        for a in (PD1, PD2, PV1, PV2):
            a[two_sided] = np.nan
    PD1, PD2, PV1, PV2 = repair.vertex_values_to_caller(R, PD1, PD2, PV1, PV2)
    bad = ~(np.isfinite(PD1).all(axis=1) & np.isfinite(PD2).all(axis=1) & np.isfinite(PV1) & np.isfinite(PV2))
    for a in (PD1, PD2, PV1, PV2):
        a[bad] = np.nan
    return PD1, PD2, PV1, PV2, bad


def on_repaired_mesh(exc, V, F, data, compute, what, *, count_lost=False, stacklevel=2):
    """``(R, compute(R.V, R.F, data on R))`` for a mesh refused with the repairable ``exc``.

    :func:`igl_hhj.repair.repair_mesh`; the per-vertex ``data`` (dict name -> (#V, ...) or
    None) restricted to the repaired vertices; no warning about the seams of split vertices,
    one :class:`~igl_hhj.mesh.MeshWarning` naming the repairs and ``what`` was computed
    (``count_lost``: and how many caller vertices lost every face), ``stacklevel`` frames up.
    ``(R, None)`` when every face was dropped."""
    V, F = repair.caller_arrays(V, F)
    R = repair.repair_mesh(V, F)
    data = repair.map_vertex_kwargs(R, data)
    out = None
    if len(R.F):
        with repair.seams_not_warned():
            out = compute(R.V, R.F, data)
    repair.warn_repaired(R, exc, what, F if count_lost else None, stacklevel=stacklevel + 1)
    return R, out


# --------------------------------------------------------------------------- the shape operator
def shape_operator(V, F, opts: Options, *, repair_defects=False):
    """:func:`igl_hhj.shape_operator` (the docstring is there): stages 3-6 and no silent NaN."""
    try:
        mesh = as_mesh(V, F)                                                     # 3. mesh
    except MeshDefectError as exc:                                               # 3. | repair
        if not repair_defects:
            raise
        no_named_creases_on_repair(opts.crease_edges, exc)
        R, S = on_repaired_mesh(exc, V, F, opts.data_dict(), lambda V2, F2, data: shape_operator(
            V2, F2, opts.on_repaired(data)), "the shape operator", stacklevel=5)
        if S is not None and R.two_sided is not None:     # a two-sided patch: no sign
            S[R.two_sided] = np.nan
        return repair.face_values_to_caller(R, np.zeros((0, 3, 3)) if S is None else S)[0]
    groups_of = None
    if opts.creases:                                                             # 4. crease cut
        _, _, cut_mesh = creases.prepare_cut(mesh, opts.feature_angle, opts.crease_edges, opts.boundary,
                                             opts.data)
        groups_of, mesh = mesh, cut_mesh
    return checked_shape_operator(mesh, opts.boundary, opts.boundary_normals, opts.boundary_shape_operator,
                                  opts.simply_supported, opts.solver, opts.rtol, groups_of)


def checked_shape_operator(mesh, boundary, boundary_normals, boundary_shape_operator, simply_supported,
                           solver, rtol, groups_of=None):
    """Stages 5-6 on a validated mesh (also a cut mesh, ``groups_of`` the uncut one), and
    :class:`~igl_hhj.errors.SolverError` rather than silent NaN."""
    boundary_normals, treatment = resolve_boundary(mesh, boundary, boundary_normals, boundary_shape_operator)
    S = face_shape_operator(mesh, boundary_normals, boundary_shape_operator, simply_supported, solver,
                            check_rtol(rtol), estimated=treatment == "estimate", groups_of=groups_of)
    bad = ~np.isfinite(S).all(axis=(1, 2))
    if bad.any():
        raise SolverError(f"the HHJ solve returned NaN/inf on {int(bad.sum())} faces (first "
                          f"{int(np.flatnonzero(bad)[0])}); try solver='direct'",
                          faces=np.flatnonzero(bad))
    return S


def face_shape_operator(mesh, boundary_normals, boundary_shape_operator, simply_supported, solver,
                        rtol=DEFAULT_RTOL, info=None, estimated=False, groups_of=None):
    """Stage 6: Walker's S_h (#F, 3, 3), one solve per group of connected components.

    A mesh with several connected components is solved in independent groups
    (:func:`igl_hhj.components.solve_groups`): no component depends on another.
    ``estimated``: ``boundary_normals`` are estimated ones (NaN rows: no usable normal, see
    :func:`igl_hhj.boundary.boundary_partition`).  ``groups_of``: a mesh with the same faces
    whose components define the groups instead (the uncut mesh of a cut: the sides of one
    part are one solve).  ``info``: a dict that receives the solver and its iterations."""
    data = (boundary_normals, boundary_shape_operator, simply_supported)
    groups = None
    if all(d is None or np.shape(d)[:1] == (mesh.n_vertices,) for d in data):
        groups = components.solve_groups(mesh if groups_of is None else groups_of, solver)
    if groups is None:
        return _solve_group(mesh, *data, solver, rtol, info, estimated)
    if len(groups) == 1:              # every component small: one direct solve of the mesh
        return _solve_group(mesh, *data, groups[0][1], rtol, info, estimated)
    S = np.empty((mesh.n_faces, 3, 3))
    for faces, group_solver in groups:
        sub, verts = components.submesh(mesh, faces)
        sub_data = [None if d is None else np.asarray(d)[verts] for d in data]
        sub_info = {} if info is not None else None
        S[faces] = _solve_group(sub, *sub_data, group_solver, rtol, sub_info, estimated)
        if info is not None:
            info["iterations"] = max(info.get("iterations", 0), sub_info.get("iterations", 0))
            info.setdefault("solver", sub_info.get("solver"))
    return S


def _solve_group(mesh, boundary_normals, boundary_shape_operator, simply_supported, solver,
                 rtol=DEFAULT_RTOL, info=None, estimated=False):
    """S_h of one solve group: ``A s^k = -B X^k + g^k`` (Walker eq. 5.14 / 5.19), then
    ``S_h|_T = -Σ_k ν_T^k σ^k|_T`` (eq. 5.12)."""
    clamped, ss_edges = boundary_partition(mesh, boundary_normals, boundary_shape_operator,
                                           simply_supported, estimated)
    N = normalised_boundary_normals(mesh, boundary_normals, clamped, estimated) if clamped.any() else None
    fixed = ss_edges if ss_edges.any() else None
    if fixed is not None:
        rho = simply_supported_values(mesh, boundary_shape_operator, ss_edges)
    system = HHJSystem(mesh, fixed=fixed)
    rhs = kernels.jump_apply(mesh, mesh.V)                    # B X, (#E, 3)
    np.negative(rhs, out=rhs)                                 # -B X
    boundary_rhs(mesh, rhs, clamped, N)
    if fixed is not None:                                     # eq. 5.18/5.19: move ρ to the load
        rhs -= system.fixed_coupling(rho)
        rhs[fixed] = 0.0
    # coupled: one CG recurrence on the 3 coordinates, so a rotation of V rotates s exactly
    s, solve_info = system.solve(rhs, solver, rtol, overwrite_rhs=True, coupled=True)   # (#E, 3): σ^k DOFs
    del rhs
    if fixed is not None:
        s[fixed] = rho[fixed]
    if info is not None:
        info.update(solve_info)
    return kernels.shape_operator_faces(mesh, s)              # S_h|_T = -Σ_k ν_T^k σ^k|_T

