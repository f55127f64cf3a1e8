"""Walker's Theorem 4.1 measured: the curved HHJ surface Hessian of a general function
(Walker 2023, eq. 4.9; ‖σ − σ̂_h‖_L2 = O(h^{r+1}) for m ≥ r + 1).

w = exp(x) sin(y) on non-uniform sequences (the test sequences of ``tests/conftest.py``:
jittered torus, jittered ellipsoid, jittered saddle with clamped data ξ̃ = I_h^m ∇_Γ w),
data ŵ_h = Walker's interpolant 𝓘_h^{1,m}(w ∘ F_T)
(:func:`igl_hhj.curved.modified_interpolant`) and, as a control, the nodal values
w(Ψ^m(x_a)).  Exact Hessian ∇_Γ∇_Γ w = P ∇²w P − (ν·∇w) ∇_Γν at the closest point of
each quadrature point of Γ^m; L2 error by quadrature on Γ^m.

Run::

    python -m igl_hhj.benchmarks.walker_hessian [--levels 4] [--out demos/images]

Writes ``walker_hessian.md``.
"""
from __future__ import annotations

import argparse
import os

import numpy as np

from ..convergence import eoc
from ..curved import LagrangeSurface, modified_interpolant, surface_hessian
from ..curved.reference import lagrange_nodes

__all__ = ["w", "grad_w", "exact_hessian", "node_images", "hessian_l2_error", "sequence", "run", "CASES"]

# (surface, m, r, boundary data)
CASES = (("torus", 2, 1, "none"), ("ellipsoid", 2, 1, "none"), ("saddle", 2, 1, "clamped"),
         ("torus", 3, 2, "none"), ("ellipsoid", 3, 2, "none"), ("saddle", 3, 2, "clamped"),
         ("torus", 3, 1, "none"), ("torus", 2, 0, "none"))


def w(X):
    """w = exp(x) sin(y) (ambient; restricted to Γ)."""
    return np.exp(X[:, 0]) * np.sin(X[:, 1])


def grad_w(X):
    ex = np.exp(X[:, 0])
    return np.stack([ex * np.sin(X[:, 1]), ex * np.cos(X[:, 1]), 0 * ex], axis=1)


def exact_hessian(surface, X):
    """(n, 3, 3) ∇_Γ∇_Γ w = P ∇²w P − (ν·∇w) ∇_Γν at points X on Γ."""
    ex, s, c = np.exp(X[:, 0]), np.sin(X[:, 1]), np.cos(X[:, 1])
    H = np.zeros((len(X), 3, 3))
    H[:, 0, 0], H[:, 0, 1], H[:, 1, 0], H[:, 1, 1] = ex * s, ex * c, ex * c, -ex * s
    nu = surface.normal(X)
    P = np.eye(3) - nu[:, :, None] * nu[:, None, :]
    return P @ H @ P - np.einsum("ij,ij->i", grad_w(X), nu)[:, None, None] * surface.shape_operator(X)


def node_images(V, F, surf, project):
    """(#N, 3) Ψ^m of every node: the exact map F_T at the node's reference position on
    the flat triangle (Walker's modified interpolant moves the nodes themselves off Γ)."""
    xi = lagrange_nodes(surf.order)
    bary = np.column_stack([1 - xi.sum(1), xi])
    flat = np.einsum("bc,fck->fbk", bary, np.asarray(V)[np.asarray(F)])
    out = np.empty((surf.n_nodes, 3))
    out[surf.elements.ravel()] = project(flat.reshape(-1, 3))
    return out


def hessian_l2_error(field, surf, surface):
    """‖∇_Γ∇_Γ w ∘ π − σ̂_h‖_L2(Γ^m) (π the closest-point map), by quadrature of degree 2m + 4."""
    faces, bary, wq = surf.quadrature(2 * surf.order + 4)
    X = surface.project(surf.points(faces, bary))
    d = exact_hessian(surface, X) - field(faces, bary)
    return float(np.sqrt(np.sum(wq * (d ** 2).sum(axis=(1, 2)))))


def sequence(name, levels):
    """The non-uniform sequences of the test suite (:func:`igl_hhj.surfaces.standard_sequence`)."""
    from ..surfaces import standard_sequence
    return standard_sequence(name, levels)


def errors(name, order, degree, levels, boundary="none", data="walker"):
    """(errs, hs) of σ̂_h on the first ``levels`` meshes of :func:`sequence`."""
    s, seq = sequence(name, levels)
    errs, hs = [], []
    for V, F in seq:
        surf = LagrangeSurface.from_projection(V, F, order, s.project)
        wn = (modified_interpolant(V, F, order, w, project=s.project) if data == "walker"
              else w(node_images(V, F, surf, s.project)))
        kw = {}
        if boundary == "clamped":
            Y = node_images(V, F, surf, s.project)
            nu = s.normal(Y)
            g = grad_w(Y)
            kw["boundary_gradient"] = g - np.einsum("ij,ij->i", g, nu)[:, None] * nu
        elif boundary == "zero":
            kw["boundary_gradient"] = np.zeros((surf.n_nodes, 3))
        errs.append(hessian_l2_error(surface_hessian(surf, wn, degree=degree, **kw), surf, s))
        hs.append(surf.h)
    return np.array(errs), np.array(hs)


def run(levels=4):
    """Markdown report: per case the errors and EOCs, Walker data and nodal data."""
    lines = ["# Walker's Theorem 4.1: curved HHJ Hessian of w = exp(x) sin(y)", "",
             "`python -m igl_hhj.benchmarks.walker_hessian` — L2 error of σ̂_h against ∇_Γ∇_Γ w, EOC in "
             "parentheses; data ŵ_h = 𝓘_h^{1,m}(w ∘ F_T) (Walker's interpolant), control: nodal "
             "w(Ψ^m(x_a)). Theorem 4.1: EOC r + 1.", "",
             "| surface | m | r | boundary | data | " + " | ".join(f"k = {k}" for k in range(levels)) + " |",
             "|---|---|---|---|---|" + "---|" * levels]
    cases = list(CASES) + [("torus", 3, 2, "none", "nodal"), ("saddle", 2, 1, "none"), ("saddle", 3, 2, "none")]
    for case in cases:
        name, m, r, bnd = case[:4]
        data = case[4] if len(case) > 4 else "walker"
        e, h = errors(name, m, r, levels, bnd, data)
        rates = np.concatenate([[np.nan], eoc(e, h)])
        cells = [f"{x:.2e}" + (f" ({q:.2f})" if np.isfinite(q) else "") for x, q in zip(e, rates)]
        lines.append(f"| {name} | {m} | {r} | {'clamped' if bnd == 'clamped' else 'plain' if name == 'saddle' else 'closed'}"
                     f" | {data} | " + " | ".join(cells) + " |")
        print(lines[-1], flush=True)
    return "\n".join(lines) + "\n"


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--levels", type=int, default=4)
    p.add_argument("--out", default="benchmark-results")
    a = p.parse_args(argv)
    text = run(a.levels)
    os.makedirs(a.out, exist_ok=True)
    path = os.path.join(a.out, "walker_hessian.md")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
