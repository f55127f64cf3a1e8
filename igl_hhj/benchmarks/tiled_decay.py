"""How the cut of a tile changes the drop-in's values with the ring distance to it
(``python -m igl_hhj.benchmarks.tiled_decay [MESH ...]``).

Each mesh is cut at the median of its face centroids' x; the half is computed as a
tile (its cut keeps the smoothing's interior length, as :mod:`igl_hhj.tiled` does) and
compared with the whole mesh, per ring of distance to the cut.  Both run with direct
solves everywhere (:func:`exact_dropin`: the HHJ system factorised, every smoothing
solve by CHOLMOD), so that the differences are the cut's effect and not the iterative
solvers' tolerances (which put a floor of 1e-8–1e-6 under them even at ``rtol=1e-16``).
Per mesh: the HHJ decay (the change of S_h, in decades per ring), the ring from which
the change of the principal curvatures stays below ε = 1e-6 × max |κ|, and the overlap
rule's rings for the largest radius the vertex stage chose on the tile
(:func:`igl_hhj.tiled.reach.overlap_rings`).
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..tiled import reach

EPS = reach.DEFAULT_TOLERANCE
GENERATED = ("jittered ellipsoid 82k", "noisy ellipsoid 82k", "noisy ellipsoid 328k",
             "open scan 125k", "noisy open scan 125k", "jittered torus 200k")


def _spd_solve(A):
    from ..solvers import _cholmod
    solve = _cholmod(sp.csr_matrix(A))
    if solve is None:            # CHOLMOD finds it not numerically positive definite: LU
        import scipy.sparse.linalg as spla
        return spla.factorized(sp.csc_matrix(A))
    return lambda b: solve(np.ascontiguousarray(b, dtype=np.float64).reshape(len(b), -1)).reshape(b.shape)


def _smooth(mesh, X, N, w, times, steps, order, real_boundary):
    """:func:`igl_hhj.intrinsic.smooth` with ``times`` per face, the tile's stiffness
    (:func:`igl_hhj.tiled._compute._uncut_coefficients`) and CHOLMOD solves (the complex
    Hermitian system as its real symmetric double)."""
    from ..intrinsic import connection_laplacians, transport_phases, vertex_frames
    from ..recovery import kernel_coefficients, smoothing_coefficients
    from ..tiled._compute import _uncut_coefficients
    C, m = smoothing_coefficients(mesh, w)
    if real_boundary is not None and mesh.has_boundary:
        C = _uncut_coefficients(mesh, C, real_boundary)
    e1, e2 = vertex_frames(N)
    L, Lc = connection_laplacians(mesh, C * times[:, None], transport_phases(mesh, N, e1, e2))
    M = sp.diags(m)
    Ah = (M + L).tocsr()
    Az = M + Lc
    solve_h = _spd_solve(Ah)
    solve_z = _spd_solve(sp.bmat([[Az.real, -Az.imag], [Az.imag, Az.real]]))
    n = mesh.n_vertices
    h, z = X[:, 0].copy(), np.r_[X[:, 1], X[:, 2]]
    hs, zs = np.zeros_like(h), np.zeros_like(z)
    for c in kernel_coefficients(order):
        for _ in range(steps):
            h, z = solve_h(m * h), solve_z(np.r_[m, m] * z)
        hs += c * h
        zs += c * z
    out = np.stack([hs, zs[:n], zs[n:]], axis=1)
    out[~mesh.referenced_vertices] = 0.0
    return out


def exact_dropin(V, F, radius=5, real_boundary=None):
    """The drop-in with direct solves: ``(PV1, PV2, r (#F,), S_h)`` (NaN rows at bad vertices).

    The steps of :func:`igl_hhj.intrinsic.vertex_stage_reference` (recovery, pilot step,
    adaptive radius, twiced smoothing) with factorised solves; ``real_boundary`` as
    :func:`igl_hhj.tiled._compute.tile_values`."""
    import igl_hhj
    from .. import intrinsic as I
    from ..mesh import TriangleMesh, mark_bad_vertices
    from ..recovery import recovery_weights
    mesh = TriangleMesh(V, F)
    S = igl_hhj.shape_operator(mesh, solver="direct")
    N = mesh.vertex_normals
    w = recovery_weights(mesh)
    X = I.recover(mesh, S, N, w)
    rough = I.roughness(mesh, S, N, X, w)
    pilot = _smooth(mesh, X, N, w, I.smoothing_times(mesh, I.PILOT_RADIUS, 1), 1, 1, real_boundary)
    r = I.adaptive_radius(mesh, pilot, rough, radius)
    X = _smooth(mesh, X, N, w, I.smoothing_times(mesh, r), I.SMOOTHING_STEPS, I.SMOOTHING_ORDER,
                real_boundary)
    _, _, PV1, PV2 = I.principal(X, N)
    PV1, PV2, _ = mark_bad_vertices(mesh, PV1, PV2)
    return PV1, PV2, r, S


def _hops(F, n, sources):
    """Edge distance of every vertex to ``sources`` (inf: not connected)."""
    E = np.r_[F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]
    A = sp.coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(n, n)).tocsr()
    A = ((A + A.T) > 0).astype(np.float64)
    d = np.full(n, np.inf)
    d[sources] = 0
    front = np.zeros(n, dtype=bool)
    front[sources] = True
    k = 0
    while front.any():
        k += 1
        front = ((A @ front.astype(np.float64)) > 0) & ~np.isfinite(d)
        d[front] = k
    return d


def half_space_study(V, F, radius=5, eps=EPS):
    """The cut's effect on the half ``x < median`` of a mesh (module docstring). Returns a dict."""
    from ..tiled.rings import boundary_edge_faces
    c = V[F].mean(axis=1)
    keep = c[:, 0] < np.median(c[:, 0])
    used, local = np.unique(F[keep], return_inverse=True)
    Ft = local.reshape(-1, 3)
    Eall, _ = boundary_edge_faces(F, np.arange(len(F)))
    Et, _ = boundary_edge_faces(Ft, np.arange(len(Ft)))
    n = len(V)
    whole_keys = np.minimum(*Eall.T) * n + np.maximum(*Eall.T)
    g = used[Et]
    real = np.isin(np.minimum(*g.T) * n + np.maximum(*g.T), whole_keys)
    real_v = np.zeros(len(used), dtype=bool)
    real_v[Et[real].ravel()] = True
    cut = np.unique(Et[~real])
    W1, W2, _, Sw = exact_dropin(V, F, radius)
    T1, T2, r, St = exact_dropin(V[used], Ft, radius, real_v)
    d = _hops(Ft, len(used), cut)
    dface = d[Ft].min(axis=1)
    kmax = np.nanmax(np.abs(np.r_[W1, W2]))
    dv = np.fmax(np.abs(T1 - W1[used]), np.abs(T2 - W2[used])) / kmax
    dv = np.where(np.isfinite(dv), dv, 0.0)
    smax = np.percentile(np.abs(Sw).max(axis=(1, 2)), 99)
    ds = np.abs(St - Sw[keep]).max(axis=(1, 2)) / smax
    depth = int(d[np.isfinite(d)].max())
    per_v = np.array([dv[d == k].max(initial=0.0) for k in range(depth + 1)])
    per_s = np.array([ds[dface == k].max(initial=0.0) for k in range(depth + 1)])
    above = np.flatnonzero(per_v > eps)
    measured = int(above[-1]) + 1 if above.size else 0
    ok = np.flatnonzero(per_s > 1e-13)
    last = int(ok[-1]) if ok.size else 0
    rate = (np.log10(max(per_s[0], 1e-300)) - np.log10(per_s[last])) / max(last, 1)
    band_boundary = bool(real_v.any())
    away = dface >= reach.hhj_rings(eps)                          # as igl_hhj.tiled.tile: away from the cut
    rmax = float(r[away].max() if away.any() else r.max())
    return dict(faces=len(F), depth=depth, radius_max=rmax, boundary=band_boundary,
                hhj_decades_per_ring=float(rate), hhj_rings=int(np.argmax(per_s < eps)) if (per_s < eps).any() else None,
                measured=measured, resolved=measured <= depth,
                rule=reach.overlap_rings(rmax, eps, boundary=band_boundary),
                cut_change=float(per_v[0]), curve=per_v)


def generated(name):
    """The generated meshes of :data:`GENERATED`."""
    import igl
    from ..surfaces import Ellipsoid, ellipsoid_coarse, refine
    from .speed_meshes import _open_scan
    from .tiled import torus
    rng = np.random.default_rng(6)
    if "ellipsoid" in name:
        ell = Ellipsoid()
        V, F = ellipsoid_coarse(ell, subdivisions=3, amount=0.2)
        V, F = refine(V, F, ell, 3 if "82k" in name else 4)
        if name.startswith("noisy"):
            V = V + 0.05 * igl.avg_edge_length(V, F) * rng.normal(size=(len(V), 1)) * ell.normal(V)
        return V, F
    if "scan" in name:
        V, F = _open_scan(250)
        if name.startswith("noisy"):
            V = V + 0.05 * igl.avg_edge_length(V, F) * rng.normal(size=(len(V), 1)) * igl.per_vertex_normals(V, F)
        return V, F
    if "torus" in name:
        return torus(200_000)
    raise KeyError(name)


def decay_table(names=None, mesh_dir=None, progress=True):
    """Rows of :func:`half_space_study`: for ``names`` (generated meshes of :data:`GENERATED`
    and mesh files), or, without names, the generated meshes and every mesh of ``mesh_dir``."""
    import igl
    import sys
    if names:
        gen = [n for n in names if n in GENERATED]
        paths = [Path(n) for n in names if n not in GENERATED]
    else:                                   # everything: the generated meshes and mesh_dir's
        gen = list(GENERATED)
        paths = sorted([*Path(mesh_dir).glob("*.off"), *Path(mesh_dir).glob("*.obj")]) if mesh_dir else []
    cases = [(n, lambda n=n: generated(n)) for n in gen]
    cases += [(p.name, lambda p=p: igl.read_triangle_mesh(str(p))) for p in paths]
    rows = []
    for name, load in cases:
        V, F = load()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                row = dict(mesh=name, **half_space_study(V, F))
            except Exception as exc:      # refused by the strict mesh (defects): not a decay case
                row = dict(mesh=name, faces=len(F), error=f"{type(exc).__name__}: {str(exc)[:80]}")
        rows.append(row)
        if progress:
            print({k: v for k, v in row.items() if k != "curve"}, file=sys.stderr, flush=True)
    return rows


def markdown(rows):
    out = ["| mesh | faces | depth (rings) | change at the cut | HHJ decades/ring | r_max | measured rings to 1e-6 | "
           "rule | ok |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            out.append(f"| {r['mesh']} | {r['faces']} | | | | | {r['error']} | | |")
            continue
        meas = f"{r['measured']}" if r["resolved"] else f"> {r['depth']}"
        ok = ("yes" if r["measured"] <= r["rule"] else "NO") if r["resolved"] else "– (too few rings)"
        out.append(f"| {r['mesh']} | {r['faces']:,} | {r['depth']} | {r['cut_change']:.1e} | "
                   f"{r['hhj_decades_per_ring']:.2f} | {r['radius_max']:.1f}{' (b)' if r['boundary'] else ''} | "
                   f"{meas} | {r['rule']} | {ok} |")
    return "\n".join(out)


def main(argv=None):
    import argparse
    from .tiled import _default_mesh_dir
    ap = argparse.ArgumentParser(prog="python -m igl_hhj.benchmarks.tiled_decay", description=__doc__.split("\n")[0])
    ap.add_argument("names", nargs="*", metavar="MESH",
                    help=f"generated meshes ({', '.join(GENERATED)}) or mesh files (default: all generated and --meshes)")
    ap.add_argument("--meshes", type=Path, default=_default_mesh_dir())
    a = ap.parse_args(argv)
    print(markdown(decay_table(a.names or None, a.meshes)))


if __name__ == "__main__":
    main()
