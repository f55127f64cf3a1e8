"""Polyscope helpers: HHJ face curvatures beside libigl's vertex curvatures.

polyscope is imported lazily inside every function.  Nothing here calls
``ps.show()``: interactive use is ``register_comparison(V, F); ps.show()``
(see ``demos/compare_curvature.py``); headless rendering is
:func:`screenshot` (EGL backend; on Debian needs the packages ``libegl1
libegl-mesa0 libgl1-mesa-dri``).

Colour ranges: for each quantity (κ1, κ2, H, K) the HHJ mesh and the libigl
mesh share one range, the 5th–95th percentile (by default) of both value sets together
(symmetric about 0 for K and for signed data that changes sign), so the two
pictures are directly comparable.
"""
from __future__ import annotations

import numpy as np

from .mesh import as_mesh

__all__ = ["init", "shared_range", "curvature_fields", "register_comparison", "screenshot",
           "QUANTITIES"]

QUANTITIES = ("k1", "k2", "H", "K")
_SHOT = 0
_LABEL = {"k1": "kappa1", "k2": "kappa2", "H": "mean H", "K": "Gauss K"}


def init(backend="auto"):
    """Initialise polyscope once (``backend``: "auto", "openGL3_egl", "openGL_mock", ...).

    Returns the ``polyscope`` module."""
    import polyscope as ps
    if not ps.is_initialized():
        ps.init(backend)
    return ps


def shared_range(*arrays, percentile=2.0):
    """One colour range for several value arrays (NaNs ignored).

    Returns ``(lo, hi)``: the [p, 100-p] percentiles of all values together;
    if they straddle 0 the range is made symmetric (``±max(|lo|, |hi|)``)."""
    vals = np.concatenate([np.asarray(a, dtype=np.float64).ravel() for a in arrays])
    vals = vals[np.isfinite(vals)]
    if vals.size == 0:
        return (-1.0, 1.0)
    lo, hi = np.percentile(vals, [percentile, 100.0 - percentile])
    if lo < 0 < hi:
        m = max(-lo, hi)
        lo, hi = -m, m
    if hi <= lo:
        hi = lo + 1e-12
    return float(lo), float(hi)


def curvature_fields(V, F, *, solver="auto", radius=5):
    """HHJ per-face and libigl per-vertex curvature fields of one mesh.

    Returns
    -------
    hhj : CurvatureEstimate (location "face"), from :func:`igl_hhj.baselines.hhj_face`
    igl : CurvatureEstimate (location "vertex"), from :func:`igl_hhj.baselines.libigl_quadric`
    """
    from .baselines import hhj_face, libigl_quadric
    mesh = as_mesh(V, F)
    return hhj_face(mesh.V, mesh.F, solver=solver), libigl_quadric(mesh.V, mesh.F, radius=radius)


def register_comparison(V, F, *, name="mesh", fields=None, enabled="k1", offset=None,
                        directions=True, cmap="coolwarm", percentile=5.0):
    """Register two copies of the mesh: HHJ face curvatures and libigl vertex curvatures.

    Parameters
    ----------
    V, F : mesh (validated like the core API)
    name : str, structure name prefix: ``"<name> HHJ"`` and ``"<name> libigl"``.
    fields : (hhj, igl) pair from :func:`curvature_fields`, computed if None.
    enabled : one of "k1", "k2", "H", "K" (or None): quantity shown first.
    offset : (3,) translation of the libigl copy; default 1.2 × the bounding
        box width along x.
    directions : bool, also add the principal directions (face / vertex vectors).
    percentile : float, colour range = [p, 100-p] percentiles (see :func:`shared_range`).

    Returns
    -------
    dict with keys "hhj" and "libigl" (the polyscope SurfaceMesh objects) and
    "ranges" ({quantity: (lo, hi)}).
    """
    if enabled is not None and enabled not in QUANTITIES:
        raise ValueError(f"enabled must be one of {QUANTITIES} or None, got {enabled!r}")
    mesh = as_mesh(V, F)
    hhj, igl_ = curvature_fields(mesh.V, mesh.F) if fields is None else fields
    ps = init()
    if offset is None:
        ext = mesh.V.max(axis=0) - mesh.V.min(axis=0)
        offset = np.array([1.2 * ext[0], 0.0, 0.0])
    offset = np.asarray(offset, dtype=np.float64).reshape(3)
    m_h = ps.register_surface_mesh(f"{name} HHJ", mesh.V, mesh.F)
    m_i = ps.register_surface_mesh(f"{name} libigl", mesh.V + offset, mesh.F)
    ranges, added = {}, {}
    for q in QUANTITIES:
        a, b = getattr(hhj, q), getattr(igl_, q)
        ranges[q] = shared_range(a, b, percentile=percentile)
        added[q] = (
            m_h.add_scalar_quantity(f"{_LABEL[q]} (HHJ, faces)", np.nan_to_num(a), defined_on="faces",
                                    vminmax=ranges[q], cmap=cmap, enabled=(q == enabled)),
            m_i.add_scalar_quantity(f"{_LABEL[q]} (libigl, vertices)", np.nan_to_num(b), defined_on="vertices",
                                    vminmax=ranges[q], cmap=cmap, enabled=(q == enabled)))
    if enabled is not None:
        # polyscope remembers "enabled" per structure/quantity name across
        # re-registration; enable the wanted one last so it wins.
        for qty in added[enabled]:
            if qty is not None and hasattr(qty, "set_enabled"):
                qty.set_enabled(True)
    if directions:
        for k, d in (("d1", "PD1"), ("d2", "PD2")):
            if getattr(hhj, k) is not None:
                m_h.add_vector_quantity(f"{d} (HHJ)", np.nan_to_num(getattr(hhj, k)), defined_on="faces",
                                        vectortype="ambient", length=0.5 * mesh.mean_edge_length,
                                        enabled=False)
            if getattr(igl_, k) is not None:
                m_i.add_vector_quantity(f"{d} (libigl)", np.nan_to_num(getattr(igl_, k)), defined_on="vertices",
                                        vectortype="ambient", length=0.5 * mesh.mean_edge_length,
                                        enabled=False)
    return {"hhj": m_h, "libigl": m_i, "ranges": ranges}


def screenshot(V, F, path, *, quantity="k1", fields=None, backend="openGL3_egl", size=(1200, 600),
               name="mesh", percentile=5.0):
    """Render HHJ (left) and libigl (right) side by side for one quantity and save a PNG.

    Parameters
    ----------
    path : str or path-like, output PNG file.
    quantity : "k1", "k2", "H" or "K" (same colour range on both copies).
    fields : optional precomputed (hhj, igl) from :func:`curvature_fields`.
    backend : polyscope backend; "openGL3_egl" renders without a display.
    size : window size in pixels.
    percentile : float, colour range percentile (see :func:`shared_range`).

    Returns
    -------
    (lo, hi) : the colour range used.
    """
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {QUANTITIES}, got {quantity!r}")
    ps = init(backend)
    ps.remove_all_structures()
    ps.set_window_size(int(size[0]), int(size[1]))
    ps.set_ground_plane_mode("none")
    global _SHOT
    _SHOT += 1
    # A fresh structure name per picture: re-registering a *different* mesh under
    # the same names leaves the first screenshot without its scalar quantity
    # (polyscope keeps per-name state; measured with the EGL backend).
    reg = register_comparison(V, F, name=f"{name} {_SHOT}", fields=fields, enabled=quantity, directions=False,
                              percentile=percentile)
    ps.reset_camera_to_home_view()
    ps.screenshot(str(path), transparent_bg=False)
    return reg["ranges"][quantity]
