"""Robustness benchmark of the drop-in: noisy, jittered, flipped, sliver-ridden and open meshes.

``python -m igl_hhj.benchmarks.robustness [--quick] [--out DIR] [--timing] [--no-real] [--no-picture]``

Exact surfaces: a closed ellipsoid (axes 1, 0.5, 1.5), Walker's torus, and
Walker's open saddle graph (no boundary data given: the drop-in estimates the
boundary normals).  Mesh families, built on the same non-uniform refinement
sequence at every level:

* ``clean``: the perturbed coarse mesh refined and projected;
* ``jitter a``: every vertex moved tangentially by up to a × its spacing and
  re-projected (a = 0.15, 0.30, 0.45; boundary vertices stay), fold-free (the
  vertices of faces that would fold or get 10× thinner than average stay);
* ``noise s``: every vertex moved along the exact normal by N(0, (s·h̄)²)
  (s = 0.01, 0.02, 0.05, 0.1); exact values at the projected point;
* ``flips``: an independent set of ~15 % of the interior edges flipped (only
  flips that keep the faces' orientation and add no duplicate edge);
* ``slivers``: the coarse mesh jittered by 0.45 (fold-free) and refined: its
  thin triangles persist at every level.

Methods: the drop-in ``igl_hhj.principal_curvature`` at radius 1, 2, 5 (5 is
the default), HHJ per face (Walker's S_h), ``igl.principal_curvature`` at
radius 2 and 5, cotangent mean curvature + angle defect, Heine's P1 map, and
pymeshlab's quadric fit when pymeshlab is installed.  Errors: rms and max of H
and K and the rms angle of the principal direction d1 (degrees, where
|κ1 - κ2| > 0.2 max|κ|), per region (interior; within 2 rings of the
boundary), with the EOC of the rms error of H.  Real meshes (shared/data/meshes):
agreement of the drop-in with libigl and the roughness of both.

Outputs in ``--out``: ``robustness.md`` (tables), ``robustness.json``,
``robustness_eoc.png`` (rms H error vs h per family), ``robustness_radius.png``
(error vs radius, clean and noisy), ``robustness_bunny.png`` (bunny H: drop-in
vs libigl, one colour range, needs headless EGL) and, with ``--timing``, the
cost of each stage of the drop-in in µs/face on a 328k-face mesh.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from .. import surfaces as su
from ..mesh import TriangleMesh

JITTERS = (0.15, 0.30, 0.45)
NOISES = (0.01, 0.02, 0.05, 0.1)
FLIP_FRACTION = 0.15
METHODS = ("hhj r1", "hhj r2", "hhj r5", "hhj face", "libigl r2", "libigl r5", "cotan", "heine", "pymeshlab")
MESH_DIR = Path(__file__).resolve().parents[3] / "shared" / "data" / "meshes"


# --------------------------------------------------------------------------- meshes
def _surfaces(quick):
    n_closed = 3 if quick else 5
    n_open = 4 if quick else 5
    out = {}
    s = su.Ellipsoid()
    out["ellipsoid"] = (s, su.mesh_sequence(*su.ellipsoid_coarse(s, subdivisions=2, amount=0.2), s, n_closed))
    if not quick:
        t = su.WalkerTorus()
        out["torus"] = (t, su.mesh_sequence(*su.torus_coarse(n_phi=16, n_t=8, amount=0.2), t, n_closed - 1))
    g = su.WalkerSaddle()
    out["saddle (open)"] = (g, su.mesh_sequence(*su.graph_coarse(g, n=6, amount=0.2), g, n_open))
    return out


def _folded_faces(V, F, surface):
    """(#F,) bool: faces whose normal points against the surface normal at their centroid
    (or is 10× smaller than the mean: near folds)."""
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    c = V[F].mean(axis=1)
    c = c if isinstance(surface, su.GraphSurface) else surface.project(c)
    d = np.einsum("fa,fa->f", n, surface.normal(c))
    return d <= 0.1 * np.mean(np.abs(d))


def flip_edges(V, F, fraction, seed):
    """Flip an independent set of about ``fraction`` of the interior edges.

    An edge is flipped when its random priority is the largest among the edges
    of its two faces (so no face takes part in two flips), the flip keeps both
    new faces oriented like the old ones and does not duplicate an edge."""
    m = TriangleMesh(V, F)
    rng = np.random.default_rng(seed)
    E, EF, EL = m.edges, m.edge_faces, m.edge_local_index
    interior = (EF >= 0).all(axis=1)
    pri = np.where(interior & (rng.uniform(size=len(E)) < 2 * fraction), rng.uniform(size=len(E)), -1.0)
    fmax = pri[m.face_edges].max(axis=1)
    cand = np.flatnonzero((pri > 0) & (pri >= fmax[EF[:, 0]]) & (pri >= fmax[np.maximum(EF[:, 1], 0)]))
    f1, f2 = EF[cand, 0], EF[cand, 1]
    c = F[f1, EL[cand, 0]]                 # corners opposite the edge
    d = F[f2, EL[cand, 1]]
    a = F[f1, (EL[cand, 0] + 1) % 3]       # f1 = (c, a, b) in cyclic order
    b = F[f1, (EL[cand, 0] + 2) % 3]
    new1 = np.stack([c, a, d], axis=1)
    new2 = np.stack([c, d, b], axis=1)
    X = m.V

    def nrm(T):
        return np.cross(X[T[:, 1]] - X[T[:, 0]], X[T[:, 2]] - X[T[:, 0]])
    old = m.face_normals[f1] + m.face_normals[f2]
    ok = (np.einsum("fa,fa->f", nrm(new1), old) > 0) & (np.einsum("fa,fa->f", nrm(new2), old) > 0)
    nV = len(X)
    keys = np.sort(E, axis=1) @ np.array([nV, 1])
    newkey = np.sort(np.stack([c, d], axis=1), axis=1) @ np.array([nV, 1])
    ok &= ~np.isin(newkey, keys)
    # two candidate flips may create the same new edge: keep the first
    _, first = np.unique(newkey[ok], return_index=True)
    sel = np.flatnonzero(ok)[first]
    G = F.copy()
    G[f1[sel]] = new1[sel]
    G[f2[sel]] = new2[sel]
    return G, len(sel) / max(int(interior.sum()), 1)


def fold_free_jitter(V, F, surface, amount, seed):
    """:func:`igl_hhj.surfaces.jitter_tangentially` (boundary vertices fixed) whose
    vertices on faces that would fold or get 10× thinner than average stay put."""
    fixed = TriangleMesh(V, F).boundary_vertices
    W = su.jitter_tangentially(V, F, surface, amount, seed=seed, fixed=fixed)
    for _ in range(20):
        bad = _folded_faces(W, F, surface)
        if not bad.any():
            break
        back = np.unique(F[bad])
        W[back] = V[back]
    if _folded_faces(W, F, surface).any():
        raise RuntimeError(f"jitter {amount} folded a mesh")
    return W


def families(surface, seq, n_levels):
    """dict family → list of (V, F, exact-point X) per level."""
    fam = {}
    fam["clean"] = [(V, F, V) for V, F in seq]
    for a in JITTERS:
        rows = []
        for k, (V, F) in enumerate(seq):
            W = fold_free_jitter(V, F, surface, a, 100 + k)
            rows.append((W, F, W))
        fam[f"jitter {a:.2f}"] = rows
    for s in NOISES:
        rows = []
        for k, (V, F) in enumerate(seq):
            h = TriangleMesh(V, F).mean_edge_length
            rng = np.random.default_rng(200 + k)
            W = V + s * h * rng.normal(size=(len(V), 1)) * surface.normal(V)
            rows.append((W, F, surface.project(W)))
        fam[f"noise {s:g}"] = rows
    rows = []
    for k, (V, F) in enumerate(seq):
        G, _ = flip_edges(V, F, FLIP_FRACTION, seed=300 + k)
        rows.append((V, G, V))
    fam["flips"] = rows
    V0, F0 = seq[0]
    sl = su.mesh_sequence(fold_free_jitter(V0, F0, surface, 0.45, 7), F0, surface, n_levels)
    fam["slivers"] = [(V, F, V) for V, F in sl]
    return fam


# --------------------------------------------------------------------------- methods
def _have_pymeshlab():
    try:
        import pymeshlab  # noqa: F401
        return True
    except ImportError:
        return False


def run_method(name, V, F, cache=None):
    """→ (location, k1, k2, d1) with location "vertex" or "face".

    The HHJ variants share one solve through ``cache`` (a dict): the same
    S_h and the same steps as ``igl_hhj.principal_curvature(V, F, radius)`` /
    ``igl_hhj.face_principal_curvature(V, F)``."""
    import igl

    from .. import baselines
    from ..curvature import (principal_from_shape_operator, shape_operator, vertex_principal_curvature,
                             vertex_shape_operator)
    if name.startswith("hhj"):
        cache = {} if cache is None else cache
        if "S" not in cache:
            cache["mesh"] = TriangleMesh(V, F)
            cache["S"] = shape_operator(V, F)
        m, S = cache["mesh"], cache["S"]
        if name == "hhj face":
            PD1, _, PV1, PV2 = principal_from_shape_operator(S, m.face_normals)
            return "face", PV1, PV2, PD1
        Sv, N = vertex_shape_operator(m, S, smoothing=int(name[5:]))
        PD1, _, PV1, PV2 = vertex_principal_curvature(m, Sv, N)
        return "vertex", PV1, PV2, PD1
    if name.startswith("libigl r"):
        PD1, _, PV1, PV2, _ = igl.principal_curvature(V, F, int(name[8:]))
        return "vertex", np.asarray(PV1), np.asarray(PV2), np.asarray(PD1)
    if name == "cotan":
        e = baselines.libigl_cotan(V, F)
    elif name == "heine":
        e = baselines.heine(V, F)
    elif name == "pymeshlab":
        e = baselines.pymeshlab_principal_curvature(V, F, "quadric")
    else:
        raise ValueError(name)
    return "vertex", e.k1, e.k2, e.d1


def ring_band(mesh, rings=2):
    import igl
    b = mesh.boundary_vertices.copy()
    if not b.any():
        return b
    A = igl.adjacency_matrix(mesh.F)
    for _ in range(rings):
        b = b | (A @ b.astype(float) > 0)
    return b


def errors(surface, V, F, X, loc, k1, k2, d1):
    """Per-region error dict for one estimate (exact values at the points X)."""
    m = TriangleMesh(V, F)
    band = ring_band(m)
    if loc == "face":
        P = X[F].mean(axis=1)
        P = P if isinstance(surface, su.GraphSurface) else surface.project(P)
        region = {"interior": ~band[F].any(axis=1), "band": band[F].any(axis=1)}
        w = m.face_areas
    else:
        P = X
        region = {"interior": ~band, "band": band}
        w = m.sum_corners_to_vertices(np.broadcast_to(m.face_areas[:, None] / 3, (m.n_faces, 3)))
    e1, e2 = surface.principal_curvatures(P)
    D1 = surface.principal_directions(P)[0]
    H, K = 0.5 * (e1 + e2), e1 * e2
    dH = 0.5 * (k1 + k2) - H
    dK = k1 * k2 - K
    aniso = np.abs(e1 - e2) > 0.2 * np.max(np.abs(np.concatenate([e1, e2])))
    out = {}
    for rname, mask in region.items():
        mask = mask & np.isfinite(dH)
        if region["band"].sum() == 0 and rname == "band":
            continue
        if not mask.any():
            continue
        ww = w[mask] / w[mask].sum()
        r = {"H": float(np.sqrt(np.sum(ww * dH[mask] ** 2))), "H_max": float(np.abs(dH[mask]).max()),
             "K": float(np.sqrt(np.sum(ww * dK[mask] ** 2))), "K_max": float(np.abs(dK[mask]).max())}
        dm = mask & aniso
        if d1 is not None and dm.any():
            c = np.abs(np.einsum("ia,ia->i", d1[dm], D1[dm]))
            r["angle"] = float(np.degrees(np.sqrt(np.mean(np.arccos(np.clip(c, 0, 1)) ** 2))))
        out[rname] = r
    out["h"] = m.mean_edge_length
    out["faces"] = m.n_faces
    return out


# --------------------------------------------------------------------------- runs
def accuracy(quick, progress):
    methods = [m for m in METHODS if m != "pymeshlab" or _have_pymeshlab()]
    res = {}
    surf = _surfaces(quick)
    jobs = []
    for sname, (surface, seq) in surf.items():
        fam = families(surface, seq, len(seq))
        for fname, rows in fam.items():
            for lev, row in enumerate(rows):
                jobs.append((sname, surface, fname, lev, row))
    bar = progress(total=len(jobs) * len(methods), desc="robustness", unit="run", mininterval=2.0)
    for sname, surface, fname, lev, (V, F, X) in jobs:
        cache = {}
        for meth in methods:
            bar.set_postfix_str(f"{sname} {fname} L{lev} {meth}")
            try:
                loc, k1, k2, d1 = run_method(meth, V, F, cache)
                e = errors(surface, V, F, X, loc, k1, k2, d1)
            except (ValueError, RuntimeError) as exc:      # reported, not fatal
                e = {"error": str(exc).splitlines()[0], "h": float("nan"), "faces": len(F)}
                print(f"{sname} {fname} L{lev} {meth}: {e['error']}")
            res.setdefault(sname, {}).setdefault(fname, {}).setdefault(meth, []).append(e)
            bar.update()
    bar.close()
    return res, methods


def radius_sweep(quick):
    """rms H error of the drop-in vs radius (and libigl's), clean and noisy ellipsoid."""
    import igl

    import igl_hhj
    s = su.Ellipsoid()
    seq = su.mesh_sequence(*su.ellipsoid_coarse(s, subdivisions=2, amount=0.2), s, 3 if quick else 4)
    V0, F = seq[-1]
    h = TriangleMesh(V0, F).mean_edge_length
    radii = [1, 2, 3, 5, 8] if quick else [1, 2, 3, 4, 5, 6, 8, 10]
    out = {"faces": len(F), "radii": radii, "curves": {}}
    for label, sigma in (("clean", 0.0), ("noise 0.02", 0.02), ("noise 0.05", 0.05)):
        V = V0 + sigma * h * np.random.default_rng(5).normal(size=(len(V0), 1)) * s.normal(V0)
        X = s.project(V)
        Hx = s.mean_curvature(X)
        for who in ("hhj", "libigl"):
            errs = []
            for r in radii:
                if who == "libigl" and r < 2:       # libigl forces radius >= 2
                    errs.append(float("nan"))
                    continue
                fn = igl_hhj.principal_curvature if who == "hhj" else igl.principal_curvature
                out_ = fn(V, F, r)
                errs.append(float(np.sqrt(np.nanmean((0.5 * (out_[2] + out_[3]) - Hx) ** 2))))
            out["curves"][f"{who} {label}"] = errs
    return out


def recovery_comparison(quick):
    """rms H error of the vertex recoveries of S_h without smoothing (lumped area
    average, consistent-mass L2 projection, linear patch fit) and of the default
    drop-in, on the ellipsoid: clean, jittered 0.30, noise 0.02."""
    import igl

    from .. import recovery as rc
    from ..curvature import shape_operator, vertex_principal_curvature, vertex_shape_operator
    s = su.Ellipsoid()
    seq = su.mesh_sequence(*su.ellipsoid_coarse(s, subdivisions=2, amount=0.2), s, 3 if quick else 4)
    V0, F = seq[-1]
    h = TriangleMesh(V0, F).mean_edge_length
    cases = {"clean": V0, "jitter 0.30": fold_free_jitter(V0, F, s, 0.30, 11),
             "noise 0.02": V0 + 0.02 * h * np.random.default_rng(6).normal(size=(len(V0), 1)) * s.normal(V0)}
    out = {"faces": len(F), "rows": {}}
    for name, V in cases.items():
        m = TriangleMesh(V, F)
        Hx = s.mean_curvature(s.project(V))
        S = shape_operator(V, F)
        row = {}
        for meth in ("lumped", "consistent", "patch"):
            Sv, N = rc.recover_vertex_tensors(m, S, method=meth)
            _, _, a, b = vertex_principal_curvature(m, Sv, N)
            row[meth] = float(np.sqrt(np.mean((0.5 * (a + b) - Hx) ** 2)))
        Sv, N = vertex_shape_operator(m, S, smoothing=5)
        _, _, a, b = vertex_principal_curvature(m, Sv, N)
        row["drop-in r5"] = float(np.sqrt(np.mean((0.5 * (a + b) - Hx) ** 2)))
        q = igl.principal_curvature(V, F, 2)
        row["libigl r2"] = float(np.sqrt(np.mean((0.5 * (q[2] + q[3]) - Hx) ** 2)))
        out["rows"][name] = row
    return out


def real_meshes(quick):
    """Agreement (correlation of H, relative median difference) and roughness
    (rms of H minus its 1-ring mean, relative to rms H) on the shared meshes."""
    import igl

    import igl_hhj
    from ..mesh_io import read_mesh
    paths = sorted(p for p in MESH_DIR.glob("*.off")) if MESH_DIR.is_dir() else []
    if quick:
        paths = [p for p in paths if p.stem == "bunny"]
    rows = []
    for p in paths:
        V, F = read_mesh(str(p))[:2]
        m = TriangleMesh(V, F)
        A = igl.adjacency_matrix(m.F).astype(float)
        deg = np.asarray(A.sum(axis=1)).ravel()
        t = time.perf_counter()
        _, _, PV1, PV2, _ = igl_hhj.principal_curvature(V, F)
        t_h = time.perf_counter() - t
        t = time.perf_counter()
        _, _, QV1, QV2, _ = igl.principal_curvature(V, F)
        t_i = time.perf_counter() - t
        Hh, Hi = 0.5 * (PV1 + PV2), 0.5 * (QV1 + QV2)
        ok = np.isfinite(Hh) & np.isfinite(Hi)

        def rough(H):
            Hz = np.where(ok, H, 0.0)
            nb = (A @ Hz) / np.maximum(deg, 1)
            return float(np.sqrt(np.mean((Hz - nb)[ok] ** 2)) / np.sqrt(np.mean(Hz[ok] ** 2)))
        Kh, Ki = PV1 * PV2, QV1 * QV2
        rows.append({"mesh": p.stem, "faces": m.n_faces, "boundary_edges": int(m.boundary_edges.sum()),
                     "corr_H": float(np.corrcoef(Hh[ok], Hi[ok])[0, 1]),
                     "rel_median_dH": float(np.median(np.abs(Hh - Hi)[ok]) / np.median(np.abs(Hi[ok]))),
                     "rough_hhj": rough(Hh), "rough_libigl": rough(Hi),
                     "median_K_hhj": float(np.median(Kh[ok])), "median_K_libigl": float(np.median(Ki[ok])),
                     "time_hhj": t_h, "time_libigl": t_i})
    return rows


def timing(n_sub=7):
    """Cost of the drop-in's stages on a jittered icosphere (n_sub=7: 327 680 faces) and
    an open cap of it, in µs per face, beside igl.principal_curvature in the same run."""
    import igl

    from .. import recovery as rc
    from ..boundary_estimation import estimate_boundary_normals
    from ..curvature import _shape_operator, vertex_principal_curvature
    V, F = su.icosphere(n_sub)
    V = su.jitter_tangentially(V, F, su.Sphere(), 0.2, seed=0)
    out = {"faces": len(F)}

    def clock(key, fn, nf):
        t = time.perf_counter()
        r = fn()
        out[key] = (time.perf_counter() - t) / nf * 1e6
        return r
    m = clock("mesh topology + geometry", lambda: _touch(TriangleMesh(V, F)), len(F))
    S = clock("HHJ solve (_shape_operator)", lambda: _shape_operator(m, None, None, None, "auto"), len(F))
    Sv, N = clock("patch recovery", lambda: rc.recover_vertex_tensors(m, S), len(F))
    Ss = clock("smoothing radius 5", lambda: rc.smooth_vertex_tensors(m, Sv, N, rc.smoothing_length(m, 5)), len(F))
    clock("smoothing radius 2", lambda: rc.smooth_vertex_tensors(m, Sv, N, rc.smoothing_length(m, 2)), len(F))
    clock("principal (2x2 eigen)", lambda: vertex_principal_curvature(m, Ss, N), len(F))
    cap = F[V[F].mean(axis=1)[:, 2] < 0.5]
    mo = _touch(TriangleMesh(V, cap))
    clock("boundary normals (open cap)", lambda: estimate_boundary_normals(mo), len(cap))
    out["boundary vertices of the cap"] = int(mo.boundary_vertices.sum())
    import igl_hhj
    clock("drop-in total (radius 5)", lambda: igl_hhj.principal_curvature(V, F), len(F))
    clock("igl.principal_curvature (radius 5)", lambda: igl.principal_curvature(V, F), len(F))
    return out


def _touch(m):
    for name in ("edges", "edge_faces", "face_edges", "face_normals", "vertex_normals", "conormals"):
        getattr(m, name)
    return m


# --------------------------------------------------------------------------- report
def _fmt(x):
    return "—" if x is None or not np.isfinite(x) else (f"{x:.3g}" if abs(x) < 1000 else f"{x:.2e}")


def _eoc(runs, region, key="H"):
    e = [r.get(region, {}).get(key) for r in runs]
    h = [r["h"] for r in runs]
    if len(e) < 2 or any(x is None or not x > 0 for x in e[-2:]):
        return None
    return float(np.log(e[-2] / e[-1]) / np.log(h[-2] / h[-1]))


def report(res, methods, sweep, real, tim, out, rec=None):
    lines = ["# Robustness benchmark (`python -m igl_hhj.benchmarks.robustness`)", ""]
    lines += ["Finest level of each sequence: rms error of H (max error, EOC of the rms error over the "
              "last refinement), per region. 'interior' = farther than 2 rings from the boundary, "
              "'band' = within 2 rings (open saddle only, no boundary data given). Bold: the best of the row.", ""]
    for sname, fams in res.items():
        regions = ["interior", "band"] if any("band" in r[-1] for r in next(iter(fams.values())).values()) \
            else ["interior"]
        for region in regions:
            any_runs = next(iter(next(iter(fams.values())).values()))
            lines += [f"## {sname}: {region}, {any_runs[-1]['faces']} faces at the finest level", ""]
            lines += ["| family | " + " | ".join(methods) + " |", "|---|" + "---|" * len(methods)]
            for fname, mres in fams.items():
                vals = {m: mres[m][-1].get(region, {}).get("H") for m in methods}
                finite = [v for v in vals.values() if v is not None and np.isfinite(v)]
                best = min(finite) if finite else None
                cells = []
                for m in methods:
                    v = vals[m]
                    r = mres[m][-1].get(region, {})
                    c = f"{_fmt(v)} ({_fmt(r.get('H_max'))}, {_fmt(_eoc(mres[m], region))})"
                    cells.append(f"**{c}**" if v is not None and v == best else c)
                lines.append(f"| {fname} | " + " | ".join(cells) + " |")
            lines.append("")
            lines += [f"K and direction ({sname}, {region}): rms K error / rms d1 angle (°)", ""]
            lines += ["| family | " + " | ".join(methods) + " |", "|---|" + "---|" * len(methods)]
            for fname, mres in fams.items():
                cells = []
                for m in methods:
                    r = mres[m][-1].get(region, {})
                    cells.append(f"{_fmt(r.get('K'))} / {_fmt(r.get('angle'))}")
                lines.append(f"| {fname} | " + " | ".join(cells) + " |")
            lines.append("")
    # ours vs libigl summary
    lines += ["## Drop-in vs libigl (rms H error ratio libigl / drop-in at the finest level; > 1: drop-in better)", ""]
    lines += ["| surface | region | family | r5 vs libigl r5 | r2 vs libigl r2 |", "|---|---|---|---|---|"]
    for sname, fams in res.items():
        for fname, mres in fams.items():
            for region in ("interior", "band"):
                a = mres["hhj r5"][-1].get(region, {}).get("H")
                if a is None:
                    continue
                b = mres["libigl r5"][-1][region]["H"]
                c = mres["hhj r2"][-1][region]["H"]
                d = mres["libigl r2"][-1][region]["H"]
                lines.append(f"| {sname} | {region} | {fname} | {b / a:.2f} | {d / c:.2f} |")
    lines.append("")
    if sweep:
        lines += [f"## Error vs radius (ellipsoid, {sweep['faces']} faces, rms H error)", ""]
        lines += ["| curve | " + " | ".join(f"r={r}" for r in sweep["radii"]) + " |",
                  "|---|" + "---|" * len(sweep["radii"])]
        for k, v in sweep["curves"].items():
            lines.append(f"| {k} | " + " | ".join(_fmt(x) for x in v) + " |")
        lines.append("")
    if rec:
        cols = list(next(iter(rec["rows"].values())))
        lines += [f"## Vertex recovery of S_h (ellipsoid, {rec['faces']} faces, rms H error, no smoothing "
                  "unless stated)", "", "| mesh | " + " | ".join(cols) + " |", "|---|" + "---|" * len(cols)]
        for k, r in rec["rows"].items():
            lines.append(f"| {k} | " + " | ".join(_fmt(r[c]) for c in cols) + " |")
        lines.append("")
    if real:
        lines += ["## Real meshes (no exact answer): drop-in (radius 5) vs igl.principal_curvature (radius 5)", ""]
        lines += ["| mesh | faces | boundary edges | corr(H) | median abs ΔH / median abs H | roughness HHJ | "
                  "roughness libigl | median K HHJ | median K libigl | time HHJ (s) | time libigl (s) |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in real:
            lines.append(f"| {r['mesh']} | {r['faces']} | {r['boundary_edges']} | {r['corr_H']:.3f} | "
                         f"{r['rel_median_dH']:.3f} | {r['rough_hhj']:.3f} | {r['rough_libigl']:.3f} | "
                         f"{_fmt(r['median_K_hhj'])} | {_fmt(r['median_K_libigl'])} | {r['time_hhj']:.2f} | "
                         f"{r['time_libigl']:.2f} |")
        lines += ["", "roughness: rms(H − mean of H over the 1-ring neighbours) / rms(H).", ""]
    if tim:
        lines += [f"## Cost per stage ({tim['faces']} faces, µs per face, same run)", "",
                  "| stage | µs/face |", "|---|---|"]
        for k, v in tim.items():
            if k not in ("faces", "boundary vertices of the cap"):
                lines.append(f"| {k} | {v:.2f} |")
        lines.append("")
    (out / "robustness.md").write_text("\n".join(lines))
    return "\n".join(lines)


def plots(res, methods, sweep, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    show = [m for m in ("hhj r5", "hhj r2", "hhj face", "libigl r5", "libigl r2", "cotan", "heine") if m in methods]
    for sname, fams in res.items():
        names = list(fams)
        ncol = 4
        nrow = int(np.ceil(len(names) / ncol))
        fig, axes = plt.subplots(nrow, ncol, figsize=(4 * ncol, 3.2 * nrow), squeeze=False)
        for ax, fname in zip(axes.ravel(), names):
            for m in show:
                runs = fams[fname][m]
                ax.loglog([r["h"] for r in runs], [r.get("interior", {}).get("H", np.nan) for r in runs], "o-",
                          ms=3, label=m)
            ax.set_title(f"{fname}", fontsize=9)
            ax.set_xlabel("mean edge length")
            ax.grid(True, which="both", alpha=0.3)
        for ax in axes.ravel()[len(names):]:
            ax.axis("off")
        axes[0, 0].set_ylabel("rms H error (interior)")
        axes[0, 0].legend(fontsize=7)
        fig.suptitle(f"{sname}: rms error of H vs mesh size")
        fig.tight_layout()
        fig.savefig(out / f"robustness_eoc_{sname.split()[0]}.png", dpi=90)
        plt.close(fig)
    if sweep:
        fig, ax = plt.subplots(figsize=(6, 4))
        for k, v in sweep["curves"].items():
            ax.semilogy(sweep["radii"], v, ("o-" if k.startswith("hhj") else "s--"), label=k)
        ax.set_xlabel("radius")
        ax.set_ylabel("rms H error")
        ax.set_title(f"ellipsoid, {sweep['faces']} faces: error vs radius")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(out / "robustness_radius.png", dpi=100)
        plt.close(fig)


def bunny_picture(out):
    """Bunny H: drop-in (left) vs igl.principal_curvature (right), one colour range; the
    viewer composites the titles and the colour bar."""
    from .. import baselines, viewer
    from ..mesh_io import read_mesh
    path = MESH_DIR / "bunny.off"
    if not path.exists():
        return None
    V, F = read_mesh(str(path))[:2]
    V = np.asarray(V, dtype=np.float64)
    hhj = baselines.hhj_vertex(V, F)
    lib = baselines.libigl_quadric(V, F)
    p = out / "robustness_bunny.png"
    viewer.register_comparison(V, F, hhj=hhj, libigl=lib, per="vertex", enabled="H", robust=5,
                               title=("igl_hhj.principal_curvature (radius 5)",
                                      "igl.principal_curvature (radius 5)"),
                               screenshot=str(p), size=(1600, 800))
    return p


def run(out, *, quick=False, timing_run=False, real=True, picture=True):
    """Run the benchmark, write the report, JSON and plots into ``out``; returns the results dict."""
    from tqdm import tqdm
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    res, methods = accuracy(quick, tqdm)
    sweep = radius_sweep(quick)
    rec = recovery_comparison(quick)
    real_rows = real_meshes(quick) if real else []
    tim = timing(5 if quick else 7) if timing_run else None
    text = report(res, methods, sweep, real_rows, tim, out, rec)
    results = {"accuracy": res, "radius_sweep": sweep, "recovery": rec, "real": real_rows, "timing": tim}
    (out / "robustness.json").write_text(json.dumps(results, indent=1))
    plots(res, methods, sweep, out)
    pic = None
    if picture:
        try:
            pic = bunny_picture(out)
        except Exception as exc:     # no EGL: the tables are still useful
            print(f"no bunny picture: {str(exc).splitlines()[0]}")
    print(text)
    print(f"wrote {out}/robustness.md, robustness.json, plots{', ' + str(pic) if pic else ''} "
          f"in {time.perf_counter() - t0:.0f} s")
    results["text"] = text
    return results


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m igl_hhj.benchmarks.robustness", description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="robustness_out", help="output folder (default ./robustness_out)")
    ap.add_argument("--quick", action="store_true", help="small sequences, ellipsoid + saddle only (~1-2 min)")
    ap.add_argument("--timing", action="store_true", help="also time each stage at 328k faces")
    ap.add_argument("--no-real", action="store_true", help="skip the shared/data meshes")
    ap.add_argument("--no-picture", action="store_true", help="skip the bunny screenshot (needs EGL)")
    args = ap.parse_args(argv)
    run(args.out, quick=args.quick, timing_run=args.timing, real=not args.no_real, picture=not args.no_picture)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
