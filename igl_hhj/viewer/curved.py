"""Curved Lagrange surfaces in the viewer (polyscope has no curved elements): a field of
:mod:`igl_hhj.curved` on the flat display mesh of :func:`igl_hhj.curved.display.display_mesh`."""
from __future__ import annotations

from .fields import register_scalars

__all__ = ["show_curved_field"]


def show_curved_field(surface, field, *, subdivisions=4, exact=None, name="curved", enabled="H",
                      screenshot=None, size=(1024, 768), **kwargs):
    """Register a curved surface's field with :func:`igl_hhj.viewer.register_scalars`
    (through :func:`igl_hhj.curved.display.display_mesh`); ``screenshot=path`` renders headless."""
    from ..curved.display import display_mesh      # igl_hhj.curved (scipy) only when used
    V, F, values = display_mesh(surface, field, subdivisions, exact)
    return register_scalars(V, F, values, name=name, enabled=enabled, screenshot=screenshot,
                            size=size, **kwargs)
