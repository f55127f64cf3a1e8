"""Error norms and experimental orders of convergence (EOC) against exact surfaces.

Errors follow Walker §6 (Walker 2023): the exact fields are interpolated at the
vertices (``I_h``, P1) and compared with the discrete, piecewise-constant
fields on the flat triangles.  The integrals of squared differences are exact
(3-point edge-midpoint rule, exact for quadratics).
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .mesh import as_mesh

__all__ = ["l2_error_p1_vs_p0", "shape_operator_errors", "vertex_errors", "eoc", "plot_convergence"]


def l2_error_p1_vs_p0(mesh, exact_at_vertices, face_values):
    """‖I_h u - u_h‖_L2 for u given at vertices (P1) and u_h constant per face.

    Parameters
    ----------
    exact_at_vertices : (#V, ...) values of u at the vertices
    face_values : (#F, ...) piecewise-constant u_h

    Returns
    -------
    float : sqrt(Σ_T ∫_T |I_h u - u_h|²), |·| the Frobenius norm of the trailing axes.
    """
    U = exact_at_vertices[mesh.F]                           # (#F, 3, ...)
    mid = 0.5 * (U[:, [1, 2, 0]] + U[:, [2, 0, 1]])          # edge midpoints
    D = mid - face_values[:, None]
    sq = (D.reshape(D.shape[0], 3, -1) ** 2).sum(axis=2).mean(axis=1)
    return float(np.sqrt(np.sum(mesh.face_areas * sq)))


def _linf_p1_vs_p0(mesh, exact_at_vertices, face_values):
    D = exact_at_vertices[mesh.F] - face_values[:, None]
    return float(np.sqrt((D.reshape(D.shape[0], 3, -1) ** 2).sum(axis=2)).max())


def shape_operator_errors(V, F, S, surface):
    """Walker's error table entries for a face field S_h on a mesh of ``surface``.

    Returns
    -------
    dict with keys
        ``h`` (longest edge), ``faces``, ``nu`` (L2 error of the face normal),
        ``S`` (L2 error of S_h), ``S_inf`` (max error of S_h over face corners),
        ``kappa_a`` (L2 error of tr S_h), ``kappa_g`` (L2 error of det(S_h + ν⊗ν)).
    """
    mesh = as_mesh(V, F)
    X = mesh.V
    nu_ex = surface.normal(X)
    S_ex = surface.shape_operator(X)
    nu = mesh.face_normals
    ka_ex = np.trace(S_ex, axis1=1, axis2=2)
    kg_ex = np.linalg.det(S_ex + nu_ex[:, :, None] * nu_ex[:, None, :])
    ka = np.trace(S, axis1=1, axis2=2)
    kg = np.linalg.det(S + nu[:, :, None] * nu[:, None, :])
    return {
        "h": mesh.max_edge_length,
        "faces": mesh.n_faces,
        "nu": l2_error_p1_vs_p0(mesh, nu_ex, nu),
        "S": l2_error_p1_vs_p0(mesh, S_ex, S),
        "S_inf": _linf_p1_vs_p0(mesh, S_ex, S),
        "kappa_a": l2_error_p1_vs_p0(mesh, ka_ex, ka),
        "kappa_g": l2_error_p1_vs_p0(mesh, kg_ex, kg),
    }


def vertex_errors(V, F, PV1, PV2, surface, mask=None):
    """Errors of per-vertex principal curvatures against the exact ones.

    L2 errors use the lumped (Voronoi-free, area/3) P1 mass; ``mask`` (#V bool)
    restricts all norms (e.g. to interior vertices).

    Returns
    -------
    dict: ``h``, ``k1``/``k2`` (L2), ``H`` (L2 of (κ1+κ2)/2), ``K`` (L2 of κ1κ2),
    ``k_inf`` (max over vertices of max(|Δκ1|, |Δκ2|)).
    """
    mesh = as_mesh(V, F)
    k1, k2 = surface.principal_curvatures(mesh.V)
    w = mesh.sum_corners_to_vertices(np.broadcast_to(mesh.face_areas[:, None] / 3, (mesh.n_faces, 3)))
    if mask is None:
        mask = mesh.referenced_vertices
    w = np.where(mask, w, 0.0)

    def l2(d):
        return float(np.sqrt(np.sum(w * d ** 2)))

    return {
        "h": mesh.max_edge_length,
        "k1": l2(PV1 - k1),
        "k2": l2(PV2 - k2),
        "H": l2(0.5 * (PV1 + PV2) - 0.5 * (k1 + k2)),
        "K": l2(PV1 * PV2 - k1 * k2),
        "k_inf": float(np.max(np.maximum(np.abs(PV1 - k1), np.abs(PV2 - k2))[mask])),
    }


def eoc(errors: ArrayLike, hs: ArrayLike) -> NDArray[np.float64]:
    """EOC between successive levels: log(e_k / e_{k+1}) / log(h_k / h_{k+1}).

    Returns an array one shorter than the inputs."""
    e = np.asarray(errors, dtype=np.float64)
    h = np.asarray(hs, dtype=np.float64)
    return np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:])


def plot_convergence(hs: Any, errors: Any, labels: list[str] | None = None, *, ax: Any = None,
                     rates: tuple[float, ...] = (1,), title: str | None = None, xlabel: str = "h (longest edge)",
                     ylabel: str | None = None, styles: list[dict] | None = None, legend: bool = True,
                     eoc_labels: bool = False, guide_scale: float = 0.5, path: Any = None, dpi: int = 90) -> Any:
    """Log-log plot of errors against the mesh size, with reference slopes.

    The plot every convergence study draws (the benchmarks use it): one line
    per series, dotted guides ``∝ h^p`` for each ``p`` in ``rates`` through
    ``guide_scale`` × the finest error of the first series, log axes, grid.
    matplotlib is imported here (``pip install matplotlib``).

    Parameters
    ----------
    hs : (n,) array_like (shared by all series) or a list of them (one per series)
    errors : list of (n,) array_like, or dict label -> (n,) array_like
    labels : list of str, optional (default: the dict keys, or "series i")
    ax : matplotlib Axes, optional; default a new 5 x 4 inch figure
    rates : iterable of float, the slopes of the dotted guides (() for none)
    title, xlabel, ylabel : str, optional
    styles : list of dict, optional, matplotlib keyword arguments per series
        (default ``marker="o"``)
    legend : bool
    eoc_labels : bool, append the last EOC to each label ("HHJ (EOC 1.02)")
    guide_scale : float, where the guides sit relative to the first series
    path : str, optional: save the figure there (and close it)

    Returns
    -------
    matplotlib Axes.  Series with fewer than two finite positive values are
    skipped.

    Examples
    --------
    >>> import numpy as np
    >>> from igl_hhj.convergence import plot_convergence
    >>> h = np.array([0.4, 0.2, 0.1, 0.05])
    >>> ax = plot_convergence(h, [2 * h, h ** 2], ["O(h) method", "O(h²) method"], rates=(1, 2),
    ...                       eoc_labels=True)
    >>> [t.get_text() for t in ax.get_legend().get_texts()][:2]
    ['O(h) method (EOC 1.00)', 'O(h²) method (EOC 2.00)']
    """
    import matplotlib
    if ax is None and path is not None:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if isinstance(errors, dict):
        labels = list(errors) if labels is None else list(labels)
        errors = list(errors.values())
    errors = [np.asarray(e, dtype=np.float64) for e in errors]
    labels = [f"series {i}" for i in range(len(errors))] if labels is None else list(labels)
    if len(labels) != len(errors):
        raise ValueError(f"{len(labels)} labels for {len(errors)} error series")
    if np.ndim(hs[0]) == 0:
        hs = [np.asarray(hs, dtype=np.float64)] * len(errors)
    hs = [np.asarray(h, dtype=np.float64) for h in hs]
    if len(hs) != len(errors) or any(h.shape != e.shape for h, e in zip(hs, errors)):
        raise ValueError("hs must match the errors: one (n,) array for all series or one per series")
    styles = [{}] * len(errors) if styles is None else list(styles)
    if ax is None:
        _, ax = plt.subplots(figsize=(5, 4))
    first = None
    for h, e, lab, st in zip(hs, errors, labels, styles):
        ok = np.isfinite(e) & np.isfinite(h) & (e > 0) & (h > 0)
        if ok.sum() < 2:
            continue
        h, e = h[ok], e[ok]
        if eoc_labels:
            lab = f"{lab} (EOC {eoc(e, h)[-1]:.2f})"
        ax.loglog(h, e, **{"marker": "o", "ms": 4, **st}, label=lab)
        if first is None:
            first = (h, e)
    if first is not None:
        h, e = first
        i = int(np.argmin(h))
        for p in rates:
            ax.loglog(h, guide_scale * e[i] * (h / h[i]) ** p, "k:", lw=0.9,
                      label="O(h)" if p == 1 else f"O(h^{p:g})")
    if title:
        ax.set_title(title, fontsize=10)
    if xlabel:
        ax.set_xlabel(xlabel)
    if ylabel:
        ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    if legend:
        ax.legend(fontsize=7)
    if path is not None:
        figure = ax.figure
        figure.tight_layout()
        figure.savefig(path, dpi=dpi)
        plt.close(figure)
    return ax
