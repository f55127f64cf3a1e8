"""What a ``register_*`` call registered (:class:`Registration`) and its pictures:
:func:`screenshot`, :func:`to_image`, and the notebook picture of a registration."""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .backend import _REGISTERED, _backend_name
from .camera import _union_bounds
from .render import _png_bytes, _render


@dataclass(frozen=True)
class QuantityInfo:
    """One registered polyscope quantity.

    Attributes
    ----------
    values : (n,) or (n, 3) float64, the values as computed (NaN kept).
    defined_on : {"vertices", "faces"}
    kind : {"scalar", "line"} (line: a principal-direction field, values (n, 3))
    vminmax : (lo, hi) colour range of a scalar quantity, None for line fields.
    cmap : str or None, colour map of a scalar quantity.
    enabled : bool, shown when the picture opens.
    label : str or None, what the colour bar calls it (None: the quantity name).
    """

    values: np.ndarray
    defined_on: str
    kind: str
    vminmax: tuple | None = None
    cmap: str | None = None
    enabled: bool = False
    label: str | None = None


@dataclass
class Registration:
    """What a ``register_*`` call registered.

    Attributes
    ----------
    structures : dict, structure name -> polyscope structure.
    quantities : dict, (structure name, quantity name) -> :class:`QuantityInfo`.
    ranges : dict, quantity key (e.g. "H") -> (lo, hi) colour range shared by
        every structure showing that quantity.
    screenshot : str or None, the PNG written (``screenshot=`` argument).
    bounds : (2, 3) float64 or None, bounding box of the registered vertices.
    titles : dict, structure name -> title drawn above it in screenshots.
    rotations : dict, structure name -> (3, 3) display rotation (``view=``);
        the structure shows ``V @ R.T`` (+ offset).
    """

    structures: dict = field(default_factory=dict)
    quantities: dict = field(default_factory=dict)
    ranges: dict = field(default_factory=dict)
    screenshot: str | None = None
    bounds: np.ndarray | None = None
    titles: dict = field(default_factory=dict)
    rotations: dict = field(default_factory=dict)

    def names(self, structure):
        """Quantity names registered on ``structure``."""
        return [q for s, q in self.quantities if s == structure]

    def _repr_png_(self) -> bytes | None:
        """The headless picture of these structures (:func:`to_image`, :data:`REPR_PNG_SIZE`)
        as PNG bytes: Jupyter / IPython show a registration as that image.

        None (Jupyter then shows the text ``repr``) when nothing can be drawn:
        polyscope not running, its mock backend, EGL missing, or the structures
        removed since.  Like :func:`screenshot`, this moves polyscope's camera."""
        import sys
        ps = sys.modules.get("polyscope")
        if not self.structures or ps is None or not ps.is_initialized() or _backend_name(ps) == "openGL_mock":
            return None
        try:
            return _png_bytes(to_image(self, size=REPR_PNG_SIZE))
        except (RuntimeError, ValueError):      # ViewerUnavailable is a RuntimeError
            return None

    def __repr__(self):
        shown = [f"{s}: {q}" for (s, q), info in self.quantities.items() if info.enabled]
        return (f"Registration(structures={list(self.structures)}, {len(self.quantities)} quantities, "
                f"shown={shown}, ranges={ {k: tuple(round(x, 6) for x in v) for k, v in self.ranges.items()} }"
                + (f", screenshot={self.screenshot!r}" if self.screenshot else "") + ")")


def merge(*registrations) -> Registration:
    """One :class:`Registration` holding several (e.g. to screenshot them together)."""
    out = Registration()
    for r in registrations:
        out.structures.update(r.structures)
        out.quantities.update(r.quantities)
        out.ranges.update(r.ranges)
        out.titles.update(r.titles)
        out.rotations.update(r.rotations)
    out.bounds = _union_bounds(*(r.bounds for r in registrations))
    return out


def screenshot(path: str | os.PathLike, registration: Any = None, *, size: tuple[int, int] = (1024, 768),
               annotate: bool = True) -> str:
    """Render headless (EGL, unless an interactive backend is running) and save a PNG.

    Parameters
    ----------
    path : str or path-like, the PNG to write (its directory must exist).
    registration : Registration or list of them, optional: only their
        structures are drawn (everything registered through this module
        otherwise).
    size : (width, height) in pixels of the whole picture.
    annotate : bool, default True: titles above the copies and a colour bar
        (quantity name, range, colour map) per distinct shown quantity, drawn
        with matplotlib (plain render with a warning when it is missing).

    Returns
    -------
    str, the path written.

    Raises
    ------
    ViewerUnavailable : no backend can render (e.g. EGL libraries missing).
    ValueError : unwritable path or bad size.
    """
    return _render(_registration_of(registration), path, size, annotate)


REPR_PNG_SIZE = (640, 480)
"""(width, height) of the picture a :class:`Registration` shows in a notebook."""


def to_image(registration: Any = None, *, size: tuple[int, int] = (1024, 768),
             annotate: bool = True) -> NDArray[np.uint8]:
    """The picture :func:`screenshot` would write, as an array instead of a PNG file (the
    same pixels: the file is full-colour RGB).

    Parameters
    ----------
    registration : Registration or list of them, optional
        Only their structures are drawn (everything registered through this
        module otherwise).
    size : (width, height) in pixels of the whole picture.
    annotate : bool, default True: titles and colour bars (see :func:`screenshot`).

    Returns
    -------
    (H, W, 4) uint8 RGBA array, ``(W, H) = size``, opaque (alpha 255) on a white
    background: ``matplotlib.pyplot.imshow`` it, or ``PIL.Image.fromarray``.

    Raises
    ------
    ViewerUnavailable : no backend can render (polyscope's mock backend, EGL missing).
    ValueError : bad size, or structures no longer registered.

    Examples
    --------
    >>> from igl_hhj import viewer                                        # doctest: +SKIP
    >>> reg = viewer.register_curvature(V, F, per="face")                 # doctest: +SKIP
    >>> viewer.to_image(reg, size=(400, 300)).shape                       # doctest: +SKIP
    (300, 400, 4)
    >>> reg                     # in Jupyter: shown as the picture        # doctest: +SKIP
    """
    return _render(_registration_of(registration), None, size, annotate)


def _registration_of(registration):
    """The Registration to draw: everything of this module (None), a merge (list), or ``registration``."""
    if registration is None:
        import polyscope as ps
        names = [n for n in _REGISTERED if ps.has_surface_mesh(n)]
        return Registration(structures={n: None for n in names},
                            bounds=_union_bounds(*(_REGISTERED[n] for n in names)))
    if isinstance(registration, (list, tuple)):
        return merge(*registration)
    return registration
