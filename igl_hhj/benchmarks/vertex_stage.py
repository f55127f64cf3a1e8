"""The drop-in's vertex stage on real and thin meshes, against libigl.

``python -m igl_hhj.benchmarks.vertex_stage [--meshes DIR ...] [--quick] [--out DIR]``

Prints (and writes ``vertex_stage.md`` in ``--out``):

1. **Gauss–Bonnet** on every closed mesh of ``shared/data/meshes`` and of each
   ``--meshes`` folder (e.g. a checkout of libigl's tutorial data): ``Σ_i K_i A_i``
   (Voronoi areas, ``igl.massmatrix``) against ``2πχ``, the error in units of 4π, for
   ``igl_hhj.principal_curvature`` and ``igl.principal_curvature`` at radius 5 and 2.
   For exact total curvature use :func:`igl_hhj.regge.gauss_curvature` (the lifted
   angle defect: Gauss–Bonnet to round-off).
2. **Thin torus** R = 1, r = 0.1 with 8, 12, 24 vertices around the tube: median κ1
   (exact 10), median and rms error of κ2, ``Σ K A / 4π`` (exact 0).
3. **Invariance and locality**: rigid motion, scaling, relabelling, orientation
   reversal (largest relative change of PV1) and the largest absolute change on a
   component when an unconnected one is added.
4. **Families** (``igl_hhj.benchmarks.robustness``: clean, jittered, flipped, slivers,
   noisy 0.01–0.1 h; ellipsoid, Walker's torus, the open saddle without boundary
   data with its 2-ring band): rms H and K at the vertices on the finest mesh, the
   drop-in's default against libigl r2, r5 and the cotangent formula; ``ratio`` =
   best libigl / drop-in (> 1: the drop-in wins).
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from . import progress

MESH_DIR = Path(__file__).resolve().parents[3] / "shared" / "data" / "meshes"
SUFFIXES = (".off", ".obj", ".ply", ".stl")


def _gb_error(V, F, PV1, PV2, A, chi):
    K = PV1 * PV2
    ok = np.isfinite(K)
    return (float(np.sum(K[ok] * A[ok])) - 2 * np.pi * chi) / (4 * np.pi)


def gauss_bonnet(folders, show=True):
    """Rows (mesh, χ, drop-in r5, drop-in r2, libigl r5, libigl r2) of signed errors / 4π."""
    import igl

    import igl_hhj
    paths, seen = [], set()
    for d in folders:                      # a file name seen in an earlier folder is skipped
        for p in sorted(Path(d).iterdir()) if Path(d).is_dir() else []:
            if p.suffix.lower() in SUFFIXES and p.name not in seen:
                seen.add(p.name)
                paths.append(p)
    rows = []
    for p in progress(paths, "Gauss-Bonnet", "mesh", show):
        try:
            V, F = igl.read_triangle_mesh(str(p))
        except Exception:       # noqa: BLE001 - a file libigl cannot read is skipped
            continue
        if len(F) == 0 or len(igl.boundary_facets(F)[0]) or not igl.is_edge_manifold(F):
            continue
        A = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
        chi = len(V) - len(igl.edges(F)) + len(F)
        row = [p.name, chi]
        for fn in (igl_hhj.principal_curvature, igl.principal_curvature):
            for r in (5, 2):
                try:
                    P = fn(V, F, r)
                    row.append(_gb_error(V, F, np.asarray(P[2]), np.asarray(P[3]), A, chi))
                except Exception:  # noqa: BLE001 - reported as a failure in the table
                    row.append(float("nan"))
        rows.append(row)
    return rows


def tube_torus(n_tube, R=1.0, r=0.1, jitter=0.0, seed=0):
    """Torus with ``n_tube`` vertices around the tube, square-ish faces, outward normals;
    ``jitter``: each vertex moved by up to that fraction of the spacing in both angles."""
    n_ring = int(round(n_tube * R / r))
    u = np.arange(n_ring) * 2 * np.pi / n_ring
    v = np.arange(n_tube) * 2 * np.pi / n_tube
    U, W = np.meshgrid(u, v, indexing="ij")
    if jitter:
        rng = np.random.default_rng(seed)
        U = U + jitter * (2 * np.pi / n_ring) * rng.uniform(-1, 1, U.shape)
        W = W + jitter * (2 * np.pi / n_tube) * rng.uniform(-1, 1, W.shape)
    X = np.stack([(R + r * np.cos(W)) * np.cos(U), (R + r * np.cos(W)) * np.sin(U), r * np.sin(W)],
                 axis=-1).reshape(-1, 3)
    I, J = (a.ravel() for a in np.meshgrid(np.arange(n_ring), np.arange(n_tube), indexing="ij"))

    def idx(i, j):
        return (i % n_ring) * n_tube + (j % n_tube)
    a, b, c, d = idx(I, J), idx(I + 1, J), idx(I + 1, J + 1), idx(I, J + 1)
    return X, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])


def thin_torus(n_tubes=(8, 12, 24)):
    """Rows (n_tube, method, median κ1, median κ2, rms κ2 error, Σ K A / 4π)."""
    import igl

    import igl_hhj
    rows = []
    for n in n_tubes:
        V, F = tube_torus(n)
        A = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
        ct = (np.hypot(V[:, 0], V[:, 1]) - 1.0) / 0.1
        k2e = ct / (1.0 + 0.1 * ct)
        for name, fn in (("drop-in r5", lambda: igl_hhj.principal_curvature(V, F)),
                         ("libigl r5", lambda: igl.principal_curvature(V, F, 5)),
                         ("libigl r2", lambda: igl.principal_curvature(V, F, 2))):
            _, _, k1, k2, _ = fn()
            rows.append((n, name, float(np.median(k1)), float(np.median(k2)),
                         float(np.sqrt(np.mean((k2 - k2e) ** 2))), float(np.sum(k1 * k2 * A) / (4 * np.pi))))
    return rows


def invariance():
    """dict name → largest change (relative for the transforms, absolute for locality)."""
    from scipy.spatial.transform import Rotation

    import igl_hhj
    from ..surfaces import icosphere
    V, F = tube_torus(20, r=0.4, jitter=0.3)
    rng = np.random.default_rng(0)
    P = igl_hhj.principal_curvature(V, F)
    Q = Rotation.from_euler("xyz", [0.3, 1.1, -0.7]).as_matrix()

    def rel(a, b):
        return float(np.abs(a - b).max() / np.abs(b).max())
    out = {"rotation + translation": rel(igl_hhj.principal_curvature(V @ Q.T + 1.0, F)[2], P[2]),
           "scaling × 7.3": rel(7.3 * igl_hhj.principal_curvature(7.3 * V, F)[2], P[2])}
    perm = rng.permutation(len(V))
    inv = np.argsort(perm)
    out["vertex permutation"] = rel(igl_hhj.principal_curvature(V[perm], inv[F])[2][inv], P[2])
    out["orientation reversal"] = rel(-igl_hhj.principal_curvature(V, F[:, ::-1])[3], P[2])
    V2, F2 = icosphere(5)
    both = igl_hhj.principal_curvature(np.vstack([V, 0.1 * V2 + 10]), np.vstack([F, F2 + len(V)]))
    out["another component (absolute)"] = float(np.abs(both[2][:len(V)] - P[2]).max())
    return out


def families(quick=False, show=True):
    """Rows (surface, family, region, method → (rms H, rms K)) on the finest level."""
    import igl

    from . import robustness as rb
    import igl_hhj
    from .. import baselines
    rows = []
    surfaces = rb._surfaces(quick)
    work = [(s, f) for s in surfaces for f in ("clean", "jitter 0.30", "flips", "slivers", "noise 0.01",
                                               "noise 0.02", "noise 0.05", "noise 0.1")]
    fams = {s: rb.families(*surfaces[s], len(surfaces[s][1])) for s in surfaces}
    for s, f in progress(work, "families", "case", show):
        surface = surfaces[s][0]
        V, F, X = fams[s][f][-1]
        est = {"drop-in": igl_hhj.principal_curvature(V, F)[2:4],
               "libigl r2": tuple(np.asarray(a) for a in igl.principal_curvature(V, F, 2)[2:4]),
               "libigl r5": tuple(np.asarray(a) for a in igl.principal_curvature(V, F, 5)[2:4])}
        c = baselines.libigl_cotan(V, F)
        est["cotan"] = (c.k1, c.k2)
        errs = {k: rb.errors(surface, V, F, X, "vertex", k1, k2, None) for k, (k1, k2) in est.items()}
        for region in ("interior", "band"):
            if region in errs["drop-in"]:
                rows.append((s, f, region, {k: (e[region]["H"], e[region]["K"]) for k, e in errs.items()}))
    return rows


def _fmt(x):
    return "—" if not np.isfinite(x) else f"{x:.3g}"


def report(gb, torus, inv, fam):
    lines = ["# Vertex stage (`python -m igl_hhj.benchmarks.vertex_stage`)", ""]
    if gb:
        lines += ["## Gauss–Bonnet on closed meshes: (Σ K_i A_i − 2πχ) / 4π", "",
                  "| mesh | χ | drop-in r5 | drop-in r2 | libigl r5 | libigl r2 |", "|---|---|---|---|---|---|"]
        for name, chi, *e in gb:
            lines.append(f"| {name} | {chi} | " + " | ".join(_fmt(x) for x in e) + " |")
        ok5 = sum(abs(r[2]) <= abs(r[4]) for r in gb)
        ok2 = sum(abs(r[3]) <= abs(r[5]) for r in gb)
        lines += ["", f"|error| of the drop-in ≤ libigl's on {ok5} of {len(gb)} meshes at radius 5, "
                      f"{ok2} of {len(gb)} at radius 2.", ""]
    lines += ["## Thin torus R = 1, r = 0.1 (exact κ1 = 10, κ2 = cos θ/(1 + 0.1 cos θ), Σ K A = 0)", "",
              "| around the tube | method | median κ1 | median κ2 | rms κ2 error | Σ K A / 4π |",
              "|---|---|---|---|---|---|"]
    for n, name, a, b, c, d in torus:
        lines.append(f"| {n} | {name} | {a:.3f} | {b:.3f} | {c:.3f} | {d:.3f} |")
    lines += ["", "## Invariance and locality (largest change of PV1)", "", "| transform | change |", "|---|---|"]
    lines += [f"| {k} | {v:.1e} |" for k, v in inv.items()]
    if fam:
        lines += ["", "## Families, finest mesh: rms H / rms K at the vertices", "",
                  "| surface | family | region | drop-in | libigl r2 | libigl r5 | cotan | ratio H | ratio K |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for s, f, region, e in fam:
            best_h = min(e["libigl r2"][0], e["libigl r5"][0])
            best_k = min(e["libigl r2"][1], e["libigl r5"][1])
            cells = " | ".join(f"{_fmt(e[k][0])} / {_fmt(e[k][1])}" for k in ("drop-in", "libigl r2", "libigl r5", "cotan"))
            lines.append(f"| {s} | {f} | {region} | {cells} | {best_h / e['drop-in'][0]:.2f} | "
                         f"{best_k / e['drop-in'][1]:.2f} |")
        wins_h = sum(min(e["libigl r2"][0], e["libigl r5"][0]) >= e["drop-in"][0] for *_, e in fam)
        wins_k = sum(min(e["libigl r2"][1], e["libigl r5"][1]) >= e["drop-in"][1] for *_, e in fam)
        lines += ["", f"The drop-in ≤ the best libigl setting in {wins_h} of {len(fam)} rows for H, "
                      f"{wins_k} of {len(fam)} for K."]
    return "\n".join(lines) + "\n"


def run(out="vertex_stage_out", meshes=(), quick=False, show=True, do_families=True):
    t0 = time.perf_counter()
    gb = gauss_bonnet([MESH_DIR, *meshes], show)
    torus = thin_torus()
    inv = invariance()
    fam = families(quick, show) if do_families else []
    text = report(gb, torus, inv, fam)
    Path(out).mkdir(parents=True, exist_ok=True)
    (Path(out) / "vertex_stage.md").write_text(text)
    print(text)
    print(f"wrote {Path(out) / 'vertex_stage.md'} in {time.perf_counter() - t0:.0f} s")
    return gb, torus, inv, fam


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--meshes", nargs="*", default=[], help="more folders of meshes (closed ones are used)")
    ap.add_argument("--quick", action="store_true", help="short sequences (ellipsoid + saddle)")
    ap.add_argument("--no-families", action="store_true", help="skip the exact-surface families")
    ap.add_argument("--out", default="vertex_stage_out", help="output folder")
    a = ap.parse_args(argv)
    run(a.out, a.meshes, a.quick, do_families=not a.no_families)


if __name__ == "__main__":
    main()
