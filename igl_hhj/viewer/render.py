"""Pictures: the headless render of registered structures with titles and colour bars
composited on (matplotlib), and the PNG files (full-colour RGB with Pillow)."""
from __future__ import annotations

import os

import numpy as np

from .backend import _REGISTERED, ViewerUnavailable, _add_scalar, _backend_name
from .camera import _frame


def _check_screenshot(path, size):
    """Fail fast (before any computation) on an unwritable PNG path or a bad size."""
    if path is None:
        return None
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise ValueError(f"cannot write screenshot {path!r}: directory {folder!r} does not exist")
    if not os.access(folder, os.W_OK):
        raise ValueError(f"cannot write screenshot {path!r}: directory {folder!r} is not writable")
    _check_size(size)
    return path


def _check_size(size):
    """(width, height) of a picture, at least 16 x 16 pixels."""
    try:
        w, h = (int(x) for x in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be (width, height) in pixels, got {size!r}") from None
    if w < 16 or h < 16:
        raise ValueError(f"screenshot size must be at least 16 x 16 pixels, got {size!r}")
    return w, h


def _render(reg, path, size, annotate=True):
    """Write a PNG of the structures of ``reg`` (others hidden during the shot), with
    titles and colour bars composited on (``annotate``, needs matplotlib).  ``path``
    None: return the picture, an (h, w, 4) uint8 RGBA array, instead."""
    path = _check_screenshot(path, size)
    w, h = _check_size(size)
    import polyscope as ps
    if not ps.is_initialized() or _backend_name(ps) == "openGL_mock":
        raise ViewerUnavailable("polyscope's mock backend draws nothing; register with screenshot=... "
                                "(which starts the EGL backend) or call viewer.init('openGL3_egl') first")
    bars = _colour_bars(reg) if annotate else []
    titles = {n: t for n, t in reg.titles.items() if t and n in reg.structures} if annotate else {}
    with_matplotlib = _have_matplotlib()
    own_bars = []                     # drawn by polyscope itself when matplotlib is missing
    if (bars or titles) and not with_matplotlib:
        import warnings
        warnings.warn("matplotlib is not installed: screenshot written with polyscope's colour bar but "
                      "without titles (pip install matplotlib)", stacklevel=3)
        own_bars, bars, titles = _bar_quantities(reg), [], {}
    font = _font_px(w, h)
    bar_px = int(round(3.8 * font)) if bars else 0
    top_px = int(round(1.7 * font)) if titles else 0
    h_img = h - bar_px
    if h_img < 16:
        bars, bar_px, h_img = [], 0, h
    ps.set_window_size(w, h_img)
    ps.set_ground_plane_mode("none")
    projection = ps.get_view_projection_mode()
    # look structures up by name: a Python handle of a removed structure must never be touched
    missing = [n for n in reg.structures if _structure(ps, n) is None]
    if missing:
        raise ValueError(f"cannot render: structure(s) {missing} are no longer registered in polyscope")
    others = (_structure(ps, n) for n in sorted(set(_REGISTERED) - set(reg.structures)))
    hidden = [s for s in others if s is not None and s.is_enabled()]
    for s in hidden:
        s.set_enabled(False)
    for n in reg.structures:
        _structure(ps, n).set_enabled(True)
    try:
        camera = None
        if reg.bounds is not None:
            camera = _frame(ps, reg.bounds, w, h_img, top_px=top_px)
        else:
            ps.reset_camera_to_home_view()
        if bars or titles:
            image = np.asarray(ps.screenshot_to_buffer(transparent_bg=False))
            picture = _compose(path, image, (w, h), bars, _title_positions(titles, camera, w, h_img), font)
        elif path is None:
            picture = np.array(ps.screenshot_to_buffer(transparent_bg=False), dtype=np.uint8)
        elif own_bars:
            _polyscope_screenshot_with_bars(ps, reg, own_bars, path)
        else:
            _write_screenshot(ps, path)
    finally:
        for s in hidden:
            s.set_enabled(True)
        ps.set_automatically_compute_scene_extents(True)
        ps.set_view_projection_mode(projection)
    if path is None:
        return picture
    reg.screenshot = path
    return path


def _structure(ps, name):
    """The registered surface mesh or curve network called ``name``, or None."""
    if ps.has_surface_mesh(name):
        return ps.get_surface_mesh(name)
    if ps.has_curve_network(name):
        return ps.get_curve_network(name)
    return None


def _bar_quantities(reg):
    """[(structure, quantity)]: the first shown scalar quantity of each distinct colour bar."""
    seen, out = set(), []
    for (sname, qname), q in reg.quantities.items():
        if q.kind == "scalar" and q.enabled and sname in reg.structures:
            key = (q.label or qname, tuple(q.vminmax), q.cmap or "viridis")
            if key not in seen:
                seen.add(key)
                out.append((sname, qname))
    return out


def _polyscope_screenshot_with_bars(ps, reg, quantities, path):
    """Screenshot with polyscope's own on-screen colour bars of ``quantities`` (the UI
    is included but its panels are not built), plain quantities again afterwards."""
    for sname, qname in quantities:
        _add_scalar(reg, sname, qname, reg.quantities[(sname, qname)], colour_bar=True)
    ps.set_build_gui(False)
    try:
        _write_screenshot(ps, path, include_UI=True)
    finally:
        ps.set_build_gui(True)
        for sname, qname in quantities:
            _add_scalar(reg, sname, qname, reg.quantities[(sname, qname)])


def _write_screenshot(ps, path, include_UI=False):
    """polyscope's render as a PNG (:func:`save_png`), or as polyscope writes it when Pillow
    is missing."""
    image = np.asarray(ps.screenshot_to_buffer(transparent_bg=False, include_UI=include_UI))
    if not save_png(path, image):
        ps.screenshot(path, transparent_bg=False, include_UI=include_UI)


def save_png(path, image):
    """Write an (h, w, 3|4) uint8 image as a full-colour RGB PNG (every pixel as rendered:
    a smooth field shows no bands; a 256-colour palette quantised smooth fields into steps).

    Returns False (nothing written) when Pillow is missing.
    """
    try:
        from PIL import Image
    except ImportError:
        return False
    img = Image.fromarray(np.ascontiguousarray(np.asarray(image, dtype=np.uint8)[..., :3]), "RGB")
    img.save(os.fspath(path), format="PNG", optimize=True)
    return True


def _have_matplotlib():
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def _font_px(w, h):
    """Text height in pixels for a ``w`` x ``h`` picture."""
    return float(np.clip(min(w, 1.6 * h) / 75.0, 7.0, 18.0))


def _colour_bars(reg):
    """[(label, (lo, hi), cmap)] of the scalar quantities shown (enabled) on the
    structures of ``reg``: one bar per distinct label, range and colour map."""
    bars = {}
    for (sname, qname), q in reg.quantities.items():
        if q.kind == "scalar" and q.enabled and sname in reg.structures:
            bars.setdefault((q.label or qname, tuple(q.vminmax), q.cmap or "viridis"), None)
    return list(bars)


def _title_positions(titles, camera, w, h_img):
    """[(text, x_px, y_px)]: each title centred above its structure's box (pixels, y down)."""
    out = []
    for name, text in titles.items():
        box = _REGISTERED.get(name)
        if camera is None or box is None:
            out.append((text, 0.5 * w, 0.0))
            continue
        (cx, cy), wpp = camera
        x = 0.5 * w + (0.5 * (box[0, 0] + box[1, 0]) - cx) / wpp
        y = 0.5 * h_img - (box[1, 1] - cy) / wpp
        out.append((text, float(np.clip(x, 0, w)), float(np.clip(y, 0, h_img))))
    return out


_CMAP_NAMES = {"blues": "Blues", "reds": "Reds", "spectral": "Spectral", "phase": "hsv", "pink": "pink"}


def _mpl_cmap(name):
    import matplotlib
    for n in (name, _CMAP_NAMES.get(name, name), str(name).lower()):
        try:
            return matplotlib.colormaps[n]
        except KeyError:
            continue
    return matplotlib.colormaps["viridis"]


def _tick_text(x):
    return "0" if x == 0 else f"{x:.3g}"


def _compose(path, image, size, bars, titles, font):
    """Save ``image`` (polyscope's render, (h_img, w, 3|4) uint8) with ``titles``
    (text, x, y) drawn on it and horizontal colour bars below, as a ``size`` PNG
    (``path`` None: return the picture as an (h, w, 4) uint8 array)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colorbar import ColorbarBase
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    w, h = size
    h_img, w_img = image.shape[:2]
    dpi = 100.0
    pt = font * 72.0 / dpi
    fig = Figure(figsize=(w / dpi, h / dpi), dpi=dpi, facecolor="white")
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.0, 1.0 - h_img / h, w_img / w, h_img / h))
    ax.imshow(image[..., :3], extent=(0, w_img, h_img, 0), interpolation="nearest")
    ax.set_xlim(0, w_img)
    ax.set_ylim(h_img, 0)
    ax.set_axis_off()
    for text, x, y in titles:
        ha = "left" if x < 0.08 * w else "right" if x > 0.92 * w else "center"
        ax.text(x, max(y - 0.25 * font, 1.15 * font), text, ha=ha, va="bottom", fontsize=pt, color="0.1",
                clip_on=False)
    if bars:
        bar_h = h - h_img
        slot = w / len(bars)
        for i, (label, (lo, hi), cmap) in enumerate(bars):
            width = min(0.7 * slot, 0.45 * w)
            left = i * slot + 0.5 * (slot - width)
            cax = fig.add_axes((left / w, 1.7 * font / h, width / w, 0.55 * font / h))
            cb = ColorbarBase(cax, cmap=_mpl_cmap(cmap), norm=Normalize(lo, hi), orientation="horizontal")
            ticks = [lo, 0.0, hi] if lo < 0 < hi else [lo, hi]
            cb.set_ticks(ticks)
            cb.set_ticklabels([_tick_text(t) for t in ticks])
            cax.tick_params(labelsize=0.9 * pt, length=2, pad=1)
            cb.outline.set_linewidth(0.5)
            cax.set_title(label, fontsize=pt, pad=0.6 * pt)
    canvas = fig.canvas
    canvas.draw()
    if path is None:
        return np.array(canvas.buffer_rgba(), dtype=np.uint8)    # (h, w, 4): figsize × dpi
    if not save_png(path, np.asarray(canvas.buffer_rgba())):
        fig.savefig(path, dpi=dpi, facecolor="white")
    return None


def _png_bytes(image):
    """PNG file bytes of an (h, w, 4) uint8 RGBA array (zlib only: no imaging library needed)."""
    import struct
    import zlib
    image = np.ascontiguousarray(image, dtype=np.uint8)
    h, w = image.shape[:2]
    rows = np.concatenate([np.zeros((h, 1), dtype=np.uint8), image.reshape(h, w * 4)], axis=1)  # filter 0

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6)) + chunk(b"IEND", b""))
