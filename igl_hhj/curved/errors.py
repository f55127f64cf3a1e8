"""Walker's error norms on a curved surface Γ^m (Walker 2023, §6).

``‖I_h^m u - u_h‖`` over Γ^m, with I_h^m the degree-m nodal interpolant of the
exact field evaluated at the nodes (analytic continuation off Γ, as Walker), by
quadrature on the curved elements."""
from __future__ import annotations

import numpy as np

__all__ = ["shape_operator_errors"]


def shape_operator_errors(field, surface_exact, degree=None):
    """dict: ``h``, ``faces``, ``nu``, ``S``, ``S_inf`` (max Frobenius error over the
    quadrature points), ``kappa_a``, ``kappa_g`` (L2 errors)."""
    surf = field.surface
    faces, bary, w = surf.quadrature(degree if degree is not None else 2 * surf.order + 2)
    X = surf.nodes
    nu_n = surface_exact.normal(X)
    S_n = surface_exact.shape_operator(X)
    ka_n = np.trace(S_n, axis1=1, axis2=2)
    kg_n = np.linalg.det(S_n + nu_n[:, :, None] * nu_n[:, None, :])
    out = {"h": surf.h, "faces": surf.n_faces}
    S_ex = surf.interpolate(S_n, faces, bary)
    nu_ex = surf.interpolate(nu_n, faces, bary)
    S_h = field(faces, bary)
    nu_h = surf.normals(faces, bary)
    ka_h = np.trace(S_h, axis1=1, axis2=2)
    kg_h = np.linalg.det(S_h + nu_h[:, :, None] * nu_h[:, None, :])

    def l2(d):
        d = d.reshape(len(w), -1)
        return float(np.sqrt(np.sum(w * (d ** 2).sum(1))))
    dS = S_ex - S_h
    out["nu"] = l2(nu_ex - nu_h)
    out["S"] = l2(dS)
    out["S_inf"] = float(np.sqrt((dS.reshape(len(w), -1) ** 2).sum(1)).max())
    out["kappa_a"] = l2(surf.interpolate(ka_n, faces, bary) - ka_h)
    out["kappa_g"] = l2(surf.interpolate(kg_n, faces, bary) - kg_h)
    return out
