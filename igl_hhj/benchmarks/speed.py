"""Speed of the drop-in ``igl_hhj.principal_curvature`` against ``igl.principal_curvature``,
measured in the same run.

    python -m igl_hhj.benchmarks.speed [--quick] [--repeat 3] [--meshes DIR] [--out DIR] [--radii 2]
    python -m igl_hhj.benchmarks.speed --only-real --meshes libigl-tutorial-data --min-faces 5000
    python -m igl_hhj.benchmarks.speed --rtol-study | --sliver-study | --factor-study | --tiny | --features \
        | --profile 'icosphere(8)'

Meshes: icosphere(7) (328k faces) and icosphere(8) (1.31M), a jittered ellipsoid at
82k / 328k / 1.31M faces (linear-scaling check), Walker's torus from a perturbed grid
with random diagonals (6° slivers, 262k faces), every mesh in ``../shared/data/meshes``
(``--meshes``) plus the bunny refined twice by ``igl.upsample``, and an open scan-like
height field (jittered grid with random diagonals cropped to a disc, 5° slivers).

For each mesh it prints: the smallest angle; the best-of-``--repeat`` wall time of
``igl.principal_curvature`` (default 5-ring quadric fit) and of the drop-in; the ratio
``t_libigl / t_drop-in`` (> 1: igl_hhj is faster), also at radius 2 (``--radii``: both
called with ``radius=r``); µs per face; the time of
``igl_hhj.shape_operator`` with ``solver="direct"``, ``"cg"`` and ``"auto"`` (auto must
never be slower than both); what "auto" chose and its PCG iterations; the peak memory of
one drop-in call above the input (KB per face, in a fresh subprocess after warm-up calls
on three small meshes that take every solver path: the peak resident size ``VmHWM``, reset just before the call, minus the
resident size before it), how much slower
the first call in a fresh process is than the best later one, and the time of
``from igl_hhj import principal_curvature`` there (which imports what the call needs),
both as the median over ``--fresh`` fresh processes (default 3).  Writes ``speed.md`` to
``--out``.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from . import progress as progress_bar

# the direct column is skipped above this many faces (fill, minutes of factorisation)
DIRECT_MAX_FACES = 400_000
QUICK = ("icosphere(4)", "ellipsoid 20k", "open scan 5k")
FULL = ("icosphere(7)", "icosphere(8)", "ellipsoid 82k", "ellipsoid 328k", "ellipsoid 1.31M",
        "torus 262k", "open scan 51k", "bunny upsampled ×2", "real")


def _default_mesh_dir():
    for base in (Path.cwd(), Path(__file__).resolve().parents[2]):
        d = base.parent / "shared" / "data" / "meshes"
        if d.is_dir():
            return d
    return None


def _open_scan(n):
    """Open scan-like height field: WalkerSaddle over a jittered grid with random
    diagonals, cropped to a disc (irregular boundary, 5° slivers)."""
    from ..surfaces import WalkerSaddle, square_grid
    P, F = square_grid(n, amount=0.42, seed=7)
    c = P[F].mean(axis=1) - 0.5
    F = F[(c ** 2).sum(axis=1) < 0.24]
    used = np.unique(F)
    remap = -np.ones(len(P), dtype=np.int64)
    remap[used] = np.arange(len(used))
    return WalkerSaddle().lift(P[used]), remap[F]


def _ellipsoid(faces):
    from ..surfaces import Ellipsoid, ellipsoid_coarse, refine
    ell = Ellipsoid()
    V, F = ellipsoid_coarse(ell, subdivisions=3, amount=0.2)          # 1280 faces
    while len(F) < faces:
        V, F = refine(V, F, ell, 1)
    return V, F


def _build(name, mesh_dir, min_faces=0):
    """[(label, V, F)] for one entry of QUICK / FULL ("real": every ``*.off`` and ``*.obj``
    of ``mesh_dir`` with at least ``min_faces`` faces, e.g. libigl's tutorial data)."""
    import igl
    from ..surfaces import WalkerTorus, icosphere, refine, torus_coarse
    if name.startswith("icosphere("):
        V, F = icosphere(int(name[10:-1]))
        return [(name, V, F)]
    if name.startswith("ellipsoid"):
        target = {"20k": 20_000, "82k": 80_000, "328k": 320_000, "1.31M": 1_300_000}[name.split()[1]]
        return [(f"jittered ellipsoid", *_ellipsoid(target))]
    if name == "torus 262k":
        V, F = torus_coarse(n_phi=32, n_t=16, amount=0.25)
        return [("Walker torus (sliver grid)", *refine(V, F, WalkerTorus(), 4))]
    if name.startswith("open scan"):
        n = 36 if name.endswith("5k") else 160
        return [("open scan-like height field", *_open_scan(n))]
    if mesh_dir is None:
        return []
    if name == "bunny upsampled ×2":
        p = mesh_dir / "bunny.off"
        if not p.exists():
            return []
        V, F = igl.read_triangle_mesh(str(p))
        return [(name, *igl.upsample(V, F, 2))]
    if (mesh_dir / name).is_file():              # one mesh of the folder, e.g. camelhead.off
        V, F = igl.read_triangle_mesh(str(mesh_dir / name))
        return [(name, V, F)]
    if name == "real":
        out = []
        for p in sorted([*mesh_dir.glob("*.off"), *mesh_dir.glob("*.obj")]):
            V, F = igl.read_triangle_mesh(str(p))
            if len(F) >= min_faces:
                out.append((p.name, V, F))
        return out
    raise KeyError(name)


def min_angle_degrees(V, F):
    """Smallest interior angle of the mesh in degrees."""
    X = V[F]
    l = np.linalg.norm(X[:, [2, 0, 1]] - X[:, [1, 2, 0]], axis=2)
    dbl = np.linalg.norm(np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]), axis=1)
    s = dbl * l.min(axis=1) / l.prod(axis=1)
    return float(np.degrees(np.arcsin(np.clip(s.min(), 0, 1))))


def _best(fn, repeat):
    best = np.inf
    out = None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


_CHILD_TIME = r"""
import json, sys, time
import numpy as np
t = time.perf_counter(); import igl_hhj; from igl_hhj import principal_curvature; t_import = time.perf_counter() - t
d = np.load(sys.argv[1]); V, F = d["V"], d["F"]
t = time.perf_counter(); igl_hhj.principal_curvature(V, F); first = time.perf_counter() - t
later = float("inf")
for _ in range(int(sys.argv[2])):
    t = time.perf_counter(); igl_hhj.principal_curvature(V, F); later = min(later, time.perf_counter() - t)
print(json.dumps({"import": t_import, "first": first, "later": later}))
"""

# Peak RSS from /proc/self/status VmHWM, reset to the current RSS just before the call
# (writing 5 to /proc/self/clear_refs); ru_maxrss would include the parent's RSS at fork.
_CHILD_MEMORY = r"""
import json, sys
import numpy as np
import igl_hhj
from igl_hhj.benchmarks.speed import _open_scan
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially
# imports and one-time set-up (library code paged in) of every path a call may take:
# plain PCG, the two-level sliver solve (a jittered icosphere(4)), boundary estimation
# and the direct solve (the 5k open scan)
igl_hhj.principal_curvature(*icosphere(2))
v, f = icosphere(4)
igl_hhj.principal_curvature(jitter_tangentially(v, f, Sphere(), 0.45, seed=7), f)
igl_hhj.principal_curvature(*_open_scan(36))
d = np.load(sys.argv[1]); V, F = d["V"], d["F"]
def status(key):
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(key):
                return int(line.split()[1]) * 1024
base = status("VmRSS:")
with open("/proc/self/clear_refs", "w") as fh:
    fh.write("5")
igl_hhj.principal_curvature(V, F)
print(json.dumps({"peak": status("VmHWM:") - base}))
"""


def _child_measure(V, F, repeat, fresh=3):
    """In ``fresh`` fresh processes: import time, first-call and best later time of the
    drop-in, summarised by the median over the processes of ``first / later`` and of the
    import time (one process alone scatters: 1.17-1.92 on fandisk in 8 runs); in one more,
    the peak resident memory of one call above the input (after warm-up calls on three
    small meshes covering every solver path, so that imports and library code paged in
    once are not counted)."""
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "mesh.npz")
        np.savez(path, V=np.ascontiguousarray(V, dtype=np.float64), F=np.ascontiguousarray(F, dtype=np.int64))

        def child(code):
            res = subprocess.run([sys.executable, "-c", code, path, str(max(1, repeat))],
                                 capture_output=True, text=True, check=True)
            return json.loads(res.stdout.strip().splitlines()[-1])
        runs = [child(_CHILD_TIME) for _ in range(max(1, fresh))]
        out = child(_CHILD_MEMORY)
    ratios = [r["first"] / r["later"] for r in runs]
    out.update(first_over_later=float(np.median(ratios)), first_over_later_runs=ratios,
               import_=float(np.median([r["import"] for r in runs])), fresh=len(runs))
    out["import"] = out.pop("import_")
    return out


def run(names=FULL, repeat=3, mesh_dir=None, progress=True, memory=True, fresh=3, radii=(2,),
        min_faces=0):
    """Time libigl and igl_hhj on the named meshes (entries of :data:`FULL` / :data:`QUICK`).

    Both at radius 5 (the defaults: ``libigl``, ``dropin``), and at every radius of
    ``radii`` (``libigl_r2``, ``dropin_r2``, ...: ``radius=r`` passed to both).

    Returns
    -------
    list of dict rows (seconds, counts, KB/face).
    """
    import igl

    import igl_hhj
    from igl_hhj.curvature import _shape_operator
    from igl_hhj.mesh import MeshDefectError, TriangleMesh
    mesh_dir = _default_mesh_dir() if mesh_dir is None else Path(mesh_dir)
    meshes = [m for n in names for m in _build(n, mesh_dir, min_faces)]
    rows = []
    for label, V, F in progress_bar(meshes, "speed", "mesh", progress):
        nF = len(F)
        rep = repeat if nF < 1_000_000 else max(1, repeat - 1)
        row = {"mesh": label, "faces": nF, "min_angle": min_angle_degrees(V, F)}
        row["libigl"], _ = _best(lambda: igl.principal_curvature(V, F), rep)
        row["dropin"], _ = _best(lambda: igl_hhj.principal_curvature(V, F), rep)
        for r in radii:
            row[f"libigl_r{r}"], _ = _best(lambda: igl.principal_curvature(V, F, r), rep)
            row[f"dropin_r{r}"], _ = _best(lambda: igl_hhj.principal_curvature(V, F, r), rep)
        for s in ("direct", "cg", "auto"):
            if s == "direct" and nF > DIRECT_MAX_FACES:
                row["S_direct"] = float("nan")
                continue
            try:
                row[f"S_{s}"], _ = _best(lambda: igl_hhj.shape_operator(V, F, solver=s), rep)
            except (igl_hhj.SolverError, MeshDefectError):
                # shape_operator takes manifold meshes only (the drop-in repairs the rest)
                row[f"S_{s}"] = float("nan")
        info = {}
        try:
            _shape_operator(TriangleMesh(V, F), None, None, None, "auto", info=info)
        except MeshDefectError:
            info = {"solver": "– (non-manifold: repaired by the drop-in)", "iterations": "–"}
        row["chosen"] = info["solver"] + (" (switched)" if info.get("switched") else "")
        row["iterations"] = info["iterations"]
        row["sliver_dofs"] = info.get("sliver_dofs", 0)
        if memory:
            child = _child_measure(V, F, min(rep, 2), fresh=fresh)
            row["kb_per_face"] = child["peak"] / 1024 / nF
            row["first_over_later"] = child["first_over_later"]
            row["first_over_later_runs"] = child["first_over_later_runs"]
            row["import"] = child["import"]
        rows.append(row)
    return rows


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


def _radii_of(rows):
    """The extra radii timed in ``rows`` (keys ``libigl_r<r>``), ascending."""
    return sorted({int(k[8:]) for r in rows for k in r if k.startswith("libigl_r")})


def markdown(rows):
    radii = _radii_of(rows)
    head = ["mesh", "faces", "min angle", "libigl (s)", "drop-in (s)", "ratio",
            *[f"ratio r{r} (libigl / drop-in s)" for r in radii], "µs/face",
            "S_h direct (s)", "S_h cg (s)", "S_h auto (s)", "auto chose", "PCG its",
            "peak KB/face", "1st call / later", "import (s)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    f3 = lambda x: "–" if not np.isfinite(x) else f"{x:.3f}"  # noqa: E731
    for r in rows:
        at = [f"**{r[f'libigl_r{q}'] / r[f'dropin_r{q}']:.2f}×** ({f3(r[f'libigl_r{q}'])} / "
              f"{f3(r[f'dropin_r{q}'])})" if f"libigl_r{q}" in r else "–" for q in radii]
        cells = [r["mesh"], f"{r['faces']:,}", f"{r['min_angle']:.2f}°", f3(r["libigl"]),
                 f3(r["dropin"]), f"**{r['libigl'] / r['dropin']:.2f}×**", *at,
                 f"{1e6 * r['dropin'] / r['faces']:.2f}", f3(r["S_direct"]), f3(r["S_cg"]),
                 f3(r["S_auto"]), r["chosen"], str(r["iterations"]),
                 f"{r['kb_per_face']:.2f}" if "kb_per_face" in r else "–",
                 f"{r['first_over_later']:.2f}" if "first_over_later" in r else "–",
                 f"{r['import']:.2f}" if "import" in r else "–"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


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
    """Fixed cost per call on meshes under 1,000 faces (issue 24: ≤ 2× libigl's time).

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
    """Cost of sharp-feature handling (issue 27: ≤ 1.3× the drop-in without it).

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


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="three small meshes (seconds)")
    p.add_argument("--repeat", type=int, default=3, help="best of N runs per timing")
    p.add_argument("--meshes", default=None, help="folder of real meshes (default ../shared/data/meshes)")
    p.add_argument("--min-faces", type=int, default=0,
                   help="real meshes: only those with at least this many faces (libigl's tutorial "
                        "data: 5000)")
    p.add_argument("--radii", type=int, nargs="*", default=[2],
                   help="radii timed besides 5 (both libigl and the drop-in; default: 2)")
    p.add_argument("--only-real", action="store_true", help="only the real meshes of --meshes")
    p.add_argument("--no-memory", action="store_true", help="skip the fresh-process columns")
    p.add_argument("--fresh", type=int, default=3,
                   help="fresh processes per mesh for the first-call and import columns (median)")
    p.add_argument("--out", default="benchmark-results",
                   help="folder for speed.md (default ./benchmark-results/)")
    p.add_argument("--sliver-study", action="store_true",
                   help="only PCG iterations / CPU time against the sliver threshold")
    p.add_argument("--factor-study", action="store_true",
                   help="only factorisation / solve times of the HHJ matrix: QDLDL, CHOLMOD, SuperLU")
    p.add_argument("--profile", default=None, metavar="MESH",
                   help="only the wall time, iterations and page faults of each stage of the default "
                        "drop-in on one mesh, e.g. 'icosphere(8)'")
    p.add_argument("--radius", type=int, default=5, help="--profile: the drop-in's radius")
    p.add_argument("--rtol-study", action="store_true",
                   help="only the tolerance study (PCG iterations and error vs rtol)")
    p.add_argument("--tiny", action="store_true",
                   help="only the fixed cost per call on meshes under 1,000 faces (median of interleaved calls)")
    p.add_argument("--features", action="store_true",
                   help="only the cost of feature_angle=40 against the plain drop-in (fandisk, screwdriver)")
    a = p.parse_args(argv)
    if a.features:
        print(feature_markdown(feature_study(mesh_dir=a.meshes)))
        return
    if a.tiny:
        print(tiny_markdown(tiny_study()))
        return
    if a.sliver_study:
        rows = sliver_study(mesh_dir=a.meshes)
        lines = ["| mesh | faces | sliver angle | sliver DOFs | PCG its | CPU s |", "|---|---|---|---|---|---|"]
        lines += [f"| {r['mesh']} | {r['faces']:,} | {r['angle']}° | {100 * r['fraction']:.0f} % | "
                  f"{r['iterations']} | {r['seconds']:.3f} |" for r in rows]
        print("\n".join(lines))
        return
    if a.factor_study:
        print(factor_markdown(factor_study(mesh_dir=a.meshes, repeat=a.repeat)))
        return
    if a.profile:
        V, F = _build(a.profile, _default_mesh_dir() if a.meshes is None else Path(a.meshes))[0][1:]
        prof = profile_stages(V, F, radius=a.radius)
        above = prof.pop("x above floor")
        for k, v in prof.items():
            extra = f"   ({above[k]:.1f}x above floor)" if k in above else ""
            print(f"{k}: {v:.4f}{extra}" if isinstance(v, float) else f"{k}: {v}")
        return
    if a.rtol_study:
        table = rtol_markdown(rtol_study())
        print(table)
        out = Path(a.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "speed_rtol.md").write_text(table + "\n")
        return
    names = QUICK if a.quick else ("real",) if a.only_real else FULL
    rows = run(names, a.repeat, a.meshes, memory=not a.no_memory, fresh=a.fresh,
               radii=tuple(r for r in a.radii if r != 5), min_faces=a.min_faces)
    table = markdown(rows)
    import importlib.metadata
    import platform

    from igl_hhj import kernels
    imp = f"import igl_hhj {rows[0]['import']:.2f} s (fresh process); " if rows and "import" in rows[0] else ""
    header = (f"# igl_hhj drop-in speed vs igl.principal_curvature (same run)\n\n"
              f"libigl {importlib.metadata.version('libigl')}, numpy {np.__version__}, "
              f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
              f"{kernels.max_threads()} OpenMP threads, best of {a.repeat}; {imp}"
              f"load average at the end {os.getloadavg()[0]:.1f}.\n\n")
    print(header + table)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "speed.md").write_text(header + table + "\n")
    (out / "speed.json").write_text(json.dumps(rows, indent=1))
    print(f"\nwrote {out / 'speed.md'}")


if __name__ == "__main__":
    main()
