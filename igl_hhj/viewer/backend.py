"""polyscope itself: starting a backend (window, headless EGL, mock), the interactive
window, the registry of what this package registered, and the quantity setter that
works around polyscope 2.6's bindings.

polyscope is imported inside the functions, so that importing the viewer never loads it.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .camera import _frame, _union_bounds


_EGL_HINT = ("headless rendering needs EGL: on Debian/Ubuntu `apt-get install libegl1 libegl-mesa0 "
             "libgl1-mesa-dri`")
_REGISTERED: dict[str, np.ndarray] = {}  # name -> (2, 3) bounds of the structures this module registered (they may since be removed)


class ViewerUnavailable(RuntimeError):
    """polyscope could not open the requested rendering backend (no display, no EGL, ...)."""


def _backend_name(ps):
    try:
        return ps.get_render_engine_backend_name()
    except Exception:  # pragma: no cover - older polyscope
        return ""


def init(backend="auto") -> Any:
    """Initialise polyscope and return the ``polyscope`` module.

    Parameters
    ----------
    backend : str
        ``"auto"`` keeps whatever backend is running (or lets polyscope choose,
        falling back to headless EGL without a display);
        ``"openGL3_egl"`` renders without a display; ``"openGL_mock"`` renders
        nothing (unit tests).  Asking for a backend other than the running one
        shuts polyscope down (dropping every structure) and restarts it.

    Raises
    ------
    ViewerUnavailable
        The backend cannot be opened (e.g. no display for ``"auto"``, EGL
        libraries missing for ``"openGL3_egl"``).
    """
    import polyscope as ps
    if ps.is_initialized():
        if backend == "auto" or _backend_name(ps) == backend:
            return ps
        ps.shutdown()
        _REGISTERED.clear()
    # Without this a failed backend (e.g. EGL libraries missing) crashes the interpreter.
    ps.set_errors_throw_exceptions(True)
    # "auto" without a display falls back to headless EGL: registering and
    # screenshots work everywhere, show() says that there is no window.
    ps.set_allow_headless_backends(True)
    # no .polyscope.ini / imgui.ini in the user's current folder
    ps.set_use_prefs_file(False)
    try:
        ps.init(backend)
    except Exception as exc:
        _reset_after_failed_init(ps)
        hint = (f"; {_EGL_HINT}" if "egl" in backend.lower() else
                f"; there is no display and no usable EGL for headless rendering; {_EGL_HINT}" if backend == "auto"
                else "")
        raise ViewerUnavailable(f"polyscope could not initialise backend {backend!r}: "
                                f"{str(exc).replace('[polyscope] ', '')}{hint}") from None
    return ps


def _reset_after_failed_init(ps):
    """Leave polyscope cleanly uninitialised (its exit hook fails on a half-initialised state)."""
    try:
        ps.set_verbosity(0)
        ps.init("openGL_mock")
        ps.shutdown()
        ps.set_verbosity(2)
    except Exception:  # pragma: no cover - nothing more to do
        pass


PANEL_PX = 320
"""Width of polyscope's left-hand panel at UI scale 1 (its 305 px plus a gap)."""


def show(*, window=(1600, 900), layout=True) -> None:
    """Open polyscope's interactive window on everything registered (needs a display).

    Parameters
    ----------
    window : (width, height) of the window in pixels.
    layout : bool, default True: an orthographic camera framing every
        registered structure in the part of the window right of polyscope's
        panel (:data:`PANEL_PX`), so side-by-side copies are all visible.

    Raises
    ------
    ViewerUnavailable : polyscope runs a backend without a window (mock, EGL)
        or cannot open one.
    """
    ps = init("auto")
    if _backend_name(ps) in ("openGL_mock", "openGL3_egl"):
        raise ViewerUnavailable(f"polyscope is running the windowless {_backend_name(ps)!r} backend; "
                                "use screenshot=... or run with a display")
    if layout:
        _window_layout(ps, window)
    try:
        ps.show()
    finally:
        ps.set_automatically_compute_scene_extents(True)


def _window_layout(ps, window):
    """Window size and camera of :func:`show`; returns the camera (``_frame``) or None."""
    w, h = (int(x) for x in window)
    ps.set_window_size(w, h)
    boxes = [_REGISTERED[n] for n in _REGISTERED if ps.has_surface_mesh(n) and ps.get_surface_mesh(n).is_enabled()]
    if not boxes:
        return None
    try:
        scale = float(ps.get_ui_scale())
    except Exception:  # pragma: no cover - older polyscope
        scale = 1.0
    return _frame(ps, _union_bounds(*boxes), w, h, left_px=min(int(PANEL_PX * scale), w // 2))


_RETURN_CONVERSION_ERROR = "Unable to convert function return value"
_SINGULAR = {"vertices": "vertex", "faces": "face", "nodes": "node", "edges": "edge"}


def _set(method, *args):
    """Call a polyscope quantity setter for its effect.  polyscope 2.6's bindings return
    the quantity itself from setters such as ``set_color_map``; in some processes (about
    one run in four of ``tests/app/test_view.py`` after other tests) nanobind fails to
    convert that returned ``SurfaceScalarQuantity`` reference ("Unable to convert
    function return value ..."), after the C++ setter has run.  That error is ignored:
    the setting is made, only the unused return value is lost; any other error is
    raised."""
    try:
        method(*args)
    except TypeError as exc:
        if _RETURN_CONVERSION_ERROR not in str(exc):
            raise


def _add_scalar(reg, sname, qname, q, colour_bar=False):
    """Hand one recorded scalar quantity to polyscope (``colour_bar``: with polyscope's
    own on-screen colour bar, drawn in screenshots that include the UI).

    The quantity is added through polyscope's bound structure and configured with
    :func:`_set` (what ``add_scalar_quantity(..., vminmax=, cmap=, enabled=)`` does, without
    its failing return-value conversion)."""
    import polyscope_bindings as psb
    values = np.nan_to_num(np.asarray(q.values, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    bound = reg.structures[sname].bound_instance
    # vertices, faces (surface meshes), nodes, edges (curve networks)
    add = getattr(bound, f"add_{_SINGULAR[q.defined_on]}_scalar_quantity")
    bq = add(qname, values, psb.DataType.standard)
    if q.vminmax is not None:
        _set(bq.set_map_range, tuple(float(v) for v in q.vminmax))
    if q.cmap is not None:
        _set(bq.set_color_map, q.cmap)
    if colour_bar:
        _set(bq.set_onscreen_colorbar_enabled, True)
    if q.enabled is not None:
        _set(bq.set_enabled, bool(q.enabled))


def _polyscope_for(screenshot):
    """polyscope, initialised for interactive use or (``screenshot`` given) able to render."""
    import polyscope as ps
    if screenshot is not None and (not ps.is_initialized() or _backend_name(ps) == "openGL_mock"):
        return init("openGL3_egl")
    return init("auto")
