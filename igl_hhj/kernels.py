"""Thin Python face of the compiled core ``igl_hhj._hhj_core`` (C++17, nanobind).

Every function checks and coerces its arrays once (C-contiguous float64 / int64, shapes;
the topology maps of :class:`igl_hhj.mesh.TriangleMesh` as they are stored, int32 indices
and int8 local indices, so no call copies them) and hands them to one C++ kernel; the
kernels have no hidden state and release the GIL.  The readable numpy reference of each
kernel is named in its docstring; tests (``tests/core/``, ``tests/mesh/``, ``tests/hhj/``,
``tests/vertex_stage/``) compare the two.

The extension is loaded, and its thread and heap policy kept, by :mod:`igl_hhj.runtime`:
every wrapper applies the thread policy (:func:`igl_hhj.runtime.apply_thread_policy`)
before its call.  The runtime's functions and its documented switches are also reachable
here under their old names (``kernels.set_num_threads``, ``kernels.run_tasks``,
``kernels.ADAPT_TO_LOAD = False``, ``kernels.LARGE_CALL_HEAP = False``, ...): reading or
setting a switch here reads or sets :mod:`igl_hhj.runtime`'s.
"""
from __future__ import annotations

import sys
import types

import numpy as np

from . import runtime
from .runtime import (apply_thread_policy as _threads, core as _core, large_call_heap,  # noqa: F401
                      max_threads, run_tasks, set_num_threads, task_workers, with_large_call_heap)

__all__ = [
    "topology", "hhj_system", "jump_apply", "block_pcg", "shape_operator_faces",
    "face_tensors", "principal_2x2", "max_threads",
    "set_num_threads", "ell_indptr", "edge_morton_order", "recovery_weights",
    "face_metrics", "vertex_area_sums",
    "intrinsic_patch_recovery", "vertex_components", "transport_phases",
    "adaptive_radius", "principal_hz", "intrinsic_smoothing", "dihedral_magnitudes", "crease_cut",
    "run_tasks", "task_workers", "dropin_small",
    "large_call_heap", "with_large_call_heap", "LARGE_CALL_HEAP",
]


def _f64(a, name, shape_tail=None):
    a = np.ascontiguousarray(a, dtype=np.float64)
    if shape_tail is not None and a.shape[1:] != tuple(shape_tail):
        raise ValueError(f"{name} must have shape (n, {', '.join(map(str, shape_tail))}), got {a.shape}")
    return a


def _i64(a):
    return np.ascontiguousarray(a, dtype=np.int64)


def _i32(a):
    return np.ascontiguousarray(a, dtype=np.int32)


def _i8(a):
    return np.ascontiguousarray(a, dtype=np.int8)


def _switch(name):
    """A property of this module that reads and sets :mod:`igl_hhj.runtime`'s ``name``."""
    return property(lambda self: getattr(runtime, name), lambda self, value: setattr(runtime, name, value),
                     doc=f"igl_hhj.runtime.{name}")


class _Kernels(types.ModuleType):
    """This module's type: its runtime switches are :mod:`igl_hhj.runtime`'s."""

    ADAPT_TO_LOAD = _switch("ADAPT_TO_LOAD")
    LARGE_CALL_HEAP = _switch("LARGE_CALL_HEAP")
    TASKS_MIN_WORK = _switch("TASKS_MIN_WORK")


sys.modules[__name__].__class__ = _Kernels


def topology(F, n_vertices):
    """Unique edges and incidence maps of ``F`` in one pass.

    Reference: ``igl.unique_edge_map`` plus the numpy properties of
    :class:`igl_hhj.mesh.TriangleMesh`.

    Returns
    -------
    edges : (#E, 2) int32, ``(min, max)`` vertex pairs in lexicographic order
        (the order of ``igl.unique_edge_map``'s ``uE``).
    face_edges : (#F, 3) int32, the edge opposite corner i of face f.
    count : (#E,) int8, faces per edge, saturated at 127.
    edge_faces : (#E, 2) int32, faces (column 0: the one whose half-edge runs
        min → max); -1 for none.
    local_index : (#E, 2) int8, the edge's local index in those faces; -1 for none.
    sign : (#F, 3) int8, +1 where the half-edge ``x_{i+1} → x_{i+2}`` runs min → max, else -1.

    Raises
    ------
    ValueError
        2³¹ or more vertices, faces or unique edges (the maps hold int32 indices).
    """
    shape = getattr(F, "shape", None)
    if shape is not None and len(shape) == 2 and (shape[0] >= 2**31 or int(n_vertices) >= 2**31):
        raise ValueError(f"topology: at most 2**31 - 1 vertices, faces and unique edges (igl_hhj's "
                         f"edge maps are int32), got {shape[0]} faces and {int(n_vertices)} vertices")
    F = _i64(F)
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"F must have shape (#F, 3), got {F.shape}")
    return _core.topology(F, int(n_vertices))


def face_metrics(V, F):
    """One pass over the faces: ``(cross (#F, 3), double_areas (#F,), l2max (#F,))``, the
    cross product ``(x1 - x0) × (x2 - x0)``, its norm and the squared longest edge.

    Reference: :attr:`igl_hhj.mesh.TriangleMesh._cross`, ``face_double_areas`` and
    :func:`igl_hhj.mesh.zero_area_faces`.  ``V`` (#V, 3) float64, ``F`` (#F, 3) int64
    (validated indices)."""
    _threads()
    return _core.face_metrics(_f64(V, "V", (3,)), _i64(F))


def vertex_area_sums(F, n_vertices, cross, double_areas):
    """``(Σ_{T∋v} c_T (#V, 3), Σ_{T∋v} |c_T| (#V,))`` of :attr:`igl_hhj.mesh.TriangleMesh.folded_vertices`."""
    return _core.vertex_area_sums(_i64(F), int(n_vertices), _f64(cross, "cross", (3,)),
                                  _f64(double_areas, "double_areas"))


def edge_morton_order(mesh):
    """(#E,) int64 permutation listing the edges by the Morton (Z-order) code of their
    midpoints: a cache-friendly numbering for the solver (the lexicographic edge order
    scatters neighbouring edges across memory)."""
    return _core.edge_morton_order(mesh.V, _i32(mesh.edges))


def hhj_system(mesh, fixed=None, schwarz=True, topology=None):
    """Assembled HHJ matrix A and its face-Schwarz preconditioner M, fixed-width rows.

    Reference: :func:`igl_hhj.hhj.mass_matrix` and
    :func:`igl_hhj.hhj.face_schwarz_preconditioner`.

    Parameters
    ----------
    mesh : TriangleMesh
    fixed : (#E,) bool, optional
        Fixed DOFs: M gets zero rows/columns there (A is returned unmasked).
    schwarz : bool
        Also build M.
    topology : (face_edges, edge_faces, edge_local_index), optional
        A renumbering of the mesh's edge maps (e.g. by :func:`edge_morton_order`);
        rows, columns and ``fixed`` are then in that numbering.  int32, int32, int8
        as the mesh stores them (other integer types are converted).

    Returns
    -------
    cols : (#E, 5) int32, column of each slot (slot 0 = the diagonal; unused
        slots point at the diagonal with value 0)
    A : (#E, 5) float64, ``A[e, e'] = Σ_T |T| φ_e : φ_e'`` (Walker eq. 5.14)
    M : (#E, 5) float64 or None, ``Σ_T R_Tᵀ (R_T A R_Tᵀ)⁻¹ R_T`` (same columns)
    n_jacobi : int, faces whose block was numerically singular and got Jacobi instead
    sin_min_angle : (#F,) float64, sine of each face's smallest angle,
        ``2|T| l_min / (l_0 l_1 l_2)``
    """
    fx = None if fixed is None else np.ascontiguousarray(fixed, dtype=np.uint8)
    FE, EF, ELI = topology if topology is not None else \
        (mesh.face_edges, mesh.edge_faces, mesh.edge_local_index)
    FE, EF, ELI = _i32(FE), _i32(EF), _i8(ELI)
    nE = mesh.n_edges
    if FE.shape != (mesh.n_faces, 3) or EF.shape != (nE, 2) or ELI.shape != (nE, 2) \
            or (fx is not None and fx.shape != (nE,)):
        raise ValueError("hhj_system: topology arrays do not match the mesh")
    _threads()
    return _core.hhj_system(mesh.V, mesh.F, FE, EF, ELI, fx, bool(schwarz))


def jump_apply(mesh, W):
    """``B W`` (#E, k) for P1 vertex values ``W`` (#V, k); reference :func:`igl_hhj.hhj.jump_matrix`."""
    W = _f64(W, "W")
    if W.ndim != 2 or W.shape[0] != mesh.n_vertices:
        raise ValueError(f"W must have shape ({mesh.n_vertices}, k), got {W.shape}")
    _threads()
    return _core.jump_apply(mesh.V, mesh.F, _i32(mesh.edge_faces), _i8(mesh.edge_local_index), W)


def ell_indptr(n, width=5):
    """(n + 1,) CSR row pointer of a fixed-width row format: int32 while ``width * n``
    fits (memory: the HHJ system holds it at the solve; :func:`block_pcg` takes int32
    row pointers as they are), else int64."""
    return np.arange(0, width * n + 1, width, dtype=np.int32 if width * n < 2**31 else np.int64)


def envelope_ldl_solve(indptr, indices, data, R, resid_rtol):
    """Direct solve ``A X = R`` of a small SPD CSR matrix by a dense envelope LDLᵀ
    (no pivoting) in the compiled core, for the tiny systems where building scipy
    sparse matrices and a QDLDL factor costs more than the factorisation itself.

    Row ``i`` is stored packed from its first nonzero column to the diagonal (the factor
    keeps that envelope): O(Σ_i bandwidth_i²) flops and O(Σ_i bandwidth_i) memory, so only
    for n ≲ a few hundred (:data:`igl_hhj.solvers.ENVELOPE_MAX`).  Reference: :func:`igl_hhj.solvers.cholesky_solve`.

    Returns
    -------
    X : (n, k) float64
    status : int, 0 solved (every column's relative residual ≤ ``resid_rtol``), 1 a pivot
        ≤ 1e-13 max|a_ii| (numerically semi-definite: use a pivoted solver), 2 residual
        too large, 3 a column index out of range
    """
    R = _f64(R, "R")
    if R.ndim != 2:
        raise ValueError(f"R must have shape (n, k), got {R.shape}")
    return _core.envelope_ldl_solve(_i64(indptr), _i32(indices), _f64(data, "data"), R,
                                    float(resid_rtol))


def block_pcg(indptr, indices, data, R, *, rtol, maxiter, M=None, dinv=None,
              probe_iter=0, max_predicted=np.inf, subdomain=None, subdomain_solve=None,
              subdomain_ldl=None, overwrite_R=False, coupled=False):
    """Fused block PCG on all columns of ``R`` (n, k ≤ 16) for a CSR matrix.

    ``coupled=False``: k independent CG recurrences (one per column); ``True``: one CG
    on the k columns together (every scalar summed over the columns), so that
    mixing the columns by an orthogonal matrix (a rotation of the coordinate
    right-hand sides of Walker's eq. 5.14) mixes the iterates the same way.

    Column indices travel as int32 (memory bandwidth: the sweeps are memory-bound).  Row
    pointers: int32 when those of A and of M both are (passed without a copy, e.g.
    :func:`ell_indptr`'s), else int64.
    Reference: :func:`igl_hhj.solvers._block_pcg`.  Preconditioner: ``M`` =
    ``(indptr, indices, data)`` of a CSR matrix, else Jacobi with ``dinv``; with
    ``subdomain`` (int64 indices S) and ``subdomain_solve(r_S, z_S)`` (writes
    ``z_S = C r_S`` into its second argument, (|S|, k) float64) a second level
    ``z += R_Sᵀ C R_S r`` is added (e.g. an exact sparse solve on the DOFs of
    badly shaped faces).  Instead of ``subdomain_solve``, ``subdomain_ldl`` = ``(Lp, Li,
    Lx, D, perm)`` gives ``C = A_SS⁻¹`` as an LDLᵀ factor ``P (I + L) D (I + L)ᵀ Pᵀ``
    (QDLDL's layout: ``L`` strictly lower triangular CSC, ``P[perm[i], i] = 1``), solved in
    the compiled core on all k columns at once, without a Python call per iteration.

    Returns
    -------
    X : (n, k) float64
    iterations : int
    status : int, 0 converged, 1 reached maxiter, 2 stopped early because the
        extrapolated number of iterations still needed exceeded ``max_predicted`` (checked every
        ``probe_iter`` iterations), 3 breakdown (``pᵀAp ≤ 0`` or the residual grew
        10⁴-fold: the matrix is numerically singular or not SPD)
    relres : list of float, final relative residual per column
    """
    R = np.asarray(R, dtype=np.float64, order="C") if overwrite_R else \
        np.array(R, dtype=np.float64, order="C", copy=True)
    if R.ndim != 2:
        raise ValueError(f"R must be (n, k), got {R.shape}")
    n = R.shape[0]
    if n >= 2 ** 31:
        raise ValueError(f"block_pcg handles fewer than 2**31 unknowns, got {n}")
    indptr = np.asarray(indptr)
    narrow = indptr.dtype == np.int32 and (M is None or np.asarray(M[0]).dtype == np.int32)
    idx = _i32 if narrow else _i64
    indptr, indices, data = idx(indptr), _i32(indices), _f64(data, "data")
    if indptr.shape != (n + 1,) or indices.shape != data.shape or indptr[-1] > len(indices):
        raise ValueError("inconsistent CSR arrays for block_pcg")
    if len(indices) and (indices.min() < 0 or indices.max() >= n):
        raise ValueError("CSR column index out of range in block_pcg")
    Mp = Mi = Mx = None
    if M is not None:
        Mp, Mi, Mx = idx(M[0]), _i32(M[1]), _f64(M[2], "M")
        if Mp.shape != (n + 1,) or Mi.shape != Mx.shape or (len(Mi) and (Mi.min() < 0 or Mi.max() >= n)):
            raise ValueError("inconsistent preconditioner CSR arrays for block_pcg")
    elif dinv is not None:
        dinv = _f64(dinv, "dinv")
        if dinv.shape != (n,):
            raise ValueError(f"dinv must be ({n},), got {dinv.shape}")
    else:
        raise ValueError("block_pcg needs M or dinv")
    S = ldl = None
    if subdomain is not None:
        S = _i64(subdomain)
        if subdomain_ldl is not None:
            if subdomain_solve is not None:
                raise TypeError("give subdomain_solve or subdomain_ldl, not both")
            if len(subdomain_ldl) != 5:
                raise ValueError("subdomain_ldl must be (Lp, Li, Lx, D, perm)")
            Lp, Li, Lx, D, perm = subdomain_ldl
            ldl = (_i64(Lp), _i64(Li), _f64(Lx, "Lx"), _f64(D, "D"), _i64(perm))
        elif subdomain_solve is None or not callable(subdomain_solve):
            raise TypeError("subdomain needs a callable subdomain_solve(r_S, z_S) or subdomain_ldl")
    _threads()
    return (_core.block_pcg32 if narrow else _core.block_pcg)(
        indptr, indices, data, Mp, Mi, Mx, dinv, R, float(rtol), int(maxiter), int(probe_iter),
        float(max_predicted), S, subdomain_solve if S is not None and ldl is None else None, ldl, bool(coupled))


def shape_operator_faces(mesh, s):
    """``S_h|_T = -Σ_k ν_T^k σ^k|_T`` (#F, 3, 3) from the edge DOFs ``s`` (#E, 3), Walker eq. (5.12).

    Reference: :func:`igl_hhj.hhj.face_tensors` contracted with the face normals."""
    s = _f64(s, "s", (3,))
    _threads()
    return _core.shape_operator_faces(mesh.V, mesh.F, _i32(mesh.face_edges), s)


def face_tensors(mesh, s):
    """``Σ_j s[e(f, j), k] φ_j`` (#F, k, 3, 3) for edge DOFs ``s`` (#E, k); reference :func:`igl_hhj.hhj.face_tensors`."""
    s = _f64(s, "s")
    if s.ndim != 2 or s.shape[0] != mesh.n_edges:
        raise ValueError(f"s must have shape ({mesh.n_edges}, k), got {s.shape}")
    _threads()
    return _core.face_tensors(mesh.V, mesh.F, _i32(mesh.face_edges), s)


def principal_2x2(S, N):
    """Closed-form principal curvatures/directions of tangential tensors.

    Reference: the numpy ``eigh`` version,
    ``principal_from_shape_operator_reference`` of ``tests/vertex_stage/reference_intrinsic.py``.
    ``S`` (n, 3, 3), ``N`` (n, 3) unit normals → ``PD1, PD2`` (n, 3), ``PV1 ≥ PV2`` (n,)."""
    S = _f64(S, "S", (3, 3))
    N = _f64(N, "N", (3,))
    if S.shape[0] != N.shape[0]:
        raise ValueError(f"S and N must have the same length, got {S.shape[0]} and {N.shape[0]}")
    _threads()
    return _core.principal_2x2(S, N)


def _ref_mask(mesh):
    return np.ascontiguousarray(mesh.referenced_vertices, dtype=np.uint8)


def recovery_weights(mesh, quality_floor):
    """Face weights ``|T| min(1, q~_T / quality_floor)`` (#F,); reference
    :func:`igl_hhj.recovery.recovery_weights`."""
    _threads()
    return _core.recovery_weights(mesh.V, mesh.F, _i32(mesh.face_edges), _i32(mesh.edge_faces),
                                  float(quality_floor))


def _recovery_args(mesh, S, N, w, name):
    """The checked (#F, 3, 3) face tensors, (#V, 3) normals and (#F,) weights of a recovery kernel."""
    S = _f64(S, "S", (3, 3))
    N = _f64(N, "N", (3,))
    w = _f64(w, "w")
    if S.shape[0] != mesh.n_faces or N.shape[0] != mesh.n_vertices or w.shape != (mesh.n_faces,):
        raise ValueError(f"{name}: S must be (#F, 3, 3), N (#V, 3) and w (#F,)")
    return S, N, w


def intrinsic_patch_recovery(mesh, S, N, w):
    """Intrinsic patch recovery: ``(X, rough)``, X (#V, 3) components ``(h, Re z, Im z)``
    (reference ``recover`` of ``tests/vertex_stage/reference_intrinsic.py``, rows of unreferenced vertices 0) and
    rough (#V,) the roughness of S_h around each vertex (reference
    ``roughness`` there).  ``S`` (#F, 3, 3), ``N`` (#V, 3) unit vertex
    normals, ``w`` (#F,) face weights."""
    S, N, w = _recovery_args(mesh, S, N, w, "intrinsic_patch_recovery")
    _threads()
    return _core.intrinsic_patch_recovery(mesh.V, mesh.F, S, N, w, _ref_mask(mesh),
                                          float(mesh.mean_edge_length))


def vertex_components(mesh):
    """Connected components of the vertex graph: ``(labels (#V,) int32, count)``, labelled in
    the order of their smallest vertex; vertices of no edge get label 0."""
    return _core.vertex_components(_i32(mesh.edges), int(mesh.n_vertices))


def graph_components(pairs, n):
    """Connected components of the graph on ``n`` nodes with the edges ``pairs`` (k, 2):
    ``(labels (n,) int32, count)``, labelled in the order of their smallest node (the
    labels of ``scipy.sparse.csgraph.connected_components``), every node its own
    component unless an edge joins it (one union-find pass, as :func:`vertex_components`)."""
    if n >= 2**31:                                     # before anything of size n is allocated
        raise ValueError("graph_components: at most 2**31 - 1 nodes (the core's labels are int32)")
    pairs = _i64(pairs)
    if pairs.ndim != 2 or pairs.shape[1] != 2:
        raise ValueError("graph_components: pairs must be (k, 2)")
    if pairs.size and (pairs.min() < 0 or pairs.max() >= n):
        raise ValueError(f"graph_components: node index out of range 0..{n - 1}")
    alone = np.ones(n, dtype=bool)                     # nodes of no edge: a loop each, so that
    alone[pairs.ravel()] = False                       # each is its own component
    loops = np.flatnonzero(alone)
    return _core.vertex_components(_i32(np.concatenate([pairs, np.stack([loops, loops], axis=1)])), int(n))


def dihedral_magnitudes(mesh):
    """``|θ_e|`` (#E,) of every edge with exactly two faces (0 on the others); reference
    ``tests/vertex_stage/reference_creases.py``."""
    _threads()
    return _core.dihedral_magnitudes(_f64(mesh.face_normals, "face_normals", (3,)), _i32(mesh.edge_faces),
                                     _i8(mesh.edge_face_count))


def crease_cut(mesh, join):
    """The cut of :func:`igl_hhj.creases.cut_along` (reference
    :func:`igl_hhj.creases.cut_along_reference`): ``join`` (#E,) bool, the edges across
    which corners stay together (two faces, not a crease).  Returns ``(Fc (#F, 3) int64,
    extra (k,) int64)``: the cut faces and the vertex of every extra side (row #V + i)."""
    join = np.ascontiguousarray(join, dtype=np.uint8)
    if join.shape != (mesh.n_edges,):
        raise ValueError(f"crease_cut: join must have shape ({mesh.n_edges},), got {join.shape}")
    return _core.crease_cut(_i64(mesh.F), int(mesh.n_vertices), _i32(mesh.edge_faces),
                            _i8(mesh.edge_local_index), join, _f64(mesh.face_areas, "face_areas"))


def transport_phases(mesh, N):
    """(#E, 2) cos and sin of the spin-2 transport of each edge; reference
    :func:`igl_hhj.intrinsic_numpy.transport_phase_components`."""
    N = _f64(N, "N", (3,))
    if N.shape[0] != mesh.n_vertices:
        raise ValueError("transport_phases: N must be (#V, 3)")
    _threads()
    return _core.transport_phases(N, _i32(mesh.edges))


def boundary_normal_fits(mesh, verts, rings, N0):
    """The two quadric height fits of :func:`igl_hhj.boundary_estimation.estimate_boundary_normals`
    at the vertices ``verts`` (n,) over their ``rings``-ring (one more where that ring has
    fewer than 10 vertices), starting from the normals N0 (n, 3), coordinates scaled by the
    mean length of each vertex's edges: (n, 3) the second fit's unit normal where both fits
    are well posed, else N0.  Reference
    :func:`igl_hhj.boundary_estimation.boundary_normal_fits_reference`."""
    verts = _i64(verts)
    N0 = _f64(N0, "N0", (3,))
    if verts.ndim != 1 or N0.shape[0] != len(verts):
        raise ValueError("boundary_normal_fits: verts must be (n,) and N0 (n, 3)")
    if int(rings) < 1:
        raise ValueError(f"boundary_normal_fits: rings must be >= 1, got {rings}")
    _threads()
    return _core.boundary_normal_fits(mesh.V, _i32(mesh.edges), verts, int(rings), N0)


def adaptive_radius(mesh, pilot, rough, radius, gain, power, lo, hi):
    """Per-face smoothing radius (#F,); reference :func:`igl_hhj.intrinsic_numpy.adaptive_radius`."""
    pilot = _f64(pilot, "pilot", (3,))
    rough = _f64(rough, "rough")
    if pilot.shape[0] != mesh.n_vertices or rough.shape != (mesh.n_vertices,):
        raise ValueError("adaptive_radius: pilot must be (#V, 3) and rough (#V,)")
    _threads()
    return _core.adaptive_radius(mesh.V, mesh.F, pilot, rough, float(radius), float(gain), float(power),
                                 float(lo), float(hi))


def principal_hz(X, N):
    """Principal directions and curvatures of components (h, Re z, Im z) (n, 3) in the frames
    of N (n, 3): ``(PD1, PD2, PV1, PV2)``; reference ``principal`` of
    ``tests/vertex_stage/reference_intrinsic.py``."""
    X = _f64(X, "X", (3,))
    N = _f64(N, "N", (3,))
    if X.shape[0] != N.shape[0]:
        raise ValueError(f"X and N must have the same length, got {X.shape[0]} and {N.shape[0]}")
    _threads()
    return _core.principal_hz(X, N)


def intrinsic_smoothing(mesh, X, C, mass, phase, rough, radius, *, per_radius, pilot_radius, pilot_rtol,
                        gain, power, bounds, steps, coefficients, rtol, maxiter):
    """The drop-in's smoothing in one call, in place on ``X`` (#V, 3): the pilot step, the
    adaptive per-face radius, the twiced smoothing at it (reference
    :func:`igl_hhj.intrinsic_numpy.smooth_reference`).  Returns ``(status, iterations,
    components, radius (#F,))``; status 0 when every solve converged (else X unchanged)."""
    if not (isinstance(X, np.ndarray) and X.dtype == np.float64 and X.flags.c_contiguous
            and X.shape == (mesh.n_vertices, 3)):
        raise ValueError("intrinsic_smoothing: X must be a C-contiguous float64 (#V, 3) array")
    C = _f64(C, "C", (3,))
    mass = _f64(mass, "mass")
    phase = _f64(phase, "phase", (2,))
    rough = _f64(rough, "rough")
    if C.shape[0] != mesh.n_faces or mass.shape != (mesh.n_vertices,) or phase.shape[0] != mesh.n_edges \
            or rough.shape != (mesh.n_vertices,):
        raise ValueError("intrinsic_smoothing: C must be (#F, 3), mass and rough (#V,), phase (#E, 2)")
    _threads()
    return _core.intrinsic_smoothing(mesh.V, mesh.F, _i32(mesh.edges), _i32(mesh.edge_faces),
                                     _i8(mesh.edge_local_index), C, mass, phase, rough, X, float(radius),
                                     float(per_radius), float(pilot_radius), float(pilot_rtol), float(gain),
                                     float(power), float(bounds[0]), float(bounds[1]), int(steps),
                                     [float(c) for c in coefficients], float(rtol), int(maxiter))


def dropin_small(V, F, N, cot, checks, smoothing, binom):
    """The whole drop-in on a small mesh in one call (``_core/small_mesh.cpp``; the caller,
    :func:`igl_hhj.small_mesh.try_dropin`, checks the arrays and passes the constants).
    Returns ``(status, PD1, PD2, PV1, PV2, bad)``, status 0 when the compiled path applies.
    Single-threaded by construction: no thread policy to apply."""
    return _core.dropin_small(V, F, N, cot, checks, smoothing, binom)
