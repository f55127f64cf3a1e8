"""How many CG iterations the smoothing would take with other preconditioners.

The drop-in's smoothing solves ``(M + L_t) dY = -L_t Y`` with a Jacobi-preconditioned CG
(:func:`igl_hhj.kernels.intrinsic_smoothing`); on sliver-rich real meshes it takes 100-500
iterations over its five solves (beetle: 496 at radius 5), 60 % of the call.  This study
builds the scalar (h) system of the final smoothing exactly as the drop-in does (recovery,
pilot, adaptive per-face radius: the library's own functions) and counts the iterations of
one solve, to the drop-in's tolerance, with

* ``jacobi``: today's preconditioner (a scalar per vertex);
* ``sgs``: symmetric Gauss-Seidel in the vertex order (two triangular sweeps);
* ``sa``: one V-cycle of smoothed-aggregation AMG (``pyamg``, optional: the column is
  empty without it), with its set-up time in Python.

It prints iteration counts, not seconds of a compiled implementation: an AMG V-cycle costs
several sweeps of the matrix, and its aggregation must keep the exact invariances of the
vertex stage (:mod:`igl_hhj.intrinsic`: a relabelling of the vertices must not change the
iterates, which a greedy aggregation in vertex order does).  Run::

    python -m igl_hhj.benchmarks.smoothing_preconditioners --meshes DIR [--radius 5]
"""
from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np
import scipy.sparse as sp

MESHES = ("beetle.off", "camelhead.off", "bunny.off", "fandisk.off", "screwdriver.off", "cheburashka.off")
"""The meshes of :func:`study` (those present in the mesh folder)."""


def smoothing_system(V, F, radius=5):
    """The scalar system of the drop-in's final smoothing and its first right-hand side.

    Returns ``(A, b, info)``: A (#V, #V) scipy CSR ``M + L_t`` (lumped mass of
    :func:`igl_hhj.recovery.smoothing_coefficients` plus the cotangent stiffness at the
    adaptive per-face times), b (#V,) ``-L_t h`` of the recovered mean curvature h, and
    ``info`` with the drop-in's own smoothing iteration count (all solves, h and z)."""
    import igl_hhj
    from igl_hhj import intrinsic, kernels
    from igl_hhj.mesh import as_mesh
    from igl_hhj.recovery import QUALITY_FLOOR, smoothing_coefficients
    from igl_hhj.solvers import DEFAULT_RTOL
    mesh = as_mesh(V, F)
    S = igl_hhj.shape_operator(V, F)
    N = mesh.vertex_normals
    w = kernels.recovery_weights(mesh, QUALITY_FLOOR)
    X, rough = kernels.intrinsic_patch_recovery(mesh, S, N, w)
    C0, mass = smoothing_coefficients(mesh, w)
    phase = kernels.transport_phases(mesh, N)
    status, its, _, r = intrinsic.adaptive_smoothing(mesh, X.copy(), C0, mass, phase, rough, radius, DEFAULT_RTOL)
    C = C0 * intrinsic.smoothing_times(mesh, r)[:, None]
    e1, e2 = intrinsic.vertex_frames(N)
    L, _ = intrinsic.connection_laplacians(mesh, C, intrinsic.transport_phases(mesh, N, e1, e2))
    A = (sp.diags(mass) + L).tocsr()
    return A, -(L @ X[:, 0]), {"dropin_iterations": int(its), "status": int(status),
                               "rtol": intrinsic.smoothing_rtol(DEFAULT_RTOL)}


def pcg_iterations(A, b, precondition, rtol, maxiter=5000):
    """Iterations of CG on ``A x = b`` preconditioned by ``precondition(r)`` until
    ``‖r‖ ≤ rtol ‖b‖`` (maxiter if never)."""
    x = np.zeros_like(b)
    r = b.copy()
    z = precondition(r)
    p = z.copy()
    rz = r @ z
    nb = np.linalg.norm(b)
    for k in range(maxiter):
        q = A @ p
        alpha = rz / (p @ q)
        x += alpha * p
        r -= alpha * q
        if np.linalg.norm(r) <= rtol * nb:
            return k + 1
        z = precondition(r)
        rz_new = r @ z
        p = z + (rz_new / rz) * p
        rz = rz_new
    return maxiter


def preconditioners(A):
    """``{name: (apply, set-up seconds)}``: Jacobi, symmetric Gauss-Seidel, and a
    smoothed-aggregation V-cycle when ``pyamg`` is installed."""
    from scipy.sparse.linalg import spsolve_triangular
    d = A.diagonal()
    lower, upper = sp.tril(A, format="csr"), sp.triu(A, format="csr")
    out = {"jacobi": (lambda r: r / d, 0.0),
           "sgs": (lambda r: spsolve_triangular(upper, d * spsolve_triangular(lower, r, lower=True),
                                                lower=False), 0.0)}
    try:
        import pyamg
    except ImportError:
        return out
    t = time.perf_counter()
    ml = pyamg.smoothed_aggregation_solver(A, symmetry="symmetric", max_coarse=300)
    setup = time.perf_counter() - t
    M = ml.aspreconditioner(cycle="V")
    out["sa"] = (lambda r: M @ r, setup)
    return out


def study(mesh_dir, radius=5):
    """Rows ``{mesh, vertices, dropin_iterations, jacobi, sgs, sa, sa_setup_ms}`` for the
    :data:`MESHES` in ``mesh_dir`` (``sa`` None without pyamg)."""
    import igl
    rows = []
    for name in MESHES:
        path = Path(mesh_dir) / name
        if not path.is_file():
            continue
        V, F = igl.read_triangle_mesh(str(path))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")           # unwelded seams of some tutorial meshes
            A, b, info = smoothing_system(V, F, radius)
        row = {"mesh": name, "vertices": A.shape[0], "dropin_iterations": info["dropin_iterations"],
               "sa": None, "sa_setup_ms": None}
        for key, (apply, setup) in preconditioners(A).items():
            row[key] = pcg_iterations(A, b, apply, info["rtol"])
            if key == "sa":
                row["sa_setup_ms"] = 1e3 * setup
        rows.append(row)
    return rows


def markdown(rows, radius=5):
    lines = [f"| mesh | #V | drop-in smoothing its (5 solves, h and z) | one h solve: Jacobi | SGS | "
             f"SA V-cycle (pyamg) | SA set-up ms (Python) |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        sa = "–" if r["sa"] is None else str(r["sa"])
        setup = "–" if r["sa_setup_ms"] is None else f"{r['sa_setup_ms']:.1f}"
        lines.append(f"| {r['mesh']} | {r['vertices']:,} | {r['dropin_iterations']} | {r['jacobi']} | "
                     f"{r['sgs']} | {sa} | {setup} |")
    return f"radius {radius}\n\n" + "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--meshes", required=True, help="folder with the meshes (e.g. libigl's tutorial data)")
    p.add_argument("--radius", type=int, default=5)
    a = p.parse_args(argv)
    print(markdown(study(a.meshes, a.radius), a.radius))


if __name__ == "__main__":
    main()
