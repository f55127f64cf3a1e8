"""Polyscope viewers for igl_hhj results: curvature (HHJ beside libigl), surface
Hessians, biharmonic solutions and Regge Gauss curvature.

polyscope is imported lazily inside the functions, so ``import igl_hhj`` never
loads it.  Every ``register_*`` function

* validates the mesh like the core API (``ValueError``/``TypeError``),
* registers polyscope structures and quantities and returns a
  :class:`Registration` describing exactly what it registered (names, values,
  element type, colour ranges) — the thing tests and scripts inspect,
* takes ``screenshot="out.png"`` to render **headless** (EGL backend; on
  Debian/Ubuntu install ``libegl1 libegl-mesa0 libgl1-mesa-dri``) only the
  structures of this call and write a PNG.

In a notebook a :class:`Registration` shows itself as that picture (``_repr_png_``),
and :func:`to_image` returns it as an (H, W, 4) uint8 array instead of a file.

Interactive use::

    from igl_hhj import viewer
    viewer.register_comparison(V, F)   # HHJ (left) and libigl (right), same colour ranges
    viewer.show()

Colour maps: signed curvature-like quantities use a diverging map
(``coolwarm``) with a range **symmetric about 0** by default, so white is
zero curvature; ``robust=p`` takes the range from the ``[p, 100-p]``
percentiles instead of the extremes (ignores outliers, e.g. at sharp features of
scanned meshes).  Quantities compared side by side (HHJ and libigl values of the
same curvature) always share one range.  NaN values (undefined, e.g.
unreferenced vertices) are shown as 0 and kept as NaN in the
:class:`Registration`.

Screenshots explain themselves: each copy gets a title (method, per face /
vertex, mesh, face count; ``title=`` overrides it) and the picture a colour
bar per distinct (quantity, range, colour map) shown, composited with
matplotlib onto polyscope's render (polyscope 2.6 has no colour bar in
Python; without matplotlib the plain render is written).  ``view=`` turns the
mesh for display: ``"auto"`` looks along the direction of largest projected
area (:func:`best_view_direction`), ``"+x"``, ``"-y"``, ... or a 3-vector
look from that side.

Principal directions are line fields (polyscope tangent-vector quantities
with 2-fold symmetry, ``vectortype="ambient"``) on faces or vertices: a
principal direction has no sign, so it is drawn as a line, not an arrow, and
its length is ``direction_scale`` times the local mean edge length so the
lines stay readable on graded meshes.

Modules
-------
:mod:`.curvature` (:func:`register_curvature`, :func:`register_result`,
:func:`register_comparison`), :mod:`.fields` (Hessians, biharmonic solutions, Regge
curvature, scalars, creases), :mod:`.curved` (curved Lagrange surfaces),
:mod:`.registration` (:class:`Registration`, :func:`screenshot`, :func:`to_image`),
:mod:`.structures` (registering into polyscope), :mod:`.render` (pictures and PNG files),
:mod:`.camera` (views), :mod:`.values` (labels, colour ranges), :mod:`.backend`
(polyscope's start-up and window).  Every name of ``__all__`` is importable from here.
"""
from __future__ import annotations

from .backend import PANEL_PX, ViewerUnavailable, init, show
from .camera import VIEWS, best_view_direction, view_rotation
from .curvature import curvature_estimate, register_comparison, register_curvature, register_result
from .curved import show_curved_field
from .fields import (register_biharmonic, register_creases, register_hessian, register_regge_curvature,
                     register_scalars)
from .registration import REPR_PNG_SIZE, QuantityInfo, Registration, merge, screenshot, to_image
from .values import (LABELS, LENGTH_UNIT, LONG_LABELS, METHOD_TITLES, METHODS, QUANTITIES, color_range,
                     local_edge_length)

__all__ = [
    "ViewerUnavailable", "QuantityInfo", "Registration", "QUANTITIES", "METHODS",
    "init", "show", "color_range", "curvature_estimate", "local_edge_length",
    "register_curvature", "register_comparison", "register_hessian", "register_biharmonic",
    "register_regge_curvature", "register_scalars", "register_result", "register_creases", "merge", "screenshot",
    "VIEWS", "best_view_direction", "view_rotation", "to_image", "REPR_PNG_SIZE", "show_curved_field",
    "LABELS", "LENGTH_UNIT", "LONG_LABELS", "METHOD_TITLES", "PANEL_PX",
]
