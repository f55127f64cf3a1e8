"""Heine's tables 5.1–5.4 (paper 003) for Lagrange degree γ = 1, 2, 3, 4 on isoparametric
curved surfaces (igl_hhj.curved.heine_weingarten).

Surfaces (5.1a)–(5.1d) (:mod:`igl_hhj.surfaces.heine`), perturbed icosphere
sequences (:func:`~igl_hhj.surfaces.heine.heine_sequence`), the surface of
degree γ the nodal Lagrange interpolant of the closest-point map (as Heine:
"the discrete surface is just the interpolation of the exact shape").  Errors
are Heine's relative ones, ``‖C - C_h‖_{L_r(Γ_h)} / ‖C‖_{L_r(Γ_h)}`` for
C ∈ {K, H}, r ∈ {2, ∞}, with H_h = tr Π_h / 2 and K_h the sum of the 2×2
principal minors of Π_h, the exact C at the projection of each quadrature
point.  Run::

    python -m igl_hhj.benchmarks.heine_curved [--levels 4] [--degrees 1 2 3 4] [--jitter 0.3] [--out DIR]

Also the absolute errors of Theorem 4.1, ``‖Y − Y_h‖`` (curvature vector, eq. 4.1) and
``‖Π − Π_h‖`` (nodal Weingarten map, eq. 4.2), and beside our last row Heine's row at the
nearest h_max and his last row (:data:`PAPER_HEINE_TABLES`).
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ..convergence import eoc
from ..curved import LagrangeSurface, heine_weingarten

__all__ = ["PAPER_HEINE_EOC", "PAPER_HEINE_TABLES", "run", "heine_errors", "format_table", "main"]

# Heine Tables 5.1–5.4, every row: (h_max, E_K2, EOC, E_Kinf, EOC, E_H2, EOC, E_Hinf, EOC)
# per surface and polynomial degree γ = 1..4 (None: no EOC on the first row).
# Parsed from shared/papers/003_*.txt; NOT computed by this project.
PAPER_HEINE_TABLES = {
    "5.1a": {
        1: [
            (0.135, 0.79, None, 1.4, None, 0.19, None, 0.36, None),
            (0.0689, 0.87, -0.16, 2.2, -0.61, 0.19, 0.055, 0.36, -0.028),
            (0.0361, 0.9, -0.041, 2.1, 0.015, 0.19, -0.0011, 0.4, -0.15),
            (0.0199, 0.91, -0.022, 2.3, -0.12, 0.19, -0.0065, 0.42, -0.081),
            (0.0114, 0.91, -0.0072, 2.3, -0.02, 0.19, -0.0042, 0.43, -0.024),
            (0.00654, 0.91, -0.0023, 2.3, -0.0059, 0.19, -0.0021, 0.43, -0.0092),
        ],
        2: [
            (0.372, 1.7, None, 2.5, None, 0.15, None, 0.48, None),
            (0.206, 1.0, 0.85, 2.7, -0.14, 0.085, 0.92, 0.31, 0.75),
            (0.118, 0.54, 1.2, 1.5, 1.0, 0.044, 1.2, 0.15, 1.3),
            (0.0681, 0.2, 1.8, 0.69, 1.4, 0.02, 1.4, 0.067, 1.5),
            (0.0382, 0.082, 1.6, 0.44, 0.78, 0.0099, 1.3, 0.044, 0.74),
            (0.0219, 0.032, 1.7, 0.13, 2.2, 0.0047, 1.3, 0.018, 1.6),
            (0.0123, 0.015, 1.4, 0.044, 1.9, 0.0023, 1.2, 0.0088, 1.2),
        ],
        3: [
            (0.488, 1.5, None, 3.6, None, 0.13, None, 0.49, None),
            (0.32, 2.1, -0.83, 5.4, -1.0, 0.15, -0.26, 0.58, -0.4),
            (0.191, 1.1, 1.1, 6.3, -0.3, 0.087, 1.0, 0.62, -0.12),
            (0.11, 0.17, 3.5, 1.3, 2.9, 0.022, 2.5, 0.17, 2.3),
            (0.064, 0.054, 2.1, 0.46, 1.9, 0.0068, 2.1, 0.083, 1.4),
            (0.0359, 0.014, 2.3, 0.13, 2.2, 0.0018, 2.3, 0.026, 2.0),
            (0.0202, 0.0036, 2.4, 0.034, 2.3, 0.00046, 2.4, 0.0069, 2.3),
        ],
        4: [
            (0.549, 4.5, None, 13.0, None, 0.3, None, 1.4, None),
            (0.324, 1.6, 2.0, 8.6, 0.77, 0.12, 1.8, 0.75, 1.2),
            (0.196, 0.34, 3.1, 1.5, 3.5, 0.035, 2.4, 0.24, 2.3),
            (0.121, 0.04, 4.4, 0.5, 2.2, 0.0048, 4.1, 0.055, 3.0),
            (0.0697, 0.0047, 3.9, 0.046, 4.3, 0.00074, 3.4, 0.0092, 3.2),
            (0.0402, 0.00061, 3.7, 0.0062, 3.6, 9.1e-05, 3.8, 0.0012, 3.7),
            (0.0232, 7.4e-05, 3.8, 0.00068, 4.0, 1.1e-05, 3.8, 0.00015, 3.8),
        ],
    },
    "5.1b": {
        1: [
            (0.205, 1.7, None, 1.9, None, 0.39, None, 0.69, None),
            (0.0957, 1.4, 0.22, 1.7, 0.14, 0.24, 0.64, 0.59, 0.21),
            (0.0508, 1.5, -0.11, 2.3, -0.44, 0.2, 0.29, 0.37, 0.75),
            (0.0263, 1.7, -0.19, 3.3, -0.56, 0.19, 0.057, 0.37, -0.025),
            (0.0151, 1.8, -0.091, 3.7, -0.21, 0.19, -0.0025, 0.41, -0.17),
            (0.00864, 1.8, -0.033, 3.7, -0.037, 0.2, -0.0041, 0.43, -0.085),
        ],
        2: [
            (0.368, 2.7, None, 5.2, None, 0.25, None, 0.58, None),
            (0.204, 4.4, -0.83, 11.0, -1.3, 0.15, 0.9, 0.42, 0.52),
            (0.116, 2.4, 1.1, 6.4, 1.0, 0.073, 1.2, 0.31, 0.53),
            (0.0673, 0.96, 1.7, 3.8, 0.95, 0.039, 1.2, 0.21, 0.71),
            (0.0379, 0.34, 1.8, 1.6, 1.5, 0.018, 1.3, 0.087, 1.6),
            (0.0214, 0.11, 2.0, 0.47, 2.2, 0.0085, 1.4, 0.039, 1.4),
        ],
        3: [
            (0.468, 12.0, None, 19.0, None, 0.45, None, 0.84, None),
            (0.322, 13.0, -0.15, 29.0, -1.1, 0.34, 0.73, 1.1, -0.78),
            (0.19, 10.0, 0.39, 50.0, -1.1, 0.19, 1.2, 1.4, -0.4),
            (0.113, 1.3, 4.0, 8.0, 3.5, 0.055, 2.3, 0.43, 2.3),
            (0.0653, 0.36, 2.3, 3.6, 1.4, 0.022, 1.7, 0.27, 0.82),
            (0.0373, 0.086, 2.6, 0.88, 2.5, 0.0062, 2.2, 0.1, 1.8),
        ],
        4: [
            (0.477, 15.0, None, 39.0, None, 0.45, None, 1.2, None),
            (0.304, 8.0, 1.4, 58.0, -0.87, 0.22, 1.6, 1.3, -0.16),
            (0.196, 1.2, 4.3, 9.2, 4.2, 0.055, 3.2, 0.45, 2.5),
            (0.115, 0.22, 3.3, 3.1, 2.0, 0.013, 2.7, 0.14, 2.2),
            (0.0655, 0.022, 4.1, 0.34, 3.9, 0.0019, 3.5, 0.026, 3.0),
            (0.0374, 0.0024, 3.9, 0.025, 4.7, 0.00023, 3.8, 0.0032, 3.7),
        ],
    },
    "5.1c": {
        1: [
            (0.2, 0.76, None, 1.4, None, 0.19, None, 0.45, None),
            (0.117, 0.83, -0.14, 1.7, -0.39, 0.18, 0.056, 0.39, 0.25),
            (0.0674, 0.83, -0.0022, 1.7, 0.028, 0.18, 0.019, 0.43, -0.2),
            (0.0384, 0.83, -0.0086, 1.7, -0.098, 0.18, -0.0021, 0.48, -0.17),
            (0.0218, 0.83, -0.0067, 1.7, 0.0033, 0.18, -0.0034, 0.54, -0.2),
            (0.0127, 0.84, -0.0037, 1.8, -0.012, 0.18, -0.0019, 0.59, -0.19),
        ],
        2: [
            (0.295, 0.69, None, 1.6, None, 0.086, None, 0.27, None),
            (0.19, 0.49, 0.77, 1.7, -0.23, 0.06, 0.81, 0.23, 0.41),
            (0.107, 0.21, 1.5, 1.1, 0.85, 0.026, 1.4, 0.12, 1.1),
            (0.0588, 0.069, 1.8, 0.47, 1.4, 0.011, 1.5, 0.063, 1.1),
            (0.0309, 0.025, 1.6, 0.17, 1.6, 0.0049, 1.2, 0.031, 1.1),
            (0.0159, 0.011, 1.3, 0.056, 1.7, 0.0024, 1.1, 0.013, 1.3),
            (0.00833, 0.0051, 1.2, 0.026, 1.2, 0.0012, 1.1, 0.0064, 1.1),
        ],
        3: [
            (0.309, 2.2, None, 8.3, None, 0.23, None, 1.0, None),
            (0.198, 0.76, 2.3, 3.4, 2.0, 0.09, 2.1, 0.59, 1.2),
            (0.131, 0.16, 3.8, 1.2, 2.6, 0.025, 3.1, 0.19, 2.8),
            (0.0788, 0.041, 2.7, 0.31, 2.6, 0.0067, 2.6, 0.063, 2.1),
            (0.0457, 0.011, 2.5, 0.086, 2.4, 0.0017, 2.5, 0.019, 2.2),
            (0.0259, 0.0027, 2.4, 0.024, 2.2, 0.00044, 2.4, 0.0052, 2.3),
            (0.0145, 0.00067, 2.4, 0.0063, 2.3, 0.00011, 2.4, 0.0014, 2.3),
        ],
        4: [
            (0.443, 7.5, None, 72.0, None, 0.39, None, 4.1, None),
            (0.265, 0.23, 6.8, 2.5, 6.5, 0.04, 4.4, 0.36, 4.7),
            (0.153, 0.024, 4.1, 0.24, 4.3, 0.0056, 3.6, 0.065, 3.1),
            (0.0908, 0.0027, 4.2, 0.027, 4.2, 0.00063, 4.2, 0.0059, 4.6),
            (0.0527, 0.00034, 3.8, 0.004, 3.5, 8e-05, 3.8, 0.0012, 2.9),
            (0.0297, 4.3e-05, 3.6, 0.00057, 3.4, 1e-05, 3.6, 0.00018, 3.4),
            (0.0168, 5.5e-06, 3.6, 9.9e-05, 3.1, 1.3e-06, 3.6, 2.8e-05, 3.2),
        ],
    },
    "5.1d": {
        1: [
            (0.126, 0.41, None, 1.1, None, 0.17, None, 0.43, None),
            (0.0717, 0.41, -0.015, 1.2, -0.19, 0.18, -0.014, 0.47, -0.13),
            (0.0407, 0.42, -0.0048, 1.2, 0.088, 0.18, -0.0062, 0.45, 0.085),
            (0.0231, 0.42, -0.0038, 1.2, 0.012, 0.18, -0.0041, 0.44, 0.012),
            (0.0131, 0.42, -0.0022, 1.2, 0.0027, 0.18, -0.0023, 0.44, 0.0022),
            (0.00743, 0.42, -0.0012, 1.2, 0.0011, 0.18, -0.0012, 0.48, -0.13),
        ],
        2: [
            (0.395, 0.052, None, 0.18, None, 0.021, None, 0.082, None),
            (0.242, 0.025, 1.5, 0.13, 0.74, 0.0055, 2.7, 0.031, 2.0),
            (0.138, 0.0073, 2.2, 0.048, 1.7, 0.0014, 2.5, 0.01, 2.0),
            (0.0784, 0.0019, 2.4, 0.016, 1.9, 0.00034, 2.4, 0.0033, 2.0),
            (0.0441, 0.00049, 2.4, 0.0053, 2.0, 8.6e-05, 2.4, 0.001, 2.0),
            (0.0249, 0.00012, 2.4, 0.0017, 2.0, 2.2e-05, 2.4, 0.00033, 2.0),
            (0.014, 3.1e-05, 2.4, 0.00053, 2.0, 5.4e-06, 2.4, 0.00011, 2.0),
            (0.00787, 7.7e-06, 2.4, 0.00017, 2.0, 1.4e-06, 2.4, 3.3e-05, 2.0),
        ],
        3: [
            (0.515, 0.27, None, 2.5, None, 0.11, None, 0.54, None),
            (0.284, 0.096, 1.7, 0.52, 2.6, 0.048, 1.5, 0.23, 1.4),
            (0.154, 0.021, 2.5, 0.12, 2.4, 0.011, 2.4, 0.06, 2.2),
            (0.0863, 0.0048, 2.5, 0.037, 2.0, 0.0028, 2.4, 0.02, 1.9),
            (0.0486, 0.0012, 2.4, 0.01, 2.2, 0.0007, 2.4, 0.0061, 2.1),
            (0.0273, 0.00031, 2.4, 0.0032, 2.0, 0.00018, 2.4, 0.0019, 2.0),
            (0.0154, 7.8e-05, 2.4, 0.001, 2.0, 4.5e-05, 2.4, 0.00061, 2.0),
            (0.00856, 2e-05, 2.4, 0.00034, 1.9, 1.1e-05, 2.4, 0.0002, 1.9),
        ],
        4: [
            (0.793, 0.14, None, 0.86, None, 0.058, None, 0.26, None),
            (0.448, 0.025, 2.9, 0.14, 3.2, 0.012, 2.7, 0.056, 2.7),
            (0.244, 0.0015, 4.7, 0.0081, 4.7, 0.0008, 4.5, 0.0039, 4.4),
            (0.144, 0.00028, 3.2, 0.003, 1.9, 0.00014, 3.4, 0.0015, 1.8),
            (0.0817, 1.9e-05, 4.7, 0.00026, 4.3, 9.7e-06, 4.6, 0.00014, 4.2),
            (0.0464, 2.8e-06, 3.4, 7.5e-05, 2.2, 1.4e-06, 3.4, 3.8e-05, 2.3),
            (0.0261, 2.4e-07, 4.2, 1.5e-05, 2.8, 1.2e-07, 4.2, 7.5e-06, 2.8),
            (0.0146, 3.4e-08, 3.4, 5.4e-06, 1.8, 1.7e-08, 3.4, 2.7e-06, 1.8),
        ],
    },
}

#: EOC of the paper's last refinement, (E_K2, E_Kinf, E_H2, E_Hinf), per surface and γ.
PAPER_HEINE_EOC = {lab: {g: rows[-1][2::2] for g, rows in d.items()} for lab, d in PAPER_HEINE_TABLES.items()}

#: Heine's mesh family (§5): adaptive refinement until the L2 distance to the exact surface
#: is below this, then global refinement.
HEINE_GEOMETRIC_TOLERANCE = 0.005


def heine_errors(field, surface_exact, degree=None):
    """Heine's relative errors of K_h and H_h: dict h, K2, Kinf, H2, Hinf; and the
    absolute errors of Theorem 4.1, ``Y2 = ‖Y − Y_h‖_{L2(Γ_h)}`` (curvature vector,
    Y = 2Hν, eq. 4.1) and ``Pi2 = ‖Π − Π_h‖_{L2(Γ_h)}`` (the nodal 3×3 Π_h of
    Definition 3.2 against ∇_Γν, eq. 4.2), both at the projections of the
    quadrature points of Γ_h (proven rate γ − 1)."""
    surf = field.surface
    faces, bary, w = surf.quadrature(degree)
    Pi = field.space.evaluate(field.coefficients, faces, bary).reshape(-1, 3, 3)
    Yh = field.space.evaluate(field.raw["Y"], faces, bary)
    tr = np.trace(Pi, axis1=1, axis2=2)
    H = 0.5 * tr
    K = 0.5 * (tr ** 2 - np.einsum("nij,nji->n", Pi, Pi))
    Xp = surface_exact.project(surf.points(faces, bary))
    He, Ke = surface_exact.mean_curvature(Xp), surface_exact.gauss_curvature(Xp)
    Ye = 2.0 * He[:, None] * surface_exact.normal(Xp)
    Pie = surface_exact.shape_operator(Xp)

    def rel2(a, b):
        return float(np.sqrt(np.sum(w * (a - b) ** 2) / np.sum(w * b ** 2)))

    def relinf(a, b):
        return float(np.abs(a - b).max() / np.abs(b).max())
    return {"h": surf.h, "faces": surf.n_faces, "K2": rel2(K, Ke), "Kinf": relinf(K, Ke),
            "H2": rel2(H, He), "Hinf": relinf(H, He),
            "Y2": float(np.sqrt(np.sum(w * ((Yh - Ye) ** 2).sum(1)))),
            "Pi2": float(np.sqrt(np.sum(w * ((Pi - Pie) ** 2).sum((1, 2)))))}


def run(labels=("5.1a", "5.1b", "5.1c", "5.1d"), degrees=(1, 2), levels=4, seed=100, jitter=0.3,
        meshes="jittered", tolerance=HEINE_GEOMETRIC_TOLERANCE):
    """dict (label, γ) → list of per-level error dicts (plus ``seconds``).

    ``meshes="jittered"``: ``jitter`` re-perturbs every level (:func:`heine_sequence`): uniform
    refinement alone leaves locally symmetric (parallelogram) patches on which degree 1
    superconverges (measured on (5.1a): E_K,2 EOC 1.75 without jitter), unlike
    Heine's bisection meshes.  ``meshes="heine"``: Heine's family, per γ
    (:func:`~igl_hhj.surfaces.heine.heine_adaptive_sequence`: adaptive bisection of the
    icosahedron until the geometric L2 error of the degree-γ surface is below
    ``tolerance``, then global double bisection); each row also gets ``geometric_error``."""
    from ..surfaces.heine import heine_adaptive_sequence, heine_sequence
    if meshes not in ("jittered", "heine"):
        raise ValueError(f"meshes must be 'jittered' or 'heine', got {meshes!r}")
    res = {}
    for lab in labels:
        if meshes == "jittered":
            seq, s = heine_sequence(lab, levels, pre_refine=1, jitter=jitter, seed=seed)
        for g in degrees:
            geo = None
            if meshes == "heine":
                seq, s, info = heine_adaptive_sequence(lab, levels, degree=g, tolerance=tolerance)
                geo = info["geometric_error"]
            rows = []
            for i, (V, F) in enumerate(seq):
                t0 = time.perf_counter()
                surf = LagrangeSurface.from_projection(V, F, g, s.project, interpolant="nodal")
                e = heine_errors(heine_weingarten(surf, g), s)
                e["seconds"] = time.perf_counter() - t0
                if geo is not None:
                    e["geometric_error"] = geo[i]
                rows.append(e)
            res[(lab, g)] = rows
    return res


def _paper_row_near(lab, g, h):
    """The paper's row of (lab, γ) whose h_max is nearest (in log) to ``h``, or None."""
    rows = PAPER_HEINE_TABLES.get(lab, {}).get(g)
    if not rows:
        return None
    return min(rows, key=lambda r: abs(np.log(r[0] / h)))


def format_table(lab, g, rows):
    keys = ("K2", "Kinf", "H2", "Hinf", "Y2", "Pi2")
    hs = [r["h"] for r in rows]
    rates = {k: np.concatenate([[np.nan], eoc([r[k] for r in rows], hs)]) for k in keys}
    geo = "geometric_error" in rows[0]
    lines = [f"## Heine ({lab}), degree γ = {g}", "",
             "| h_max | #F | E_K,2 | E_K,∞ | E_H,2 | E_H,∞ | ‖Y−Y_h‖L2 | ‖Π−Π_h‖L2 | s |"
             + (" ‖dist(·, Γ)‖L2 |" if geo else ""),
             "|---|---|---|---|---|---|---|---|---|" + ("---|" if geo else "")]
    for i, r in enumerate(rows):
        cells = [f"{r[k]:.2g}" + ("" if not np.isfinite(rates[k][i]) else f" ({rates[k][i]:.2f})") for k in keys]
        lines.append(f"| {r['h']:.3g} | {r['faces']} | " + " | ".join(cells) + f" | {r.get('seconds', 0):.1f} |"
                     + (f" {r['geometric_error']:.2g} |" if geo else ""))
    near = _paper_row_near(lab, g, hs[-1])
    last = PAPER_HEINE_TABLES.get(lab, {}).get(g, [None])[-1]
    fmt = lambda v: "" if v is None else f"{v:.2g}"            # noqa: E731
    for tag, pr in (("paper, nearest h", near), ("paper, last row", last)):
        if pr is not None:
            lines.append(f"| {tag} {pr[0]:.3g} | | " + " | ".join(
                fmt(pr[1 + 2 * j]) + ("" if pr[2 + 2 * j] is None else f" ({fmt(pr[2 + 2 * j])})")
                for j in range(4)) + " | | | |"
                + (" |" if geo else ""))
    lines.append("")
    return "\n".join(lines)


HEADER = ("# Heine's tables 5.1-5.4 (paper 003), igl_hhj.curved.heine_weingarten\n\n"
          "Output of `python -m igl_hhj.benchmarks.heine_curved {args}` ({mesh}; surface of "
          "degree γ = nodal interpolant of the projection). E_C,r: Heine's relative errors; "
          "‖Y−Y_h‖L2, ‖Π−Π_h‖L2: absolute errors of Theorem 4.1 (curvature vector Y = 2Hν and the "
          "nodal Weingarten map of Definition 3.2, proven rate γ − 1). EOC in brackets. "
          "'paper, nearest h': Heine's row at the h_max nearest to our finest (its EOC is "
          "against his previous row); 'paper, last row': his finest.\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--levels", type=int, default=4)
    ap.add_argument("--degrees", type=int, nargs="+", default=[1, 2], choices=(1, 2, 3, 4))
    ap.add_argument("--surfaces", nargs="+", default=["5.1a", "5.1b", "5.1c", "5.1d"])
    ap.add_argument("--jitter", type=float, default=0.3,
                    help="re-perturbation of every level (0: plain uniform refinement)")
    ap.add_argument("--seed", type=int, default=100)
    ap.add_argument("--meshes", choices=("jittered", "heine"), default="jittered",
                    help="'jittered' (re-jittered icosphere sequences) or 'heine' (Heine §5: adaptive "
                         "bisection until the geometric L2 error < --tolerance, then global double bisection)")
    ap.add_argument("--tolerance", type=float, default=HEINE_GEOMETRIC_TOLERANCE,
                    help="geometric L2 error ending the adaptive phase of --meshes heine (paper: 0.005)")
    ap.add_argument("--out", default=None,
                    help="folder to write heine_curved.md into (e.g. demos/images); default: print only")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    res = run(a.surfaces, a.degrees, a.levels, seed=a.seed, jitter=a.jitter, meshes=a.meshes,
              tolerance=a.tolerance)
    parts = [format_table(lab, g, rows) for (lab, g), rows in res.items()]
    for t in parts:
        print(t)
    total = time.perf_counter() - t0
    print(f"total {total:.1f} s")
    if a.out is not None:
        from pathlib import Path
        args = f"--levels {a.levels} --degrees {' '.join(map(str, a.degrees))}"
        if a.meshes == "heine":
            args += f" --meshes heine --tolerance {a.tolerance}"
            mesh = (f"Heine's family: adaptive newest-vertex bisection of the icosahedron until the "
                    f"geometric L2 error of the degree-γ surface is below {a.tolerance}, then global "
                    "double bisection")
            name = "heine_curved_bisection.md"
        else:
            mesh = ("re-jittered icosphere sequences mapped onto the surfaces, jitter "
                    f"{a.jitter}, seed {a.seed}")
            name = "heine_curved.md"
        out = Path(a.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / name).write_text(HEADER.format(args=args, mesh=mesh) + "\n" + "\n".join(parts)
                                             + f"\nTotal {total:.0f} s on 2 shared cores.\n")
        print(f"wrote {out / name}")


if __name__ == "__main__":
    main()
