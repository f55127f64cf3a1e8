"""Heine's tables 5.1–5.4 (paper 003) for Lagrange degree γ = 1, 2, 3 on isoparametric
curved surfaces (igl_hhj.curved.heine_weingarten).

Surfaces (5.1a)–(5.1d) (:mod:`igl_hhj.surfaces.heine`), perturbed icosphere
sequences (:func:`~igl_hhj.surfaces.heine.heine_sequence`), the surface of
degree γ the nodal Lagrange interpolant of the closest-point map (as Heine:
"the discrete surface is just the interpolation of the exact shape").  Errors
are Heine's relative ones, ``‖C - C_h‖_{L_r(Γ_h)} / ‖C‖_{L_r(Γ_h)}`` for
C ∈ {K, H}, r ∈ {2, ∞}, with H_h = tr Π_h / 2 and K_h the sum of the 2×2
principal minors of Π_h, the exact C at the projection of each quadrature
point.  Run::

    python -m igl_hhj.benchmarks.heine_curved [--levels 4] [--degrees 1 2] [--jitter 0.3]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ..convergence import eoc
from ..curved import LagrangeSurface, heine_weingarten

__all__ = ["PAPER_HEINE_EOC", "run", "heine_errors", "main"]

# Heine Tables 5.1–5.4, polynomial degree 2: EOC of the last refinement, (E_K2, E_Kinf, E_H2, E_Hinf).
# Copied from shared/papers/003_*.txt; NOT computed by this project.
PAPER_HEINE_EOC = {
    "5.1a": {2: (1.4, 1.9, 1.2, 1.2), 1: (-0.0023, -0.0059, -0.0021, -0.0092)},
    "5.1b": {2: (2.0, 2.2, 1.4, 1.4)},
    "5.1c": {2: (1.2, 1.2, 1.1, 1.1)},
    "5.1d": {2: (2.4, 2.0, 2.4, 2.0)},
}


def heine_errors(field, surface_exact, degree=None):
    """Heine's relative errors of K_h and H_h: dict h, K2, Kinf, H2, Hinf."""
    surf = field.surface
    faces, bary, w = surf.quadrature(degree)
    Pi = field.space.evaluate(field.coefficients, faces, bary).reshape(-1, 3, 3)
    tr = np.trace(Pi, axis1=1, axis2=2)
    H = 0.5 * tr
    K = 0.5 * (tr ** 2 - np.einsum("nij,nji->n", Pi, Pi))
    Xp = surface_exact.project(surf.points(faces, bary))
    He, Ke = surface_exact.mean_curvature(Xp), surface_exact.gauss_curvature(Xp)

    def rel2(a, b):
        return float(np.sqrt(np.sum(w * (a - b) ** 2) / np.sum(w * b ** 2)))

    def relinf(a, b):
        return float(np.abs(a - b).max() / np.abs(b).max())
    return {"h": surf.h, "faces": surf.n_faces, "K2": rel2(K, Ke), "Kinf": relinf(K, Ke),
            "H2": rel2(H, He), "Hinf": relinf(H, He)}


def run(labels=("5.1a", "5.1b", "5.1c", "5.1d"), degrees=(1, 2), levels=4, seed=100, jitter=0.3):
    """dict (label, γ) → list of per-level error dicts (plus ``seconds``).

    ``jitter`` re-perturbs every level (:func:`heine_sequence`): uniform refinement
    alone leaves locally symmetric (parallelogram) patches on which degree 1
    superconverges (measured on (5.1a): E_K,2 EOC 1.75 without jitter), unlike
    Heine's bisection meshes."""
    from ..surfaces.heine import heine_sequence
    res = {}
    for lab in labels:
        seq, s = heine_sequence(lab, levels, pre_refine=1, jitter=jitter, seed=seed)
        for g in degrees:
            rows = []
            for V, F in seq:
                t0 = time.perf_counter()
                surf = LagrangeSurface.from_projection(V, F, g, s.project, interpolant="nodal")
                e = heine_errors(heine_weingarten(surf, g), s)
                e["seconds"] = time.perf_counter() - t0
                rows.append(e)
            res[(lab, g)] = rows
    return res


def format_table(lab, g, rows):
    keys = ("K2", "Kinf", "H2", "Hinf")
    hs = [r["h"] for r in rows]
    rates = {k: np.concatenate([[np.nan], eoc([r[k] for r in rows], hs)]) for k in keys}
    lines = [f"## Heine ({lab}), degree γ = {g}", "",
             "| h_max | #F | E_K,2 | E_K,∞ | E_H,2 | E_H,∞ |", "|---|---|---|---|---|---|"]
    for i, r in enumerate(rows):
        cells = [f"{r[k]:.2g}" + ("" if not np.isfinite(rates[k][i]) else f" ({rates[k][i]:.2f})") for k in keys]
        lines.append(f"| {r['h']:.3g} | {r['faces']} | " + " | ".join(cells) + " |")
    p = PAPER_HEINE_EOC.get(lab, {}).get(g)
    if p:
        lines.append("| paper, last EOC | | " + " | ".join(f"({v:.2g})" for v in p) + " |")
    lines.append("")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--levels", type=int, default=4)
    ap.add_argument("--degrees", type=int, nargs="+", default=[1, 2], choices=(1, 2, 3))
    ap.add_argument("--surfaces", nargs="+", default=["5.1a", "5.1b", "5.1c", "5.1d"])
    ap.add_argument("--jitter", type=float, default=0.3,
                    help="re-perturbation of every level (0: plain uniform refinement)")
    ap.add_argument("--seed", type=int, default=100)
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    res = run(a.surfaces, a.degrees, a.levels, seed=a.seed, jitter=a.jitter)
    for (lab, g), rows in res.items():
        print(format_table(lab, g, rows))
    print(f"total {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
