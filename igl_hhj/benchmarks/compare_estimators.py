"""Accuracy, robustness and speed of igl_hhj's HHJ curvature against the baselines.

    python -m igl_hhj.benchmarks.compare_estimators [--out DIR] [--quick] [--no-real] [--no-speed]

Writes ``compare_estimators.md``, ``compare_estimators.json``, log-log plots
(``conv_<case>.png``) and side-by-side polyscope screenshots of the real
meshes (``real_<mesh>_k1.png``, ``..._k2.png``; HHJ faces left, libigl right,
same colour range) to ``--out`` (default ``./benchmark-results/``).

Estimators: :data:`igl_hhj.baselines.ESTIMATORS` (HHJ at vertices and faces,
libigl quadric fitting with its default 5-ring and with 2-ring, libigl
cotangent H + angle-defect K, Heine's P1 Weingarten map, and pymeshlab's
Taubin / quadric fitting when pymeshlab is installed).

Errors (all *relative*, as in Heine's tables):
  * vertex estimators: ``‖q_h - q‖ / ‖q‖`` with the lumped P1 mass (|T|/3 per
    corner) over the vertices, L∞ = ``max |q_h - q| / max |q|``;
  * face estimators (HHJ S_h): ``‖I_h q - q_h‖_L2 / ‖q‖`` (P1 interpolant vs
    piecewise constant, exact 3-point rule), L∞ over face corners;
  * principal direction: angle (degrees) between the estimated and the exact
    κ1 direction, RMS (area-weighted) over points away from umbilics
    (``κ1 - κ2 > 0.1 (|κ1| + |κ2|)``), and the maximum.
Open patches: all norms over interior vertices (faces without a boundary
vertex), since the cotangent / angle-defect formulas are undefined on the
boundary; the HHJ runs use the plain assembly (no boundary data).
EOC: between successive levels, and a least-squares rate over the last three.
"""
from __future__ import annotations

import argparse
import json
import os
import time
import traceback
from pathlib import Path

import numpy as np

from ..baselines import ESTIMATORS
from ..mesh import as_mesh

# --------------------------------------------------------------------------- paper data
#: Heine (2006), Tables 5.1 and 5.3, polynomial degree 1: relative errors
#: of the mean curvature H (L2) and Gauss curvature K (L2) on the finest meshes
#: of (5.1a) and (5.1c), copied from the paper.  EOC ≈ 0 (no convergence).
HEINE_PAPER_P1 = {
    "5.1a": {"h": [0.135, 0.0689, 0.0361, 0.0199, 0.0114, 0.00654],
             "E_H2": [0.19, 0.19, 0.19, 0.19, 0.19, 0.19],
             "E_K2": [0.79, 0.87, 0.9, 0.91, 0.91, 0.91]},
    "5.1c": {"h": [0.2, 0.117, 0.0674, 0.0384, 0.0218, 0.0127],
             "E_H2": [0.19, 0.18, 0.18, 0.18, 0.18, 0.18],
             "E_K2": [0.76, 0.83, 0.83, 0.83, 0.83, 0.84]},
}

QUANTS = ("k1", "k2", "H", "K")
DEFAULT_ESTIMATORS = ["hhj_vertex", "hhj_face", "libigl_quadric", "libigl_quadric_k2", "libigl_cotan",
                      "heine", "pymeshlab_taubin", "pymeshlab_quadric"]
REFERENCE = "libigl_quadric"


# --------------------------------------------------------------------------- cases
def build_cases(quick=False):
    """dict name → (description, surface, [(V, F), ...] coarse to fine, open?)."""
    from ..surfaces.exact import Ellipsoid, WalkerSaddle, WalkerTorus
    from ..surfaces.heine import heine_coarse, heine_sequence
    from ..surfaces.meshing import ellipsoid_coarse, graph_coarse, mesh_sequence, torus_coarse

    cases = {}
    n = 3 if quick else 5
    ell = Ellipsoid()
    V0, F0 = ellipsoid_coarse(ell, subdivisions=1, amount=0.25, seed=0)
    cases["ellipsoid (5.1c)"] = ("perturbed icosahedral mesh, uniform refinement + projection",
                                 ell, mesh_sequence(V0, F0, ell, n, pre_refine=1), False)
    if not quick:
        for lab in ("5.1a", "5.1b"):
            V0, F0, s = heine_coarse(lab, subdivisions=1, seed=0)
            cases[f"Heine ({lab})"] = ("perturbed icosahedral mesh, uniform refinement + projection",
                                       s, mesh_sequence(V0, F0, s, n, pre_refine=1), False)
        tor = WalkerTorus()
        V0, F0 = torus_coarse(24, 12, amount=0.25, seed=0)
        cases["Walker torus"] = ("perturbed (phi, t) grid, random diagonals, refinement",
                                 tor, mesh_sequence(V0, F0, tor, 4), False)
        try:
            from ..surfaces.exact import WalkerGenus3
            from ..surfaces.implicit_meshing import genus3_coarse
            g3 = WalkerGenus3()
            V0, F0 = genus3_coarse(n_faces=2808, seed=0)
            cases["Walker genus 3"] = ("marching cubes + isotropic remeshing (~2808 faces), refinement",
                                       g3, mesh_sequence(V0, F0, g3, 3), False)
        except Exception as exc:  # generator missing or its optional deps (gpytoolbox) absent
            cases["Walker genus 3"] = (f"SKIPPED: {type(exc).__name__}: {exc}", None, [], False)
    # robustness: every level jittered 0-30 % of the local edge length, re-projected
    # (jittering the ellipsoid mesh itself by 30 % of the *mean* incident edge
    # length folds some faces over where its edges are anisotropic; jittering the
    # sphere mesh and mapping it onto the ellipsoid cannot.)
    levels, _ = heine_sequence("5.1c", n, pre_refine=1, jitter=0.3, seed=100)
    cases["ellipsoid, jittered 30%"] = (
        "each level jittered on the unit sphere by up to 30 % of the local edge length, then "
        "scaled onto the ellipsoid and projected", ell, levels, False)
    levels, sa = heine_sequence("5.1a", n, pre_refine=1, jitter=0.3, seed=200)
    cases["Heine (5.1a), jittered 30%"] = (
        "each level jittered on the sphere by up to 30 % of the local edge length, mapped exactly",
        sa, levels, False)
    tor = WalkerTorus()
    V0, F0 = torus_coarse(12, 48, amount=0.1, seed=1)
    cases["torus, anisotropic"] = ("12 x 48 (phi, t) grid: long thin triangles (longest edge² / 2|T| ≈ 9), refinement",
                                   tor, mesh_sequence(V0, F0, tor, 3 if quick else 4), False)
    sad = WalkerSaddle()
    V0, F0 = graph_coarse(sad, n=4, amount=0.25, seed=0)
    cases["open saddle patch"] = ("Walker's saddle graph over [0,1]^2 (boundary), refinement",
                                  sad, mesh_sequence(V0, F0, sad, 3 if quick else 4, pre_refine=2), True)
    return cases


# --------------------------------------------------------------------------- measuring
def _rss_reset():
    """Reset the peak-RSS counter (Linux) and return the current RSS in bytes, or None."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return _proc_status("VmRSS")
    except OSError:
        return None


def _proc_status(key):
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


def call_estimator(name, V, F):
    """Run one estimator; returns (estimate or None, seconds, peak extra bytes or None, note)."""
    from ..hhj import SolverDidNotConverge
    note = ""
    rss0 = _rss_reset()
    t0 = time.perf_counter()
    try:
        if name.startswith("hhj"):
            try:
                est = ESTIMATORS[name](V, F)
            except SolverDidNotConverge:
                note = "CG did not converge; direct solve"
                est = ESTIMATORS[name](V, F, solver="direct")
        else:
            est = ESTIMATORS[name](V, F)
    except ImportError as exc:
        return None, 0.0, None, f"not installed ({exc.name})"
    except Exception as exc:
        return None, time.perf_counter() - t0, None, f"FAILED: {type(exc).__name__}: {str(exc)[:120]}"
    dt = time.perf_counter() - t0
    peak = _proc_status("VmHWM")
    mem = (peak - rss0) if (peak is not None and rss0 is not None) else None
    return est, dt, mem, note


def _lumped(mesh):
    return np.bincount(mesh.F.ravel(), weights=np.repeat(mesh.face_areas / 3, 3), minlength=mesh.n_vertices)


def errors(mesh, est, surface, open_patch=False):
    """Relative errors of one estimate against the exact surface (see module docstring)."""
    X = mesh.V
    k1e, k2e = surface.principal_curvatures(X)
    ex = {"k1": k1e, "k2": k2e, "H": 0.5 * (k1e + k2e), "K": k1e * k2e}
    w = _lumped(mesh)
    vmask = mesh.referenced_vertices.copy()
    if open_patch:
        vmask &= ~mesh.boundary_vertices
    norms = {q: np.sqrt(np.sum(w[vmask] * ex[q][vmask] ** 2)) for q in QUANTS}
    maxs = {q: np.max(np.abs(ex[q][vmask])) for q in QUANTS}
    out = {"h": mesh.max_edge_length, "faces": mesh.n_faces, "bad": int(len(est.bad))}
    if est.location == "vertex":
        finite = np.isfinite(est.k1) & np.isfinite(est.k2) & np.isfinite(est.H) & np.isfinite(est.K)
        out["nan"] = int(np.sum(vmask & ~finite))
        m = vmask & finite
        for q in QUANTS:
            d = getattr(est, q) - ex[q]
            out[q] = float(np.sqrt(np.sum(w[m] * d[m] ** 2)) / norms[q])
            out[q + "_inf"] = float(np.max(np.abs(d[m])) / maxs[q])
        if est.d1 is not None:
            d1e, _ = surface.principal_directions(X)
            gap = (k1e - k2e) > 0.1 * (np.abs(k1e) + np.abs(k2e))
            md = m & gap & np.isfinite(est.d1).all(axis=1)
            ang = np.degrees(np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", est.d1, d1e)), 0, 1)))
            out["dir"] = float(np.sqrt(np.sum(w[md] * ang[md] ** 2) / np.sum(w[md]))) if md.any() else np.nan
            out["dir_inf"] = float(ang[md].max()) if md.any() else np.nan
    else:  # face values vs P1 interpolant of the exact field
        fmask = vmask[mesh.F].all(axis=1)
        finite = np.isfinite(est.k1) & np.isfinite(est.K)
        out["nan"] = int(np.sum(fmask & ~finite))
        fm = fmask & finite
        A = mesh.face_areas[fm]
        for q in QUANTS:
            U = ex[q][mesh.F[fm]]
            mid = 0.5 * (U[:, [1, 2, 0]] + U[:, [2, 0, 1]])
            D = mid - getattr(est, q)[fm][:, None]
            out[q] = float(np.sqrt(np.sum(A * (D ** 2).mean(axis=1))) / norms[q])
            out[q + "_inf"] = float(np.max(np.abs(U - getattr(est, q)[fm][:, None])) / maxs[q])
        C = surface.project(mesh.V[mesh.F].mean(axis=1))
        c1, c2 = surface.principal_curvatures(C)
        d1e, _ = surface.principal_directions(C)
        gap = (c1 - c2) > 0.1 * (np.abs(c1) + np.abs(c2))
        md = fm & gap
        ang = np.degrees(np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", est.d1, d1e)), 0, 1)))
        Af = mesh.face_areas
        out["dir"] = float(np.sqrt(np.sum(Af[md] * ang[md] ** 2) / np.sum(Af[md]))) if md.any() else np.nan
        out["dir_inf"] = float(ang[md].max()) if md.any() else np.nan
    return out


def _rate(hs, es, last=3):
    hs, es = np.asarray(hs[-last:], float), np.asarray(es[-last:], float)
    ok = np.isfinite(es) & (es > 0)
    if ok.sum() < 2:
        return np.nan
    return float(np.polyfit(np.log(hs[ok]), np.log(es[ok]), 1)[0])


def _eocs(hs, es):
    e, h = np.asarray(es, float), np.asarray(hs, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return list(np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:]))


# --------------------------------------------------------------------------- sections
def accuracy(cases, estimators, progress):
    res = {}
    for cname, (desc, surface, levels, open_patch) in cases.items():
        res[cname] = {"description": desc, "open": open_patch, "levels": [], "runs": {}}
        if surface is None:
            continue
        for V, F in levels:
            mesh = as_mesh(V, F)
            res[cname]["levels"].append({"faces": mesh.n_faces, "h": mesh.max_edge_length})
            for name in estimators:
                progress.set_postfix_str(f"{cname[:18]} {mesh.n_faces}f {name}")
                est, dt, mem, note = call_estimator(name, V, F)
                r = res[cname]["runs"].setdefault(name, [])
                if est is None:
                    r.append({"note": note, "time": dt})
                else:
                    e = errors(mesh, est, surface, open_patch)
                    e.update(time=dt, note=note)
                    r.append(e)
                progress.update(1)
    return res


def speed(sizes, estimators, progress):
    """Wall time and peak extra memory per estimator on refined ellipsoids."""
    from ..surfaces.exact import Ellipsoid
    from ..surfaces.meshing import ellipsoid_coarse, refine
    ell = Ellipsoid()
    V, F = ellipsoid_coarse(ell, subdivisions=1)
    out = []
    done = 0
    for target in sorted(sizes):
        while len(F) < target:
            V, F = refine(V, F, ell, 1)
        row = {"faces": int(len(F)), "vertices": int(len(V)), "runs": {}}
        for name in estimators:
            progress.set_postfix_str(f"speed {len(F)}f {name}")
            est, dt, mem, note = call_estimator(name, V, F)
            row["runs"][name] = {"time": dt if est is not None else None, "mem": mem, "note": note}
            progress.update(1)
        out.append(row)
        done += 1
    return out


def real_meshes(folder, estimators, outdir, screenshots, progress):
    import igl
    rows = []
    files = sorted(Path(folder).glob("*.off")) if folder and Path(folder).is_dir() else []
    for path in files:
        V, F = igl.read_triangle_mesh(str(path))
        row = {"mesh": path.name, "vertices": int(len(V)), "faces": int(len(F)), "runs": {}, "shots": []}
        ests = {}
        for name in estimators:
            progress.set_postfix_str(f"{path.name} {name}")
            est, dt, mem, note = call_estimator(name, V, F)
            if est is None:
                row["runs"][name] = {"note": note, "time": dt}
            else:
                vals = np.stack([est.k1, est.k2], axis=1)
                row["runs"][name] = {"time": dt, "note": note, "bad": int(len(est.bad)),
                                     "nan": int(np.sum(~np.isfinite(vals).all(axis=1))),
                                     "p99_abs_k1": float(np.nanpercentile(np.abs(est.k1), 99))}
                ests[name] = est
            progress.update(1)
        if screenshots and "hhj_face" in ests and "libigl_quadric" in ests:
            try:
                from .. import viewer
                for q in ("k1", "k2"):
                    fn = outdir / f"real_{path.stem}_{q}.png"
                    viewer.register_comparison(V, F, hhj=ests["hhj_face"], libigl=ests["libigl_quadric"],
                                               enabled=q, robust=5.0, directions=False, screenshot=fn,
                                               size=(1000, 500))
                    row["shots"].append(fn.name)
            except Exception as exc:
                row["shots_error"] = f"{type(exc).__name__}: {exc}"
        rows.append(row)
    return rows


# --------------------------------------------------------------------------- report
def _fmt(x, nd=3):
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "–"
    if isinstance(x, str):
        return x
    ax = abs(x)
    return f"{x:.{nd}g}" if ax >= 1e-3 or ax == 0 else f"{x:.2e}"


def _plots(acc, outdir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..convergence import plot_convergence
    files = []
    for cname, c in acc.items():
        if not c["levels"]:
            continue
        fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
        for ax, q, title in zip(axes, ("H", "K", "k1", "dir"),
                                ("rel. L2 error of H", "rel. L2 error of K", "rel. L2 error of κ1",
                                 "RMS angle of κ1 direction (deg)")):
            series = [(name, [r["h"] for r in runs if q in r], [r[q] for r in runs if q in r])
                      for name, runs in c["runs"].items()]
            series = [s for s in series if len(s[2]) >= 2 and np.all(np.isfinite(s[2]))]
            if series:
                plot_convergence([s[1] for s in series], [s[2] for s in series], [s[0] for s in series],
                                 ax=ax, title=title, legend=False)
        axes[0].legend(fontsize=7)
        fig.suptitle(cname)
        fig.tight_layout()
        fn = outdir / f"conv_{''.join(ch if ch.isalnum() else '_' for ch in cname)}.png"
        fig.savefig(fn, dpi=90)
        plt.close(fig)
        files.append(fn.name)
    return files


SUMMARY_CASES = ("Heine (5.1a), jittered 30%", "torus, anisotropic", "ellipsoid (5.1c)")
SUMMARY_ESTIMATORS = ("hhj_vertex", "hhj_face", "libigl_quadric", "libigl_quadric_k2", "libigl_cotan", "heine")


def _summary_plot(acc, outdir):
    """One figure for the docs (compare_estimators_H.png in demos/images): relative L2 error of H vs h on three cases."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..convergence import plot_convergence
    cases = [c for c in SUMMARY_CASES if c in acc and acc[c]["levels"]]
    if not cases:
        return None
    fig, axes = plt.subplots(1, len(cases), figsize=(4.2 * len(cases), 3.6), squeeze=False)
    for ax, cname in zip(axes[0], cases):
        series = []
        for name in SUMMARY_ESTIMATORS:
            runs = acc[cname]["runs"].get(name, [])
            pts = [(r["h"], r["H"]) for r in runs if "H" in r and np.isfinite(r["H"])]
            if len(pts) >= 2:
                series.append((name, *zip(*pts)))
        if series:
            hhj = [s[0].startswith("hhj") for s in series]
            plot_convergence([s[1] for s in series], [s[2] for s in series], [s[0] for s in series], ax=ax,
                             title=cname, legend=False,
                             styles=[{"marker": "o" if b else "s", "ls": "-" if b else "--", "lw": 2 if b else 1}
                                     for b in hhj])
    axes[0][0].set_ylabel("relative L2 error of H")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fn = outdir / "summary_H.png"
    fig.savefig(fn, dpi=80)
    plt.close(fig)
    return fn.name


def write_report(res, outdir):
    L = ["# Curvature estimators compared: HHJ vs libigl, Heine, pymeshlab", "",
         f"Produced by `python -m igl_hhj.benchmarks.compare_estimators` ({res['mode']} mode) on "
         f"{res['machine']}, {res['date']}. Total run time {res['total_time']:.0f} s.", "",
         "All errors are **relative** (see the module docstring). *rate* = least-squares EOC over the "
         "last three levels (O(h) = 1). `dir` = RMS angle (degrees) of the κ1 direction away from umbilics. "
         "`bad` = points without a value (NaN / flagged).", ""]
    if res.get("summary_plot"):
        L += [f"![relative L2 error of H]({res['summary_plot']})", ""]
    L += ["## Headline: relative L2 error of H and RMS κ1-direction angle on the finest mesh", "",
          "| case | best H (estimator) | hhj_vertex H | libigl_quadric H | libigl_cotan H | heine H | "
          "best dir ° (estimator) | hhj_vertex dir ° |", "|---|---|---|---|---|---|---|---|"]
    for cname, c in res["accuracy"].items():
        if not c["levels"]:
            continue
        last = {n: runs[-1] for n, runs in c["runs"].items() if "H" in runs[-1]}
        if not last:
            continue
        bh = min(last, key=lambda n: last[n]["H"])
        dirs = {n: r["dir"] for n, r in last.items() if np.isfinite(r.get("dir", np.nan))}
        bd = min(dirs, key=dirs.get) if dirs else None
        get = lambda n, k="H": _fmt(last[n][k]) if n in last and k in last[n] else "–"  # noqa: E731
        L.append(f"| {cname} | {_fmt(last[bh]['H'])} ({bh}) | {get('hhj_vertex')} | {get('libigl_quadric')} | "
                 f"{get('libigl_cotan')} | {get('heine')} | "
                 f"{(_fmt(dirs[bd]) + ' (' + bd + ')') if bd else '–'} | {get('hhj_vertex', 'dir')} |")
    L += [""]
    L += ["## Accuracy: finest mesh and rates", ""]
    for cname, c in res["accuracy"].items():
        L += [f"### {cname}", "", c["description"] + ("  (norms over interior vertices)" if c["open"] else ""), ""]
        if not c["levels"]:
            L += [""]
            continue
        L += ["faces per level: " + ", ".join(str(lv["faces"]) for lv in c["levels"]), ""]
        L += ["| estimator | κ1 | rate | κ2 | rate | H | rate | K | rate | H L∞ | dir (°) | rate | bad | time (s) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for name, runs in c["runs"].items():
            last = runs[-1]
            if "k1" not in last:
                L.append(f"| {name} | {last.get('note', '')} |" + " |" * 13)
                continue
            hs = [r["h"] for r in runs]
            cells = [name]
            for q in QUANTS:
                cells += [_fmt(last[q]), _fmt(_rate(hs, [r[q] for r in runs]), 2)]
            cells += [_fmt(last["H_inf"])]
            if "dir" in last:
                cells += [_fmt(last["dir"]), _fmt(_rate(hs, [r["dir"] for r in runs]), 2)]
            else:
                cells += ["–", "–"]
            cells += [str(last["bad"] + last.get("nan", 0)), _fmt(last["time"], 2)]
            if last.get("note"):
                cells[0] += "*"
            L.append("| " + " | ".join(cells) + " |")
        notes = {r.get("note") for runs in c["runs"].values() for r in runs if r.get("note")}
        if notes:
            L += ["", "Notes: " + "; ".join(sorted(notes))]
        if "plot" in c:
            L += ["", f"![{cname}]({c['plot']})"]
        L.append("")
    # Heine's paper beside ours
    L += ["## Heine's P1 Weingarten map: paper vs this run", "",
          "Paper (003, Tables 5.1/5.3, degree 1, bisection-refined meshes): relative L2 error of H and K "
          "does not decrease.", "",
          "| surface | source | h | E_H,2 | E_K,2 |", "|---|---|---|---|---|"]
    for lab, d in HEINE_PAPER_P1.items():
        for h, eh, ek in list(zip(d["h"], d["E_H2"], d["E_K2"]))[-3:]:
            L.append(f"| ({lab}) | paper | {h} | {eh} | {ek} |")
    for cname in ("Heine (5.1a)", "Heine (5.1a), jittered 30%", "ellipsoid (5.1c)", "ellipsoid, jittered 30%"):
        c = res["accuracy"].get(cname)
        if not c or "heine" not in c["runs"]:
            continue
        for r in c["runs"]["heine"][-3:]:
            if "H" in r:
                L.append(f"| {cname} | ours | {_fmt(r['h'])} | {_fmt(r['H'])} | {_fmt(r['K'])} |")
    L += ["", "Per-level errors and EOC of H for every case: see `compare_estimators.json` and the detail "
          "tables below.", ""]
    L += ["## Detail: relative L2 error of H per level (EOC in parentheses)", ""]
    for cname, c in res["accuracy"].items():
        if not c["levels"]:
            continue
        names = [n for n, runs in c["runs"].items() if "H" in runs[-1]]
        L += [f"**{cname}**", "", "| faces | h | " + " | ".join(names) + " |",
              "|---|---|" + "---|" * len(names)]
        for i, lv in enumerate(c["levels"]):
            cells = [str(lv["faces"]), _fmt(lv["h"])]
            for n in names:
                runs = c["runs"][n]
                e = [r.get("H", np.nan) for r in runs]
                s = _fmt(e[i])
                if i:
                    s += f" ({_fmt(_eocs([r.get('h', np.nan) for r in runs], e)[i - 1], 2)})"
                cells.append(s)
            L.append("| " + " | ".join(cells) + " |")
        L.append("")
    # speed
    L += ["## Speed and memory (refined ellipsoid, one run each, same process)", "",
          f"Ratios are time / time of `{REFERENCE}` on the same mesh in this run. Peak memory = peak RSS "
          "increase during the call (Linux VmHWM, reset before each call), includes libigl's C++ allocations "
          "but not memory the process already holds from earlier calls (hence 0 MB for small libigl runs): "
          "a lower bound.", ""]
    if res["speed"]:
        names = list(res["speed"][0]["runs"])
        L += ["| faces | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
        for row in res["speed"]:
            ref = row["runs"].get(REFERENCE, {}).get("time")
            cells = [str(row["faces"])]
            for n in names:
                r = row["runs"][n]
                if r["time"] is None:
                    cells.append(r["note"] or "–")
                    continue
                s = f"{r['time']:.2f} s"
                if ref:
                    s += f" ({r['time'] / ref:.2f}×)"
                if r["mem"] is not None:
                    s += f", {r['mem'] / 2**20:.0f} MB"
                if r["note"]:
                    s += "*"
                cells.append(s)
            L.append("| " + " | ".join(cells) + " |")
        L.append("")
    # real meshes
    L += ["## Real meshes (`shared/data/meshes`)", "",
          "Per estimator: time (s), points without a value (bad/NaN), 99th percentile of |κ1|. Screenshots: HHJ "
          "per face (left) vs libigl per vertex (right), same colour range.", ""]
    if res["real"]:
        names = list(res["real"][0]["runs"])
        L += ["| mesh | #F | " + " | ".join(names) + " |", "|---|---|" + "---|" * len(names)]
        for row in res["real"]:
            cells = [row["mesh"], str(row["faces"])]
            for n in names:
                r = row["runs"][n]
                if "bad" not in r:
                    cells.append(r.get("note", "–"))
                else:
                    cells.append(f"{r['time']:.2f} s, bad {r['bad']}, NaN {r['nan']}, |κ1|₉₉ {r['p99_abs_k1']:.3g}"
                                 + ("*" if r["note"] else ""))
            L.append("| " + " | ".join(cells) + " |")
        L.append("")
        for row in res["real"]:
            for s in row["shots"]:
                L.append(f"![{s}]({s})")
            if "shots_error" in row:
                L.append(f"Screenshot failed for {row['mesh']}: {row['shots_error']}")
        L.append("")
    else:
        L += ["(skipped)", ""]
    (outdir / "compare_estimators.md").write_text("\n".join(L))


def run(out="benchmark-results", quick=False, real=None, do_speed=True, screenshots=None,
        speed_sizes=None, estimators=None, mesh_folder=None, cases=None):
    """Run the whole comparison and write the report.

    Parameters
    ----------
    out : output folder (created).
    quick : small meshes, fewer cases (for tests: a few seconds).
    real : run the real meshes (default: not quick).
    do_speed : run the speed section.
    screenshots : headless polyscope screenshots of the real meshes (default: ``real``).
    speed_sizes : face counts for the speed section.
    estimators : names from :data:`igl_hhj.baselines.ESTIMATORS` (default: all but
        pymeshlab's PCA / normal cycles, whose default outputs are not curvatures).
    mesh_folder : folder of ``*.off`` meshes (default ``../shared/data/meshes`` from the cwd
        or the repository).
    cases : optional list of case names (keys of :func:`build_cases`) to run.

    Returns
    -------
    dict with keys "accuracy", "speed", "real", and the path of the report under "report".
    """
    from tqdm import tqdm
    t0 = time.perf_counter()
    outdir = Path(out)
    outdir.mkdir(parents=True, exist_ok=True)
    real = (not quick) if real is None else real
    screenshots = real if screenshots is None else screenshots
    if estimators is None:
        estimators = list(DEFAULT_ESTIMATORS)
    unknown = [e for e in estimators if e not in ESTIMATORS]
    if unknown:
        raise ValueError(f"unknown estimators {unknown}; use names from {sorted(ESTIMATORS)}")
    try:
        import pymeshlab  # noqa: F401
    except ImportError:
        estimators = [e for e in estimators if not e.startswith("pymeshlab")]
    if speed_sizes is None:
        speed_sizes = [1280, 5120] if quick else [20480, 81920, 327680, 1310720]
    if mesh_folder is None:
        for cand in (Path("../shared/data/meshes"), Path(__file__).resolve().parents[3] / "shared/data/meshes"):
            if cand.is_dir():
                mesh_folder = cand
                break
    all_cases = build_cases(quick)
    if cases is not None:
        missing = [c for c in cases if c not in all_cases]
        if missing:
            raise ValueError(f"unknown cases {missing}; use names from {list(all_cases)}")
        all_cases = {c: all_cases[c] for c in cases}
    cases = all_cases
    n_acc = sum(len(c[2]) for c in cases.values()) * len(estimators)
    n_speed = len(speed_sizes) * len(estimators) if do_speed else 0
    n_real = (len(list(Path(mesh_folder).glob("*.off"))) * len(estimators)) if (real and mesh_folder) else 0
    with tqdm(total=n_acc + n_speed + n_real, desc="compare_estimators", unit="run", disable=None) as bar:
        acc = accuracy(cases, estimators, bar)
        spd = speed(speed_sizes, estimators, bar) if do_speed else []
        rl = real_meshes(mesh_folder, estimators, outdir, screenshots, bar) if n_real else []
    for cname, fn in zip([c for c in acc if acc[c]["levels"]], _plots(acc, outdir)):
        acc[cname]["plot"] = fn
    summary = _summary_plot(acc, outdir)
    import platform
    res = {"accuracy": acc, "speed": spd, "real": rl, "mode": "quick" if quick else "full",
           "machine": f"{platform.machine()}, {os.cpu_count()} CPUs, Python {platform.python_version()}",
           "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "estimators": estimators,
           "summary_plot": summary}
    res["total_time"] = time.perf_counter() - t0
    write_report(res, outdir)
    (outdir / "compare_estimators.json").write_text(json.dumps(res, indent=1, default=float))
    res["report"] = str(outdir / "compare_estimators.md")
    return res


def main(argv=None):
    p = argparse.ArgumentParser(description="Compare HHJ curvature with libigl, Heine and pymeshlab.")
    p.add_argument("--out", default="benchmark-results",
                   help="folder for the tables, plots and screenshots (default ./benchmark-results/)")
    p.add_argument("--quick", action="store_true", help="small meshes, few cases (seconds)")
    p.add_argument("--no-real", action="store_true", help="skip the real meshes and screenshots")
    p.add_argument("--no-speed", action="store_true", help="skip the speed section")
    p.add_argument("--no-screenshots", action="store_true", help="skip the polyscope screenshots")
    p.add_argument("--estimators", nargs="+", help=f"subset of {sorted(ESTIMATORS)}")
    a = p.parse_args(argv)
    try:
        res = run(a.out, quick=a.quick, real=False if a.no_real else None, do_speed=not a.no_speed,
                  screenshots=False if a.no_screenshots else None, estimators=a.estimators)
    except Exception:
        traceback.print_exc()
        raise SystemExit(1)
    print(f"wrote {res['report']} ({res['total_time']:.0f} s)")


if __name__ == "__main__":
    main()
