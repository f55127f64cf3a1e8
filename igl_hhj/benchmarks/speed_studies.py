"""The studies of ``python -m igl_hhj.benchmarks.speed`` beside its main table: the PCG
tolerance (``--rtol-study``), slivers (``--sliver-study``), the direct factorisations
(``--factor-study``), the stages of one call (``--profile``), tiny meshes (``--tiny``) and
sharp features (``--features``)."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from .speed_meshes import _best, _build, _default_mesh_dir, _ellipsoid

RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-12)


def rtol_study(faces=(20_000, 80_000, 320_000, 1_300_000), rtols=RTOLS, torus_levels=3, radius=5):
    """How the PCG tolerance shows in the drop-in's vertex mean curvature.

    Jittered ellipsoids (exact principal curvatures known; the finer the mesh, the smaller
    the discretisation error) and Walker's sliver torus, through the drop-in's path (HHJ
    solve by PCG at ``rtol``, patch recovery, smoothing at ``radius``).  For each ``rtol``:
    PCG iterations, the L2 vertex error of H = (κ1+κ2)/2 against the exact surface, its
    relative change against rtol = 1e-12, and the solver's own share: the L2 deviation of
    H from the rtol = 1e-12 result divided by that result's error (the discretisation
    error).  A tolerance is tied to the discretisation error when this ratio stays small
    on the finest mesh.

    Returns
    -------
    list of dict rows: ``mesh, faces, rtol, iterations, err_H, change, deviation``.
    """
    from igl_hhj.convergence import vertex_errors
    from igl_hhj.curvature import _shape_operator, vertex_principal_curvature, vertex_shape_operator
    from igl_hhj.mesh import TriangleMesh
    from ..surfaces import Ellipsoid, WalkerTorus, refine, torus_coarse
    cases = [("jittered ellipsoid", Ellipsoid(), *_ellipsoid(n)) for n in faces]
    V, F = torus_coarse(n_phi=32, n_t=16, amount=0.25)
    cases.append(("Walker torus (sliver grid)", WalkerTorus(), *refine(V, F, WalkerTorus(), torus_levels)))
    rows = []
    for label, surface, V, F in cases:
        m = TriangleMesh(V, F)
        w = m.sum_corners_to_vertices(np.broadcast_to(m.face_areas[:, None] / 3, (m.n_faces, 3)))
        out = {}
        for rtol in rtols:
            info = {}
            S = _shape_operator(m, None, None, None, "cg", rtol, info)
            Sv, N = vertex_shape_operator(m, S, smoothing=radius)
            _, _, PV1, PV2 = vertex_principal_curvature(m, Sv, N)
            out[rtol] = (vertex_errors(m, None, PV1, PV2, surface)["H"], info["iterations"], 0.5 * (PV1 + PV2))
        ref_err, _, ref_H = out[min(rtols)]
        for rtol in rtols:
            e, it, H = out[rtol]
            dev = float(np.sqrt(np.sum(w * (H - ref_H) ** 2)))
            rows.append({"mesh": label, "faces": len(F), "rtol": rtol, "iterations": it,
                         "err_H": e, "change": abs(e - ref_err) / ref_err, "deviation": dev / ref_err})
    return rows


def rtol_markdown(rows):
    lines = ["| mesh | faces | rtol | PCG its | L2 error of H at vertices | change vs rtol 1e-12 "
             "| deviation from rtol 1e-12 / error |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['mesh']} | {r['faces']:,} | {r['rtol']:.0e} | {r['iterations']} | "
                     f"{r['err_H']:.4e} | {100 * r['change']:.4f} % | {100 * r['deviation']:.4f} % |")
    return "\n".join(lines)


SLIVER_ANGLES = (0, 5, 10, 15, 20, 25, 30)
SLIVER_MESHES = ("camelhead.off", "bunny upsampled ×2", "open scan-like height field", "jittered ellipsoid")


def sliver_study(angles=SLIVER_ANGLES, mesh_dir=None, rtol=1e-8):
    """PCG iterations and CPU time of the compiled solve against the sliver threshold
    of the two-level preconditioner (0 = face-Schwarz alone), single thread."""
    from igl_hhj import kernels, solvers
    from igl_hhj.mesh import TriangleMesh
    mesh_dir = _default_mesh_dir() if mesh_dir is None else Path(mesh_dir)
    meshes = [m for n in ("real", "bunny upsampled ×2", "open scan 51k", "ellipsoid 328k")
              for m in _build(n, mesh_dir) if m[0] in SLIVER_MESHES]
    old, threads = solvers.SLIVER_ANGLE, kernels.max_threads()
    rows = []
    try:
        kernels.set_num_threads(1)
        for label, V, F in meshes:
            m = TriangleMesh(V, F)
            rhs = -kernels.jump_apply(m, m.V)
            system = solvers.HHJSystem(m)
            for a in angles:
                solvers.SLIVER_ANGLE = a
                t = time.process_time()
                _, info = system.solve(rhs, "cg", rtol)
                rows.append({"mesh": label, "faces": len(F), "angle": a, "seconds": time.process_time() - t,
                             "iterations": info["iterations"],
                             "fraction": info.get("sliver_dofs", 0) / system.n})
    finally:
        solvers.SLIVER_ANGLE = old
        kernels.set_num_threads(threads)
    return rows


FACTOR_MESHES = ("real", "open scan 51k", "ellipsoid 82k", "bunny upsampled ×2", "torus 262k")


def factor_study(names=FACTOR_MESHES, mesh_dir=None, repeat=2, k=3):
    """Factorisation and k-column solve times (s) of the HHJ matrix A and of its sliver
    block A_SS (the two-level's subdomain) with each direct solver :mod:`igl_hhj.solvers`
    can use: QDLDL (AMD + LDLᵀ), CHOLMOD (cholespy) and SuperLU (symmetric mode,
    minimum degree), in the same run; picks :data:`igl_hhj.solvers.LDL_MAX`."""
    import scipy.sparse.linalg as spla

    from igl_hhj import solvers
    from igl_hhj.mesh import TriangleMesh
    mesh_dir = _default_mesh_dir() if mesh_dir is None else Path(mesh_dir)

    def superlu(A):
        lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
        return lu.solve
    makers = {"qdldl": solvers._ldl, "cholmod": solvers._cholmod, "superlu": superlu}
    rows = []
    for name in names:
        for label, V, F in _build(name, mesh_dir):
            system = solvers.HHJSystem(TriangleMesh(V, F))
            A = system.csr()
            S = system.sliver_dofs()
            for part, M in (("A", A), ("A_SS", A[S][:, S].tocsr())):
                R = np.random.default_rng(0).normal(size=(M.shape[0], k))
                row = {"mesh": label, "part": part, "n": M.shape[0]}
                for key, make in makers.items():
                    t_f, solve = _best(lambda: make(M), repeat)
                    t_s, _ = _best(lambda: solve(R), repeat)
                    row[key] = (t_f, t_s)
                rows.append(row)
    return rows


def factor_markdown(rows):
    lines = ["| mesh | matrix | unknowns | QDLDL factor + solve (ms) | CHOLMOD | SuperLU-MMD |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        cells = [f"{1e3 * r[k][0]:.1f} + {1e3 * r[k][1]:.2f}" for k in ("qdldl", "cholmod", "superlu")]
        lines.append(f"| {r['mesh']} | {r['part']} | {r['n']:,} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def copy_bandwidth(megabytes=256):
    """This machine's memory bandwidth in bytes/s, measured now: the best of 3 copies of a
    ``megabytes`` float64 array (bytes read + written / time)."""
    a = np.ones(megabytes * (1 << 20) // 8)
    b = np.empty_like(a)
    best, _ = _best(lambda: np.copyto(b, a), 3)
    return 2 * a.nbytes / best


def _nbytes(*objs):
    """Bytes of the numpy arrays among ``objs`` (nested in tuples/lists/dicts)."""
    total = 0
    for o in objs:
        if isinstance(o, np.ndarray):
            total += o.nbytes
        elif isinstance(o, (tuple, list)):
            total += _nbytes(*o)
        elif isinstance(o, dict):
            total += _nbytes(*o.values())
    return total


def profile_stages(V, F, rtol=None, radius=5):
    """Wall seconds (default threads), minor page faults and distance from the memory
    bandwidth floor of the default drop-in's stages on one mesh, in the drop-in's order:
    validation + topology, estimated boundary normals (open meshes), HHJ assembly, load,
    the ``auto`` solve (its iterations), S_h, vertex normals, reliability weights,
    intrinsic patch recovery, smoothing coefficients, transport phases, the smoothing
    (pilot step, adaptive radius, twiced smoothing: one compiled call, its Jacobi-CG
    iterations), principal values (κ = H ± |z|).

    ``floor[stage]``: the bytes of the stage's input and output arrays (each read or
    written once: a lower bound of its memory traffic; iterative stages count one pass
    per iteration) over :func:`copy_bandwidth` — ``seconds / floor`` is how far the stage
    is above what streaming its data once would cost.  A warm-up call runs first; the
    stages run inside :func:`igl_hhj.kernels.large_call_heap`, as the drop-in does."""
    import resource

    from igl_hhj import intrinsic, kernels, principal_curvature, recovery, solvers
    from igl_hhj.boundary_estimation import estimate_boundary_normals
    from igl_hhj.mesh import TriangleMesh
    principal_curvature(V, F, radius)              # warm-up: imports, first-touch of the heap
    bandwidth = copy_bandwidth()
    out, faults, floor = {}, {}, {}

    def stage(name, fn, inputs=()):
        f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        t = time.perf_counter()
        r = fn()
        out[name] = time.perf_counter() - t
        faults[name] = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0
        floor[name] = _nbytes(inputs, r) / bandwidth
        return r
    rtol = rtol or solvers.DEFAULT_RTOL
    Vf, Fi = np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(F, dtype=np.int64)
    # the public entry points run inside the large-call heap scope: so do the stages
    with kernels.large_call_heap(len(F)) as heap:
        m = stage("validation + topology", lambda: TriangleMesh(Vf, Fi), (Vf, Fi))
        topo = (m.edges, m.face_edges, m.edge_faces, m.edge_local_index)
        floor["validation + topology"] += _nbytes(topo) / bandwidth
        if m.has_boundary:
            stage("boundary normals (estimate)", lambda: estimate_boundary_normals(m), (Vf,))
        system = stage("HHJ assembly + preconditioner", lambda: solvers.HHJSystem(m), (Vf, Fi, topo))
        floor["HHJ assembly + preconditioner"] += _nbytes(system.A, system.M, system.cols) / bandwidth
        rhs = stage("load -B X", lambda: -kernels.jump_apply(m, m.V), (Vf, Fi, topo))
        s, info = stage("HHJ solve (auto)", lambda: system.solve(rhs, "auto", rtol), (rhs,))
        # per PCG iteration: the matrix and the preconditioner rows, ~6 (#E, 3) vectors
        floor["HHJ solve (auto)"] = max(1, info["iterations"]) * _nbytes(
            system.A, system.M, system.cols, rhs, rhs, rhs, rhs, rhs, rhs) / bandwidth
        S = stage("S_h", lambda: kernels.shape_operator_faces(m, s), (Vf, Fi, m.face_edges, s))
        N = stage("vertex normals", lambda: m.vertex_normals, (Vf, Fi))
        w = stage("reliability weights", lambda: kernels.recovery_weights(m, recovery.QUALITY_FLOOR),
                  (Vf, Fi, m.face_edges, m.edge_faces))
        X, rough = stage("intrinsic patch recovery", lambda: kernels.intrinsic_patch_recovery(m, S, N, w),
                         (Vf, Fi, S, N, w))
        C, mass = stage("smoothing coefficients", lambda: recovery.smoothing_coefficients(m, w), (Vf, Fi, w))
        phase = stage("transport phases", lambda: kernels.transport_phases(m, N), (N, m.edges))
        res = stage("smoothing (pilot + adaptive radius + twiced)", lambda: intrinsic.adaptive_smoothing(
            m, X, C, mass, phase, rough, radius, rtol), (Vf, Fi, C, mass, phase, rough, X))
        its = res[1]
        # per Jacobi-CG iteration: the Laplacian's edge weights and phases, ~6 (#V, 3) vectors
        floor["smoothing (pilot + adaptive radius + twiced)"] = max(1, its) * _nbytes(
            m.edges, phase, C, X, X, X, X, X, X) / bandwidth
        stage("principal values", lambda: kernels.principal_hz(X, N), (X, N))
    out["total of the stages"] = sum(out.values())
    out["floor of the stages"] = sum(floor.values())
    out["bandwidth GB/s"] = bandwidth / 1e9
    out["large-call heap scope"] = heap
    out["HHJ solver"] = info["solver"]
    out["HHJ PCG iterations"] = info["iterations"]
    out["smoothing iterations"] = its
    out["minor page faults"] = sum(faults.values())
    out["page faults per stage"] = faults
    out["x above floor"] = {k: out[k] / floor[k] for k in floor if floor[k] > 0}
    return out


def tiny_meshes():
    """The fixed-cost meshes of :func:`tiny_study`: ``[(name, V, F)]`` with 8-1,280 faces,
    closed and open (an octahedron, a cube, the icospheres 0-3, a coarse jittered torus, two
    open jittered grids of 18 and 128 faces)."""
    from ..surfaces import icosphere, square_grid, torus_coarse
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                  [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
    out = [("octahedron", *_octahedron()), ("cube", V, F)]
    out += [(f"icosphere({n})", *icosphere(n)) for n in range(4)]
    out.append(("torus 96", *torus_coarse(n_phi=8, n_t=6)))
    for n in (3, 8):
        P, Fg = square_grid(n, amount=0.3, seed=3)
        out.append((f"open grid {2 * n * n}", np.c_[P, 0.3 * P[:, 0] * P[:, 1]], Fg))
    return out


def _octahedron():
    V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return V, F


def _interleaved_ms(fns, calls, warmup, clock):
    """Median milliseconds of each of ``fns`` over ``calls`` interleaved rounds (f0, f1, …,
    f0, f1, …) after ``warmup`` rounds, timed with ``clock`` (a ``time`` function)."""
    for _ in range(warmup):
        for f in fns:
            f()
    t = np.empty((calls, len(fns)))
    for k in range(calls):
        for j, f in enumerate(fns):
            t0 = clock()
            f()
            t[k, j] = clock() - t0
    return np.median(t, axis=0) * 1e3


def tiny_study(calls=400):
    """Fixed cost per call on meshes under 1,000 faces (target: ≤ 2× libigl's time).

    Each mesh: the median over ``calls`` interleaved calls of ``igl.principal_curvature``
    and of the drop-in (radius 5, warm: the first calls are dropped).  Returns rows
    ``{mesh, faces, libigl_ms, hhj_ms, ratio}`` with ``ratio = t_hhj / t_libigl`` (the
    target is ≤ 2)."""
    import igl

    import igl_hhj
    rows = []
    for name, V, F in tiny_meshes():
        a, b = _interleaved_ms((lambda: igl.principal_curvature(V, F), lambda: igl_hhj.principal_curvature(V, F)),
                               calls, warmup=20, clock=time.perf_counter)
        rows.append({"mesh": name, "faces": len(F), "libigl_ms": a, "hhj_ms": b, "ratio": b / a})
    return rows


def tiny_markdown(rows):
    lines = ["| mesh | faces | libigl ms | igl_hhj ms | igl_hhj / libigl (target ≤ 2) |", "|---|---|---|---|---|"]
    lines += [f"| {r['mesh']} | {r['faces']} | {r['libigl_ms']:.3f} | {r['hhj_ms']:.3f} | {r['ratio']:.2f} |"
              for r in rows]
    return "\n".join(lines)


FEATURE_MESHES = ("fandisk.off", "screwdriver.off")
"""The meshes of :func:`feature_study` (those present in the mesh folder)."""


def feature_study(mesh_dir=None, calls=15, feature_angle=40):
    """Cost of sharp-feature handling (target: ≤ 1.3× the drop-in without it).

    For each of :data:`FEATURE_MESHES` found in ``mesh_dir`` (default ../shared/data/meshes):
    the median CPU time (``time.process_time``, one thread) over ``calls`` interleaved
    calls of ``igl_hhj.principal_curvature(V, F)`` and ``(V, F, feature_angle=...)``, after
    three warm-up calls of each.  Returns rows ``{mesh, faces, plain_ms, features_ms,
    ratio}``."""
    import igl

    import igl_hhj
    from .. import kernels
    mesh_dir = _default_mesh_dir() if mesh_dir is None else Path(mesh_dir)
    rows = []
    if mesh_dir is None:
        return rows
    nt = kernels.max_threads()
    kernels.set_num_threads(1)
    try:
        for name in FEATURE_MESHES:
            path = mesh_dir / name
            if not path.is_file():
                continue
            V, F = igl.read_triangle_mesh(str(path))
            a, b = _interleaved_ms((lambda: igl_hhj.principal_curvature(V, F),
                                    lambda: igl_hhj.principal_curvature(V, F, feature_angle=feature_angle)),
                                   calls, warmup=3, clock=time.process_time)
            rows.append({"mesh": name, "faces": len(F), "plain_ms": a, "features_ms": b, "ratio": b / a})
    finally:
        kernels.set_num_threads(nt)
    return rows


def feature_markdown(rows):
    lines = ["| mesh | faces | drop-in ms | with features ms | ratio (target ≤ 1.3) |", "|---|---|---|---|---|"]
    lines += [f"| {r['mesh']} | {r['faces']:,} | {r['plain_ms']:.1f} | {r['features_ms']:.1f} | {r['ratio']:.2f} |"
              for r in rows]
    return "\n".join(lines)
