"""Walker's curved blocks (Walker 2023, §6, Tables 1–5, m = 2, 3): geometry of degree m,
HHJ of degree r = m − 1, on the project's four surfaces.

Used by ``python -m igl_hhj.benchmarks.walker_tables --orders 1 2 3``.  For each
surface and order m the flat sequence of :func:`walker_cases.surface_levels` is
made curved by Walker's modified interpolant (eq. 4.14, :mod:`igl_hhj.curved`)
of the exact element maps — the closest-point (Newton foot-point) projection for
the torus and genus-3 surface, the vertical projection onto the graph for the
saddle, the graph over a smooth blended ("Lenoir type") curved-boundary map of the
planar domain for the dumbbell (:func:`smooth_blended_map`) — and the errors of Walker §6 are measured on
Γ^m (:func:`igl_hhj.curved.errors.shape_operator_errors`: I_h^m of the exact
fields at the nodes vs the discrete ones, by quadrature on the curved elements).
"""
from __future__ import annotations

import time

import numpy as np

from ..convergence import eoc
from ..curved import LagrangeSurface, shape_operator
from ..curved.errors import shape_operator_errors
from .walker_cases import HEAD, KEYS, _fmt, _fmt_eoc, condition_numbers, paper_comparison, surface_levels

__all__ = ["PAPER_CURVED", "curved_levels", "run_curved", "format_curved_table"]

_N = None
# --------------------------------------------------------------------------------------------
# PAPER DATA — Walker, Tables 2–5, m = 2 and m = 3 blocks: per k the errors
# (ν L2, ∇ν L2, ∇ν L∞, κ^a L2, κ^g L2) and the published EOCs.  Copied by hand from
# shared/papers/000_*.txt; NOT computed by this project.
# --------------------------------------------------------------------------------------------
PAPER_CURVED = {
    "saddle": {2: [
        ((3.87e-03, 1.52e-01, 8.89e-01, 9.77e-02, 4.69e-01), (2.19, 1.87, 0.94, 1.78, 1.57)),
        ((9.13e-04, 3.71e-02, 2.83e-01, 2.49e-02, 1.23e-01), (2.08, 2.03, 1.65, 1.97, 1.93)),
        ((2.25e-04, 9.07e-03, 8.35e-02, 6.10e-03, 3.08e-02), (2.02, 2.03, 1.76, 2.03, 2.00)),
        ((5.59e-05, 2.25e-03, 2.14e-02, 1.51e-03, 7.68e-03), (2.01, 2.01, 1.96, 2.01, 2.00)),
        ((1.40e-05, 5.62e-04, 5.41e-03, 3.77e-04, 1.92e-03), (2.00, 2.00, 1.99, 2.00, 2.00))],
        3: [
        ((1.20e-04, 1.41e-02, 2.00e-01, 1.08e-02, 5.10e-02), (3.51, 2.95, 2.56, 2.72, 2.81)),
        ((1.15e-05, 1.86e-03, 2.12e-02, 1.50e-03, 7.47e-03), (3.38, 2.93, 3.24, 2.85, 2.77)),
        ((1.28e-06, 2.37e-04, 1.77e-03, 1.92e-04, 9.68e-04), (3.16, 2.97, 3.58, 2.97, 2.95)),
        ((1.55e-07, 2.98e-05, 2.20e-04, 2.42e-05, 1.22e-04), (3.05, 2.99, 3.01, 2.99, 2.99)),
        ((1.92e-08, 3.73e-06, 2.73e-05, 3.03e-06, 1.53e-05), (3.01, 3.00, 3.01, 3.00, 3.00))]},
    "dumbbell": {2: [
        ((8.31e-03, 3.79e-02, 1.08e-01, 2.35e-02, 2.81e-02), (2.00, 1.99, 1.62, 2.04, 2.00)),
        ((2.07e-03, 9.41e-03, 2.78e-02, 5.68e-03, 6.95e-03), (2.01, 2.01, 1.95, 2.05, 2.01)),
        ((5.16e-04, 2.34e-03, 6.60e-03, 1.39e-03, 1.73e-03), (2.00, 2.01, 2.08, 2.03, 2.01)),
        ((1.29e-04, 5.83e-04, 1.55e-03, 3.45e-04, 4.30e-04), (2.00, 2.00, 2.09, 2.01, 2.01)),
        ((3.22e-05, 1.46e-04, 3.69e-04, 8.59e-05, 1.07e-04), (2.00, 2.00, 2.07, 2.01, 2.00))],
        3: [
        ((3.92e-04, 3.78e-03, 1.30e-02, 2.12e-03, 2.64e-03), (3.04, 2.83, 2.42, 2.72, 2.84)),
        ((4.85e-05, 4.94e-04, 2.26e-03, 2.95e-04, 3.49e-04), (3.02, 2.93, 2.53, 2.85, 2.92)),
        ((6.04e-06, 6.28e-05, 3.29e-04, 3.83e-05, 4.46e-05), (3.01, 2.98, 2.78, 2.94, 2.97)),
        ((7.53e-07, 7.88e-06, 4.42e-05, 4.85e-06, 5.60e-06), (3.00, 2.99, 2.89, 2.98, 2.99)),
        ((9.41e-08, 9.87e-07, 5.72e-06, 6.09e-07, 7.01e-07), (3.00, 3.00, 2.95, 2.99, 3.00))]},
    "torus": {2: [
        ((1.76e-02, 1.98e-01, 3.24e-01, 1.60e-01, 3.70e-01), (None,) * 5),
        ((4.35e-03, 4.94e-02, 1.04e-01, 4.21e-02, 9.95e-02), (2.01, 2.00, 1.64, 1.93, 1.89)),
        ((1.08e-03, 1.23e-02, 3.29e-02, 1.06e-02, 2.58e-02), (2.00, 2.01, 1.66, 1.98, 1.95)),
        ((2.71e-04, 3.08e-03, 8.54e-03, 2.67e-03, 6.54e-03), (2.00, 2.00, 1.95, 1.99, 1.98))],
        3: [
        ((5.06e-03, 3.96e-02, 5.69e-02, 2.82e-02, 5.79e-02), (None,) * 5),
        ((6.64e-04, 5.12e-03, 1.10e-02, 3.64e-03, 6.77e-03), (2.93, 2.95, 2.38, 2.96, 3.10)),
        ((8.38e-05, 6.46e-04, 1.63e-03, 4.60e-04, 8.30e-04), (2.99, 2.99, 2.75, 2.99, 3.03)),
        ((1.05e-05, 8.10e-05, 2.14e-04, 5.78e-05, 1.03e-04), (3.00, 2.99, 2.93, 2.99, 3.01))]},
    "genus3": {2: [
        ((4.37e-02, 1.35e00, 2.43e00, 1.13e00, 7.05e00), (None,) * 5),
        ((1.14e-02, 3.51e-01, 7.41e-01, 2.77e-01, 1.73e00), (1.94, 1.94, 1.71, 2.02, 2.03)),
        ((2.85e-03, 8.74e-02, 2.58e-01, 6.70e-02, 4.19e-01), (2.00, 2.01, 1.52, 2.05, 2.04)),
        ((7.14e-04, 2.17e-02, 7.10e-02, 1.63e-02, 1.02e-01), (2.00, 2.01, 1.86, 2.04, 2.03)),
        ((1.78e-04, 5.42e-03, 2.05e-02, 4.02e-03, 2.53e-02), (2.00, 2.00, 1.79, 2.02, 2.02))],
        3: [
        ((3.36e-02, 6.03e-01, 1.16e00, 3.84e-01, 2.14e00), (None,) * 5),
        ((4.23e-03, 6.44e-02, 1.74e-01, 3.76e-02, 2.22e-01), (2.99, 3.23, 2.75, 3.35, 3.27)),
        ((5.36e-04, 7.54e-03, 2.07e-02, 4.48e-03, 2.19e-02), (2.98, 3.09, 3.07, 3.07, 3.35)),
        ((6.73e-05, 9.24e-04, 2.66e-03, 5.53e-04, 2.37e-03), (2.99, 3.03, 2.96, 3.02, 3.21))]},
}
BOUNDARY = {"saddle": "clamped", "dumbbell": "simply_supported", "torus": "closed", "genus3": "closed"}


def smooth_blended_map(P0, F0, Q, coarse_face, edge_curve):
    """A smooth curved-boundary map of the planar domain (for m ≥ 2).

    On a coarse triangle (a, b, c) with boundary edge ab (λ its barycentrics),

        Φ(x) = x + 4 λ_a λ_b / (1 - (λ_a - λ_b)²) · [γ(s) - (s a + (1 - s) b)],
        s = (1 + λ_a - λ_b) / 2,

    with γ the boundary arc (``edge_curve(b, a, s)``).  On the edge (λ_a + λ_b = 1)
    s = λ_a and the factor is 1, so Φ maps it onto γ; on the two other edges the
    factor vanishes (continuity with the neighbours).  Since γ - chord vanishes
    linearly at s = 0, 1, Φ = x + λ_a λ_b g(s) with g smooth: C^∞ on the closed
    triangle.  The Zlámal blend of :func:`~igl_hhj.surfaces.dumbbell.blended_map`
    (correction (λ_a+λ_b) d(λ_a/(λ_a+λ_b)), homogeneous of degree 1) has
    unbounded second derivatives at c: harmless for m = 1 (only vertex positions
    are used) but, measured, it stalled the m = 2, 3 errors at ‖S‖L∞ ≈ 0.46.
    """
    from ..surfaces.dumbbell import coarse_barycentrics
    is_bnd, T, lam = coarse_barycentrics(P0, F0, Q, coarse_face)
    X = np.array(Q, dtype=np.float64, copy=True)
    for j in range(3):                              # the 3 local edges, vectorised over points
        a, b = (j + 1) % 3, (j + 2) % 3
        den = 1.0 - (lam[:, a] - lam[:, b]) ** 2
        sel = is_bnd[coarse_face, j] & (den > 1e-14)
        if not sel.any():
            continue
        la, lb = lam[sel, a], lam[sel, b]
        fac = 4.0 * la * lb / den[sel]
        sv = np.clip(0.5 * (1.0 + la - lb), 0.0, 1.0)
        chord = sv[:, None] * T[sel, a] + (1.0 - sv[:, None]) * T[sel, b]
        X[sel] += fac[:, None] * (edge_curve(T[sel, b], T[sel, a], sv) - chord)
    return X


JOINS = np.array([[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]])


def dumbbell_coarse_with_joins(seed=0):
    """The coarse dumbbell mesh (:func:`~igl_hhj.surfaces.dumbbell.dumbbell_coarse`) with the
    boundary vertex nearest to each of the four joins (±1, ±1) of the boundary pieces of
    eq. (6.2) moved onto the join.

    ∂U is only C¹ there (the curvature jumps from the circles' 1 to the waves' 0.4π²), so
    a curved element straddling a join cannot be better than O(h²) in geometry: measured
    with the unsnapped mesh, the m = 3 errors stalled (EOC 0.7) with the worst elements at
    the joins.  Walker's assumption "corners of Σ are captured by vertices" applied to
    the pieces.  (m = 1 tables keep the unsnapped mesh.)"""
    import igl
    from ..surfaces.dumbbell import dumbbell_coarse
    P0, F0 = dumbbell_coarse(seed=seed)
    P0 = np.array(P0, dtype=np.float64)
    bnd = np.unique(np.asarray(igl.boundary_facets(np.asarray(F0, dtype=np.int64))[0]).ravel())
    for J in JOINS:
        i = bnd[np.argmin(np.linalg.norm(P0[bnd] - J, axis=1))]
        P0[i] = J
    return P0, F0


def _dumbbell_maps(n_levels, pre_refine=2, seed=0):
    """Dumbbell levels with exact element maps χ ∘ Φ (Φ = :func:`smooth_blended_map`)."""
    import igl
    from ..surfaces.dumbbell import WalkerDumbbell, dumbbell_edge_curve
    surface = WalkerDumbbell()
    P0, F0 = dumbbell_coarse_with_joins(seed=seed)
    out = []
    Q = np.column_stack([P0, np.zeros(len(P0))])
    Fq = np.asarray(F0, dtype=np.int64)
    for _ in range(pre_refine):
        Q, Fq = igl.upsample(Q, Fq)
    for k in range(n_levels):
        if k:
            Q, Fq = igl.upsample(Q, Fq)
        L = pre_refine + k
        Qk, F = np.asarray(Q)[:, :2], np.asarray(Fq, dtype=np.int64)
        vf = np.zeros(len(Qk), dtype=np.int64)
        vf[F.ravel()] = np.repeat(np.arange(len(F)), 3)
        V = surface.lift(smooth_blended_map(P0, F0, Qk, vf // 4 ** L, dumbbell_edge_curve))

        def element_map(faces, bary, Qk=Qk, F=F, L=L):
            Qp = np.einsum("nc,nck->nk", bary, Qk[F[faces]])
            return surface.lift(smooth_blended_map(P0, F0, Qp, faces // 4 ** L, dumbbell_edge_curve))
        out.append((V, F, element_map))
    return surface, out


def curved_levels(name, n_levels, seed=0):
    """Exact surface and [(V, F, element_map)] for :meth:`LagrangeSurface.from_parametrization`."""
    if name == "dumbbell":
        return _dumbbell_maps(n_levels, seed=seed)
    surface, seq = surface_levels(name, n_levels, seed)
    out = []
    for V, F in seq:
        X = np.asarray(V, dtype=np.float64)[np.asarray(F)]

        def element_map(faces, bary, X=X):
            return surface.project(np.einsum("nc,nck->nk", bary, X[faces]))
        out.append((V, F, element_map))
    return surface, out


def run_curved(surfaces, orders=(2, 3), levels=3, cond_levels=2, progress=True, seed=0,
               max_faces=None, interpolant="walker", min_level=0):
    """Errors of the curved HHJ shape operator per surface and order.

    ``min_level``: levels k < min_level are refined through but not solved (to add the
    finest rows of a table without recomputing the coarse ones).

    Returns dict (name, m) → list of per-level dicts (keys of
    :func:`igl_hhj.curved.errors.shape_operator_errors` plus ``k``, ``seconds``,
    ``cond_A``, ``cond_DA`` (NaN beyond ``cond_levels``), ``dofs``)."""
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=len(surfaces) * len(orders) * (levels - min_level), desc="walker curved", unit="level")
    res = {}
    for name in surfaces:
        surface, seq = curved_levels(name, levels, seed)
        for m in orders:
            rows = []
            for k, (V, F, emap) in enumerate(seq):
                if max_faces is not None and len(F) > max_faces:
                    break
                if k < min_level:
                    continue
                t0 = time.perf_counter()
                surf = LagrangeSurface.from_parametrization(V, F, m, emap, interpolant=interpolant)
                kw = {}
                if BOUNDARY[name] == "clamped":
                    kw["boundary_normals"] = surface.normal(surf.nodes)
                elif BOUNDARY[name] == "simply_supported":
                    kw["boundary_shape_operator"] = surface.shape_operator(surf.nodes)
                fld = shape_operator(surf, **kw)
                e = shape_operator_errors(fld, surface)
                e["seconds"] = time.perf_counter() - t0
                e["k"] = k
                e["dofs"] = fld.space.n_dofs
                e["cond_A"] = e["cond_DA"] = e["cond_S"] = e["cond_DS"] = float("nan")
                if cond_levels is not None and k < cond_levels:
                    A, _ = fld.space.matrices
                    if BOUNDARY[name] == "simply_supported":
                        free = np.ones(fld.space.n_dofs, dtype=bool)
                        b = np.flatnonzero(surf.mesh.boundary_edges)
                        free[fld.space.edge_dofs[b].ravel()] = False
                        A = A[free][:, free]
                    e["cond_A"], e["cond_DA"] = condition_numbers(A)
                    Sc = fld.space._A_condensed
                    if BOUNDARY[name] == "simply_supported":
                        Sc = Sc[free[:fld.space.n_edge_dofs]][:, free[:fld.space.n_edge_dofs]]
                    e["cond_S"], e["cond_DS"] = condition_numbers(Sc)
                rows.append(e)
                if bar is not None:
                    bar.set_postfix_str(f"{name} m={m} k={k} #F={len(F)}")
                    bar.update(1)
            res[(name, m)] = rows
    if bar is not None:
        bar.close()
    return res


def format_curved_table(name, m, rows, m1_cond=None, heading="##"):
    """Markdown table: our rows k beside the paper's rows (Walker Tables 2–5, block m).

    Rows carry their level ``k`` (default: their index); the EOC is printed between
    consecutive levels only."""
    paper = PAPER_CURVED[name][m]
    hs = [r["h"] for r in rows]
    ks = [r.get("k", i) for i, r in enumerate(rows)]
    rates = {key: np.concatenate([[np.nan], eoc([r[key] for r in rows], hs)]) if len(rows) > 1
             else np.array([np.nan]) for key in KEYS}
    for key in KEYS:
        rates[key][1:][np.diff(ks) != 1] = np.nan
    lines = [f"{heading} {name}, m = {m} (HHJ r = {m - 1}) — boundary: {BOUNDARY[name]}", "",
             "| k | #F | h | " + " | ".join(HEAD) + " | s |", "|---|---|---|" + "---|" * (len(HEAD) + 1)]
    for i, (k, r) in enumerate(zip(ks, rows)):
        cells = [f"{_fmt(r[key])}{_fmt_eoc(rates[key][i])}" for key in KEYS]
        lines.append(f"| {k} | {r['faces']} | {r['h']:.3g} | " + " | ".join(cells) + f" | {r['seconds']:.1f} |")
        if k < len(paper):
            pe, pr = paper[k]
            lines.append(f"| paper {k} | | | " + " | ".join(f"{_fmt(v)}{_fmt_eoc(q)}" for v, q in zip(pe, pr)) + " | |")
    lines.append("")
    lines += paper_comparison(ks, rows, rates, paper), ""
    if any(np.isfinite(r["cond_A"]) for r in rows):
        lines += ["| k | #DOF | κ(A^m) | κ(D⁻¹A^m) | κ(S^m) condensed | κ(D⁻¹S^m) |"
                  + (" κ(A^m)/κ(A^1) |" if m1_cond else ""),
                  "|---|---|---|---|---|---|" + ("---|" if m1_cond else "")]
        for k, r in enumerate(rows):
            if not np.isfinite(r["cond_A"]):
                continue
            ratio = ""
            if m1_cond and k < len(m1_cond) and np.isfinite(m1_cond[k]):
                ratio = f" {r['cond_A'] / m1_cond[k]:.0f} |"
            lines.append(f"| {k} | {r['dofs']} | {_fmt(r['cond_A'])} | {_fmt(r['cond_DA'])} | "
                         f"{_fmt(r.get('cond_S'))} | {_fmt(r.get('cond_DS'))} |" + ratio)
        lines.append("")
    return "\n".join(lines)
