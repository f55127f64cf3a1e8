"""Curvature in the viewer: one estimator (:func:`register_curvature`), a saved result
(:func:`register_result`), HHJ beside libigl (:func:`register_comparison`)."""
from __future__ import annotations

import os
from typing import Any

import numpy as np

from ..mesh import as_mesh
from .backend import _polyscope_for
from .camera import _rotation_for
from .registration import Registration
from .render import _check_screenshot
from .structures import _add_estimate, _finish, _surface, _title
from .values import _TAG, METHOD_TITLES, METHODS, QUANTITIES, _check, _explicit_range, color_range


def curvature_estimate(V: Any, F: Any = None, *, method="hhj", per="face", **kwargs) -> Any:
    """Curvatures of one estimator as a :class:`igl_hhj.baselines.CurvatureEstimate`.

    Parameters
    ----------
    method : {"hhj", "igl", "heine"}
        HHJ shape operator (Walker), ``igl.principal_curvature`` (quadric fit),
        or Heine's L2-projected Weingarten map.
    per : {"face", "vertex"}
        "face" exists for "hhj" only (the native per-face S_h); "vertex" is the
        drop-in recovery for "hhj".
    **kwargs : passed to the estimator (e.g. boundary data for "hhj",
        ``radius`` for "igl").
    """
    from .. import baselines
    _check(method, "method", METHODS)
    _check(per, "per", ("face", "vertex"))
    if F is None:                       # a mesh object (trimesh, pyvista, meshio) or a TriangleMesh
        mesh = as_mesh(V)
        V, F = mesh.V, mesh.F
    if method == "hhj":
        return (baselines.hhj_face if per == "face" else baselines.hhj_vertex)(V, F, **kwargs)
    if per == "face":
        raise ValueError(f"method {method!r} gives per-vertex curvature only; use per='vertex'")
    return (baselines.libigl_quadric if method == "igl" else baselines.heine)(V, F, **kwargs)


def register_curvature(V: Any, F: Any = None, estimate=None, *, method="hhj", per="both", name="mesh", enabled="H",
                       directions=True, show_directions=False, symmetric=True, robust=1.0, cmap="coolwarm", ranges=None,
                       direction_scale=0.5, offset=None, view=None, title=None, screenshot=None, size=(1024, 768),
                       **estimator_kwargs) -> Registration:
    """Register a mesh with its curvature: κ1, κ2, H, K (scalars) and principal directions.

    Parameters
    ----------
    V : (#V, 3) array_like, F : (#F, 3) array_like int (validated, never reordered)
    estimate : CurvatureEstimate or sequence of them, optional
        Precomputed result(s) (:func:`curvature_estimate`); then ``method`` and
        ``per`` are ignored.
    method : {"hhj", "igl", "heine"}
    per : {"face", "vertex", "both"}, default "both"
        For "hhj": the per-face S_h, the recovered per-vertex values, or both
        (same colour ranges).  "igl"/"heine" are per vertex.
    name : str, structure name.
    enabled : one of "k1", "k2", "H", "K" or None, quantity shown first.
    directions : bool, register the PD1/PD2 line fields.
    show_directions : bool, display them when the picture opens (screenshots).
    symmetric, robust : colour range (:func:`color_range`), shared by all
        values of one quantity; default ``robust=1``: the 1st-99th percentiles, as
        ``igl-hhj curvature --view`` (a few extreme values at sharp features or
        defects would otherwise wash the picture out; None: the full range).
    cmap : polyscope colour map name (diverging by default).
    ranges : dict, optional, explicit ``{quantity: (lo, hi)}`` overriding the
        computed ranges (e.g. to match another picture).
    direction_scale : float, direction length in units of the local mean edge length.
    offset : (3,), optional translation of the structure (to lay out several pictures).
    view : None, "auto", "+x", "-x", "+y", "-y", "+z", "-z" or (3,), optional:
        turn the mesh for display so that it is seen from that side
        (:func:`view_rotation`; None: as given).
    title : str, optional, the title above the copy in screenshots ("" for
        none; default: method, per face / vertex, name, face count).
    screenshot : path, optional: render headless to this PNG (see :func:`screenshot`).
    size : (width, height) of the screenshot in pixels.
    **estimator_kwargs : passed to the estimator (boundary data, ``radius``...).

    Returns
    -------
    Registration (``ranges`` has keys "k1", "k2", "H", "K").

    Examples
    --------
    >>> from igl_hhj import viewer
    >>> from igl_hhj.surfaces import icosphere
    >>> V, F = icosphere(3)
    >>> reg = viewer.register_curvature(V, F, per="face", enabled="H", robust=2,
    ...                                 screenshot="sphere_H.png", size=(800, 600))   # doctest: +SKIP
    >>> reg.titles                                                                   # doctest: +SKIP
    {'mesh': 'HHJ, per face — 1,280 faces'}
    """
    if enabled is not None:
        _check(enabled, "enabled", QUANTITIES)
    mesh = as_mesh(V, F)
    _check_screenshot(screenshot, size)
    if estimate is None:
        _check(per, "per", ("face", "vertex", "both"))
        pers = ("face", "vertex") if per == "both" else (per,)
        if method != "hhj" and per == "both":
            pers = ("vertex",)
        ests = [curvature_estimate(mesh.V, mesh.F, method=method, per=p, **estimator_kwargs) for p in pers]
        tags = [_TAG[method]] * len(ests)
    else:
        ests = list(estimate) if isinstance(estimate, (list, tuple)) else [estimate]
        tags = [_tag_of(e) for e in ests]
    _check_sizes(mesh, ests)
    ps = _polyscope_for(screenshot)
    reg = Registration()
    reg.ranges = {q: color_range(*(getattr(e, q) for e in ests), symmetric=symmetric, robust=robust)
                  for q in QUANTITIES}
    if ranges:
        for k in ranges:
            _check(k, "ranges key", QUANTITIES)
        reg.ranges.update({k: _explicit_range(v) for k, v in ranges.items()})
    where = "/".join(dict.fromkeys(e.location for e in ests))
    _surface(ps, reg, name, mesh.V, mesh.F, offset, view,
             _title(title, f"{METHOD_TITLES.get(tags[0], tags[0])}, per {where}", name, mesh))
    for i, (est, tag) in enumerate(zip(ests, tags)):
        _add_estimate(reg, name, mesh, est, tag, reg.ranges, cmap, directions, direction_scale,
                      enabled=enabled if i == 0 else None, show_directions=show_directions and i == 0)
    return _finish(reg, screenshot, size)


def register_result(path: str | os.PathLike, *, enabled: str | None = None, name: str | None = None,
                    robust: float | None = 1.0, view: Any = None, show_directions: bool = False,
                    screenshot: str | os.PathLike | None = None, size: tuple[int, int] = (1024, 768)) -> Registration:
    """Re-open a saved curvature result with its stored quantities (``igl-hhj view``).

    Parameters
    ----------
    path : str or os.PathLike
        A file of ``igl-hhj curvature -o`` / :func:`igl_hhj.mesh_io.write_curvature`
        (:data:`igl_hhj.mesh_io.RESULT_EXTENSIONS`: ``.npz``, ``.ply``, ``.vtp``, ``.vtu``,
        ``.vtk``), read by :func:`igl_hhj.mesh_io.read_curvature`.
    enabled : {"k1", "k2", "H", "K"}, optional
        Quantity shown first (default: the one the file was written to show, its PLY
        ``quality`` or VTK active scalars; else H).
    name : str, optional, structure name (default: the file's stem).
    robust, view, show_directions, screenshot, size : as :func:`register_curvature`.

    Returns
    -------
    Registration
        κ1, κ2, H, K per vertex or per face as stored, and the principal directions
        PD1, PD2 when the file has them; the title names the file, the method and
        where the values live.
    """
    from pathlib import Path

    from ..mesh_io import read_curvature
    if enabled is not None:
        _check(enabled, "enabled", QUANTITIES)
    cf = read_curvature(path)
    tag = _tag_of(cf.estimate)
    where = cf.estimate.location
    title = (f"{Path(path).name}: {METHOD_TITLES.get(tag, 'stored curvature')}, per {where} — "
             f"{len(cf.F):,} faces")
    return register_curvature(cf.V, cf.F, estimate=cf.estimate, name=name or Path(path).stem,
                              enabled=enabled or cf.quantity, robust=robust, view=view,
                              show_directions=show_directions, title=title, screenshot=screenshot, size=size)


def _tag_of(est):
    n = getattr(est, "name", "") or ""
    if n.startswith("hhj"):
        return "HHJ"
    if n.startswith("libigl"):
        return "libigl"
    if n.startswith("heine"):
        return "Heine"
    return n or "estimate"


def _check_sizes(mesh, ests):
    for e in ests:
        n = mesh.n_faces if e.location == "face" else mesh.n_vertices
        if len(e.k1) != n:
            raise ValueError(f"estimate {getattr(e, 'name', '')!r} has {len(e.k1)} {e.location} values, "
                             f"the mesh has {n} {e.location}s")


def register_comparison(V: Any, F: Any = None, *, hhj=None, libigl=None, per="vertex", layout="copy", name="mesh", enabled="H",
                        directions=True, show_directions=False, symmetric=True, robust=1.0, cmap="coolwarm", offset=None,
                        direction_scale=0.5, radius=5, view=None, title=None, screenshot=None, size=(1600, 800)) -> Registration:
    """HHJ curvature beside ``igl.principal_curvature`` on the same mesh, identical colour ranges.

    Parameters
    ----------
    V, F : mesh
    hhj, libigl : CurvatureEstimate, optional precomputed results (HHJ at
        faces or vertices; libigl at vertices).
    per : {"vertex", "face"}, where the HHJ values live if computed here; default "vertex",
        like with like beside libigl's per-vertex values ("face": Walker's S_h per face,
        which looks mottled beside a per-vertex field at the same colour range).
    layout : {"copy", "quantities"}
        "copy": two structures, ``"<name> HHJ"`` and ``"<name> libigl"``, the
        libigl one translated by ``offset``; "quantities": one structure
        ``name`` carrying both sets of quantities.
    offset : (3,) translation of the libigl copy; default 1.15 × the bounding
        box width along x.
    radius : libigl's ``radius`` (k-ring size).
    view : as :func:`register_curvature`; both copies are turned alike.
    title : str or (str, str), optional: the copies' titles ("" for none;
        default: method, per face / vertex, name, face count).
    other parameters : as :func:`register_curvature`.

    Returns
    -------
    Registration; ``ranges[q]`` is the one range used by both estimators.

    Examples
    --------
    >>> from igl_hhj import viewer
    >>> from igl_hhj.surfaces import icosphere
    >>> V, F = icosphere(3)
    >>> reg = viewer.register_comparison(V, F, enabled="K", view="auto",
    ...                                  screenshot="sphere_K.png")        # doctest: +SKIP
    >>> viewer.register_comparison(V, F); viewer.show()                    # doctest: +SKIP
    """
    if enabled is not None:
        _check(enabled, "enabled", QUANTITIES)
    _check(layout, "layout", ("copy", "quantities"))
    mesh = as_mesh(V, F)
    _check_screenshot(screenshot, size)
    if hhj is None:
        hhj = curvature_estimate(mesh.V, mesh.F, method="hhj", per=per)
    if libigl is None:
        libigl = curvature_estimate(mesh.V, mesh.F, method="igl", per="vertex", radius=radius)
    _check_sizes(mesh, [hhj, libigl])
    ps = _polyscope_for(screenshot)
    reg = Registration()
    reg.ranges = {q: color_range(getattr(hhj, q), getattr(libigl, q), symmetric=symmetric, robust=robust)
                  for q in QUANTITIES}
    R = _rotation_for(view, mesh.V, mesh.F)
    titles = (title, title) if title is None or isinstance(title, str) else tuple(title)
    t_hhj = _title(titles[0], f"HHJ, per {hhj.location}", name, mesh)
    t_igl = _title(titles[1], "libigl quadric fit, per vertex", name, mesh)
    if layout == "copy":
        if offset is None:
            Vd = mesh.V if R is None else mesh.V @ R.T
            ext = Vd.max(axis=0) - Vd.min(axis=0)
            offset = np.array([1.15 * ext[0], 0.0, 0.0])
        sh, si = f"{name} HHJ", f"{name} libigl"
        _surface(ps, reg, sh, mesh.V, mesh.F, None, R, t_hhj)
        _surface(ps, reg, si, mesh.V, mesh.F, np.asarray(offset, dtype=np.float64).reshape(3), R, t_igl)
    else:
        sh = si = name
        _surface(ps, reg, name, mesh.V, mesh.F, None, R, t_hhj)
    _add_estimate(reg, sh, mesh, hhj, "HHJ", reg.ranges, cmap, directions, direction_scale, enabled=enabled,
                  show_directions=show_directions)
    _add_estimate(reg, si, mesh, libigl, "libigl", reg.ranges, cmap, directions, direction_scale,
                  enabled=enabled if layout == "copy" else None, show_directions=show_directions and layout == "copy")
    return _finish(reg, screenshot, size)
