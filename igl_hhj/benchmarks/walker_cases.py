"""Walker's test cases as the table benchmarks share them: the four surfaces and their
mesh sequences, the condition numbers of Walker's Table 1, and the cells and the
paper comparison of the tables (:mod:`.walker_tables` for m = 1, :mod:`.walker_curved`
for m = 2, 3)."""
from __future__ import annotations

import numpy as np

from ..surfaces.dumbbell import WalkerDumbbell, dumbbell_sequence, saddle_sequence
from ..surfaces.exact import WalkerGenus3, WalkerSaddle, WalkerTorus
from ..surfaces.implicit_meshing import genus3_coarse, implicit_sequence, torus_mc_coarse

__all__ = ["SURFACES", "KEYS", "HEAD", "surface_levels", "condition_numbers", "paper_comparison"]

KEYS = ("nu", "S", "S_inf", "kappa_a", "kappa_g")
HEAD = ("‖ν‖L2", "‖S‖L2", "‖S‖L∞", "‖κa‖L2", "‖κg‖L2")

SURFACES = ("saddle", "dumbbell", "torus", "genus3")


def surface_levels(name, n_levels, seed=0):
    """Exact surface and Walker-style mesh sequence [(V_k, F_k)], k = 0..n_levels-1.

    ``name`` is one of :data:`SURFACES` (a ``_plain`` suffix is accepted)."""
    base = name[:-6] if name.endswith("_plain") else name
    if base == "saddle":
        return WalkerSaddle(), saddle_sequence(n_levels, seed=seed)
    if base == "dumbbell":
        return WalkerDumbbell(), dumbbell_sequence(n_levels, seed=seed)
    if base == "torus":
        s = WalkerTorus()
        return s, implicit_sequence(*torus_mc_coarse(seed=seed), s, n_levels)
    if base == "genus3":
        s = WalkerGenus3()
        return s, implicit_sequence(*genus3_coarse(seed=seed), s, n_levels)
    raise ValueError(f"unknown surface {name!r}; use one of {SURFACES} (optionally with '_plain')")


def condition_numbers(A, tol=1e-6):
    """Spectral condition numbers of an SPD sparse matrix A and of D⁻¹A, D = diag(A).

    κ(A) = λ_max/λ_min from ``eigsh`` (λ_max: Lanczos; λ_min: shift-invert
    about 0 through one ``splu`` of A).  D⁻¹A is similar to the SPD matrix
    D^-1/2 A D^-1/2, so κ(D⁻¹A) is its λ_max/λ_min, the number that governs
    Jacobi-preconditioned CG; its shift-invert reuses the same LU
    ((D^-1/2 A D^-1/2)⁻¹ = D^1/2 A⁻¹ D^1/2).

    Returns
    -------
    (cond_A, cond_DA) : floats
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    A = sp.csc_matrix(A)
    n = A.shape[0]
    d = A.diagonal()
    if np.any(d <= 0):
        raise ValueError("A must be SPD (positive diagonal)")
    s = 1.0 / np.sqrt(d)
    Ah = sp.csc_matrix(sp.diags(s) @ A @ sp.diags(s))
    lu = spla.splu(A)
    inv_A = spla.LinearOperator((n, n), matvec=lambda x: lu.solve(np.asarray(x, dtype=np.float64).ravel()))
    r = np.sqrt(d)
    inv_Ah = spla.LinearOperator((n, n), matvec=lambda x: r * lu.solve(r * np.asarray(x, dtype=np.float64).ravel()))
    out = []
    for M, inv in ((A, inv_A), (Ah, inv_Ah)):
        lmax = spla.eigsh(M, k=1, which="LA", tol=tol, return_eigenvectors=False)[0]
        lmin = spla.eigsh(M, k=1, sigma=0.0, OPinv=inv, which="LM", tol=tol, return_eigenvectors=False)[0]
        out.append(float(lmax / lmin))
    return tuple(out)


def _fmt(x):
    return "—" if x is None or not np.isfinite(x) else f"{x:.2e}"


def _fmt_eoc(x):
    return "" if x is None or not np.isfinite(x) else f" ({x:.2f})"


def paper_comparison(ks, rows, rates, paper):
    """One line: ours / paper per column at the last level that the paper has, and the
    EOC differences (ours − paper) there."""
    last = [i for i, k in enumerate(ks) if k < len(paper)]
    if not last:
        return "(no paper row at these levels)"
    i = last[-1]
    k = ks[i]
    pe, pr = paper[k]
    ratio = ", ".join(f"{h} {rows[i][key] / v:.2f}" for h, key, v in zip(HEAD, KEYS, pe))
    diffs = [f"{h} {rates[key][i] - q:+.2f}" for h, key, q in zip(HEAD, KEYS, pr)
             if q is not None and np.isfinite(rates[key][i])]
    text = f"At k = {k}, ours / paper: {ratio}."
    if diffs:
        text += " EOC ours − paper: " + ", ".join(diffs) + "."
    return text
