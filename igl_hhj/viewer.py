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
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .mesh import as_mesh

__all__ = [
    "ViewerUnavailable", "QuantityInfo", "Registration", "QUANTITIES", "METHODS",
    "init", "show", "color_range", "curvature_estimate", "local_edge_length",
    "register_curvature", "register_comparison", "register_hessian", "register_biharmonic",
    "register_regge_curvature", "register_scalars", "register_result", "register_creases", "merge", "screenshot",
    "VIEWS", "best_view_direction", "view_rotation", "to_image", "REPR_PNG_SIZE",
]

QUANTITIES = ("k1", "k2", "H", "K")
METHODS = ("hhj", "igl", "heine")
LABELS = {"k1": "kappa1", "k2": "kappa2", "H": "mean H", "K": "Gauss K"}
LENGTH_UNIT = "1/length unit"
"""Unit of curvatures in colour-bar labels (the mesh's coordinates carry the length unit)."""
LONG_LABELS = {"k1": f"principal curvature κ1 [{LENGTH_UNIT}]", "k2": f"principal curvature κ2 [{LENGTH_UNIT}]",
               "H": f"mean curvature H [{LENGTH_UNIT}]", "K": "Gauss curvature K [1/length unit²]"}
"""Colour-bar labels of the curvature quantities (with their units)."""
VIEWS = ("auto", "+x", "-x", "+y", "-y", "+z", "-z")
"""Named ``view=`` directions (the side the camera looks from); a 3-vector works too."""
METHOD_TITLES = {"HHJ": "HHJ", "libigl": "libigl quadric fit", "Heine": "Heine P1"}
"""How titles name the estimators (by their tag)."""
_TAG = {"hhj": "HHJ", "igl": "libigl", "heine": "Heine"}
_EGL_HINT = ("headless rendering needs EGL: on Debian/Ubuntu `apt-get install libegl1 libegl-mesa0 "
             "libgl1-mesa-dri`")
_REGISTERED: dict[str, np.ndarray] = {}  # name -> (2, 3) bounds of the structures this module registered (they may since be removed)


class ViewerUnavailable(RuntimeError):
    """polyscope could not open the requested rendering backend (no display, no EGL, ...)."""


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


# --------------------------------------------------------------------------- backend
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


# --------------------------------------------------------------------------- values
def color_range(*arrays, symmetric=True, robust=None) -> tuple[float, float]:
    """One colour range for several value arrays (NaN/inf ignored).

    Parameters
    ----------
    *arrays : array_like
    symmetric : bool, default True
        Return ``(-m, m)`` with ``m`` the largest magnitude (diverging maps:
        white is 0).
    robust : float or None
        Percentile ``p`` in [0, 50): use the ``[p, 100-p]`` percentiles instead
        of min/max, ignoring outliers.

    Returns
    -------
    (lo, hi) : floats with ``lo < hi`` (``(-1, 1)`` if no finite value).
    """
    if robust is not None and not (0.0 <= float(robust) < 50.0):
        raise ValueError(f"robust must be a percentile in [0, 50), got {robust!r}")
    vals = np.concatenate([np.asarray(a, dtype=np.float64).ravel() for a in arrays]) if arrays else np.zeros(0)
    vals = vals[np.isfinite(vals)]
    if vals.size == 0:
        return (-1.0, 1.0)
    if robust is None:
        lo, hi = float(vals.min()), float(vals.max())
    else:
        lo, hi = (float(x) for x in np.percentile(vals, [float(robust), 100.0 - float(robust)]))
    if symmetric:
        m = max(abs(lo), abs(hi))
        lo, hi = -m, m
    if hi <= lo:
        pad = max(abs(hi), 1.0) * 1e-6
        lo, hi = lo - pad, hi + pad
    return lo, hi


def local_edge_length(mesh, location) -> np.ndarray:
    """Mean length of the edges of each face, or incident to each vertex.

    Parameters
    ----------
    mesh : TriangleMesh
    location : {"face", "vertex"}

    Returns
    -------
    (#F,) or (#V,) float64 (unreferenced vertices get the global mean).
    """
    if location == "face":
        return mesh.edge_lengths.mean(axis=1)
    ends = mesh.edges.ravel()
    total = np.bincount(ends, weights=np.repeat(mesh.unique_edge_lengths, 2), minlength=mesh.n_vertices)
    count = np.bincount(ends, minlength=mesh.n_vertices)
    out = np.full(mesh.n_vertices, mesh.mean_edge_length)
    np.divide(total, count, out=out, where=count > 0)
    return out


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
    from . import baselines
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


def _explicit_range(vminmax):
    """A user-given (lo, hi) colour range, checked."""
    try:
        lo, hi = (float(x) for x in vminmax)
    except (TypeError, ValueError):
        raise ValueError(f"a colour range must be (lo, hi), got {vminmax!r}") from None
    if not lo < hi:
        raise ValueError(f"a colour range must be (lo, hi) with lo < hi, got {vminmax!r}")
    return lo, hi


def _check(value, name, choices):
    if value not in choices:
        raise ValueError(f"{name} must be one of {choices}, got {value!r}")


# --------------------------------------------------------------------------- views
def _fibonacci_sphere(n):
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(1.0 - z * z)
    phi = np.pi * (3.0 - np.sqrt(5.0)) * i
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def best_view_direction(V, F, *, n_directions=400, max_faces=50_000) -> np.ndarray:
    """Unit direction from which the mesh shows its largest projected area.

    The projected area seen from ``d`` is ``½ Σ_T |T| |n_T · d|`` (closed
    surfaces); it is maximised over ``n_directions`` near-uniform directions (a Fibonacci sphere, plus the axes; at most ``max_faces`` faces,
    evenly subsampled, enter the sum).  Of ``d`` and ``-d``: on an open
    surface the side that sees clearly more of it (25 %), otherwise the view
    from above (+y, the usual "up" of scanned models), then from the front (+z).

    Parameters
    ----------
    V : (#V, 3) array_like, F : (#F, 3) array_like int

    Returns
    -------
    (3,) float64 unit vector (the side the camera looks from).

    Examples
    --------
    >>> import numpy as np
    >>> from igl_hhj import viewer
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
    >>> np.round(viewer.best_view_direction(V, F), 2).tolist()   # a triangle in the xy plane
    [0.0, 0.0, 1.0]
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F)
    step = max(1, len(F) // int(max_faces))
    T = V[F[::step]]
    N = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])          # 2 |T| n_T
    D = _fibonacci_sphere(int(n_directions))
    D = np.vstack([np.eye(3), D[D[:, 2] >= 0]])               # the axes are candidates too
    seen = N @ D.T                                            # (#T, #D) 2 |T| n_T · d
    score = np.abs(seen).sum(axis=0)
    k = int(np.flatnonzero(score >= score.max() * (1 - 1e-9))[0])
    d = D[k]
    front, back = np.clip(seen[:, k], 0, None).sum(), np.clip(-seen[:, k], 0, None).sum()
    if max(front, back) > 1.25 * min(front, back):        # an open surface: look at its larger side
        flip = back > front
    else:                                                  # closed: from above (+y), then from the front (+z)
        flip = d @ np.array([0.1, 1.0, 0.5]) < 0
    if flip:
        d = -d
    return d / np.linalg.norm(d)


def view_rotation(view, V=None, F=None, *, landscape=False) -> np.ndarray:
    """(3, 3) rotation ``R``: ``V @ R.T`` is seen from ``view`` by the screenshots' camera
    (which looks down -z with y up).

    Parameters
    ----------
    view : {"auto", "+x", "-x", "+y", "-y", "+z", "-z"} or (3,) direction
        The side the camera looks from; "auto" is :func:`best_view_direction`
        of ``(V, F)``.  The picture's "up" is world +y projected into the view
        (+z or -z when looking along y).
    landscape : bool, turn the picture a quarter turn when the mesh ``V``
        would be taller than wide (copies laid side by side fit better).

    Returns
    -------
    (3, 3) float64 orthogonal, det +1; rows: picture right, up, towards the camera.

    Examples
    --------
    >>> from igl_hhj import viewer
    >>> viewer.view_rotation("+z").tolist() == [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    True
    """
    if isinstance(view, str):
        _check(view, "view", VIEWS)
        if view == "auto":
            if V is None or F is None:
                raise ValueError("view='auto' needs the mesh (V, F)")
            d = best_view_direction(V, F)
        else:
            d = np.zeros(3)
            d["xyz".index(view[1])] = 1.0 if view[0] == "+" else -1.0
    else:
        d = np.asarray(view, dtype=np.float64).reshape(-1)
        if d.shape != (3,) or not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0:
            raise ValueError(f"view must be one of {VIEWS} or a nonzero 3-vector, got {view!r}")
        d = d / np.linalg.norm(d)
    up = np.array([0.0, 1.0, 0.0])
    if abs(d[1]) > 0.95:                       # looking along y: the front (+z) at the picture's bottom
        up = np.array([0.0, 0.0, -np.sign(d[1])])
    u = up - (up @ d) * d
    u /= np.linalg.norm(u)
    r = np.cross(u, d)
    R = np.stack([r, u, d])
    if landscape and V is not None:            # a quarter turn in the picture if it is taller than wide
        P = np.asarray(V, dtype=np.float64) @ R[:2].T
        if np.ptp(P[:, 1]) > np.ptp(P[:, 0]):
            R = np.stack([u, -r, d])
    R[np.abs(R) < 1e-15] = 0.0
    return R


def _rotation_for(view, V, F):
    """None (no rotation) or the (3, 3) display rotation of ``view`` (also accepts a matrix)."""
    if view is None:
        return None
    if not isinstance(view, str) and np.shape(view) == (3, 3):
        return np.asarray(view, dtype=np.float64)
    return view_rotation(view, V, F)


# --------------------------------------------------------------------------- registration helpers
def _placed(reg, name, V, F, offset=None, view=None):
    """The displayed positions of the mesh (V, F) registered as ``name``: turned by ``view``
    (the rotation recorded in ``reg.rotations``) and translated by ``offset``."""
    R = _rotation_for(view, V, F)
    if R is not None:
        V = V @ R.T
        reg.rotations[name] = R
    if offset is not None:
        off = np.asarray(offset, dtype=np.float64)
        if off.shape != (3,) or not np.all(np.isfinite(off)):
            raise ValueError(f"offset must be 3 finite numbers, got {offset!r}")
        V = V + off
    return V


def _record_bounds(reg, name, X):
    """Add the bounding box of a structure's displayed points X to ``reg`` and the registry."""
    box = np.stack([X.min(axis=0), X.max(axis=0)])
    reg.bounds = _union_bounds(reg.bounds, box)
    _REGISTERED[name] = box


def _surface(ps, reg, name, V, F, offset=None, view=None, title=None):
    """Register a surface mesh under ``name`` (turned by ``view``, translated by ``offset``),
    replacing one of the same name; ``title`` is drawn above it in screenshots."""
    V = _placed(reg, name, V, F, offset, view)
    if title:
        reg.titles[name] = str(title)
    if ps.has_surface_mesh(name):
        ps.remove_surface_mesh(name)
    s = ps.register_surface_mesh(name, V, F, color=(0.75, 0.75, 0.75))  # grey: no quantity shown
    reg.structures[name] = s
    _record_bounds(reg, name, V)
    return s


def _title(title, what, name, mesh):
    """``title`` as given ("" = none), or "<what> — <name>, <#F> faces"."""
    if title is not None:
        return str(title)
    who = "" if name == "mesh" else f"{name}, "
    return f"{what} — {who}{mesh.n_faces:,} faces"


def _union_bounds(*boxes):
    """Bounding box (2, 3) of several (2, 3) boxes (None entries ignored; None if all are)."""
    boxes = [b for b in boxes if b is not None]
    if not boxes:
        return None
    boxes = np.stack(boxes)
    return np.stack([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])


def _scalar(reg, sname, qname, values, defined_on, vminmax, cmap, enabled=False, label=None):
    """Record a scalar quantity; :func:`_add_scalars` hands them to polyscope."""
    values = np.asarray(values, dtype=np.float64)
    reg.quantities[(sname, qname)] = QuantityInfo(values, defined_on, "scalar", tuple(float(x) for x in vminmax),
                                                  cmap, bool(enabled), label)


def _add_scalars(reg):
    """Add the recorded scalar quantities, the enabled one of each structure last.

    polyscope shows one colour quantity per structure and remembers a
    quantity's "enabled" flag by name across re-registration; adding the
    wanted one last makes it win regardless of what an earlier picture showed.
    """
    items = sorted(((k, q) for k, q in reg.quantities.items() if q.kind == "scalar"),
                   key=lambda kq: kq[1].enabled)
    for (sname, qname), q in items:
        _add_scalar(reg, sname, qname, q)


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


def _line_field(reg, sname, qname, vectors, normals, defined_on, enabled=False):
    """A principal-direction field drawn as tangent *lines* (polyscope tangent
    vectors with 2-fold symmetry): ``vectors`` (n, 3) tangent to ``normals``
    (n, 3), their length is the drawn length."""
    vectors = np.asarray(vectors, dtype=np.float64)
    vectors = np.where(np.isfinite(vectors), vectors, 0.0)
    computed = vectors
    R = reg.rotations.get(sname)
    if R is not None:                        # the structure is displayed turned by R
        vectors, normals = vectors @ R.T, np.asarray(normals, dtype=np.float64) @ R.T
    length = np.linalg.norm(vectors, axis=1)
    bx = np.zeros_like(vectors)
    np.divide(vectors, length[:, None], out=bx, where=length[:, None] > 0)
    bx[length == 0] = (1.0, 0.0, 0.0)
    by = np.cross(np.asarray(normals, dtype=np.float64), bx)     # tangent frame (bx, by)
    values = np.stack([length, np.zeros_like(length)], axis=1)
    reg.structures[sname].add_tangent_vector_quantity(qname, values, bx, by, n_sym=2, defined_on=defined_on,
                                                      vectortype="ambient", enabled=bool(enabled))
    reg.quantities[(sname, qname)] = QuantityInfo(computed, defined_on, "line", None, None, bool(enabled))


def _add_estimate(reg, sname, mesh, est, tag, ranges, cmap, directions, direction_scale, enabled=None,
                  show_directions=False):
    """Scalar (k1, k2, H, K) and direction quantities of one CurvatureEstimate."""
    where = "faces" if est.location == "face" else "vertices"
    for q in QUANTITIES:
        _scalar(reg, sname, f"{LABELS[q]} ({tag} {where})", getattr(est, q), where, ranges[q], cmap,
                enabled=(q == enabled), label=LONG_LABELS[q])
    if directions and est.d1 is not None:
        scale = direction_scale * local_edge_length(mesh, est.location)[:, None]
        normals = mesh.face_normals if est.location == "face" else mesh.vertex_normals
        for k, lab in (("d1", "PD1"), ("d2", "PD2")):
            _line_field(reg, sname, f"{lab} ({tag} {where})", getattr(est, k) * scale, normals, where,
                        enabled=show_directions)


def _polyscope_for(screenshot):
    """polyscope, initialised for interactive use or (``screenshot`` given) able to render."""
    import polyscope as ps
    if screenshot is not None and (not ps.is_initialized() or _backend_name(ps) == "openGL_mock"):
        return init("openGL3_egl")
    return init("auto")


def _finish(reg, screenshot, size):
    _add_scalars(reg)
    if screenshot is not None:
        _render(reg, screenshot, size)
    return reg


# --------------------------------------------------------------------------- curvature
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

    from .mesh_io import read_curvature
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


def register_comparison(V: Any, F: Any = None, *, hhj=None, libigl=None, per="face", layout="copy", name="mesh", enabled="H",
                        directions=True, show_directions=False, symmetric=True, robust=1.0, cmap="coolwarm", offset=None,
                        direction_scale=0.5, radius=5, view=None, title=None, screenshot=None, size=(1600, 800)) -> Registration:
    """HHJ curvature beside ``igl.principal_curvature`` on the same mesh, identical colour ranges.

    Parameters
    ----------
    V, F : mesh
    hhj, libigl : CurvatureEstimate, optional precomputed results (HHJ at
        faces or vertices; libigl at vertices).
    per : {"face", "vertex"}, where the HHJ values live if computed here.
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


# --------------------------------------------------------------------------- other fields
def register_hessian(V, F, w, *, boundary_gradient=None, name="mesh", label="w", enabled="trace",
                     directions=True, symmetric=True, robust=None, cmap="coolwarm", direction_scale=0.5,
                     offset=None, view=None, title=None, screenshot=None, size=(1024, 768)) -> Registration:
    """Register a P1 function ``w`` and its HHJ surface Hessian (Walker eq. 4.9).

    Parameters
    ----------
    w : (#V,) array_like or callable ``w(V: (#V, 3)) -> (#V,)``
    boundary_gradient : optional clamped data, see :func:`igl_hhj.surface_hessian`.
    label : str, name of the function in the quantity names.
    enabled : {"w", "lambda1", "lambda2", "trace", "norm"}, quantity shown first.
    offset : (3,), optional translation of the structure.
    view : None, "auto", "+x", "-x", "+y", "-y", "+z", "-z" or (3,), optional:
        turn the mesh for display so that it is seen from that side
        (:func:`view_rotation`; None: as given).
    title : str, optional, the title above the copy in screenshots ("" for
        none; default: method, per face / vertex, name, face count).

    Registered (on structure ``name``): ``w`` (vertices, viridis), the
    eigenvalues λ1 ≥ λ2 of the tangential Hessian and its trace (the surface
    Laplacian Δ_Γ w) per face (diverging, λ1/λ2 share a range), its Frobenius
    norm (faces), and the eigen-directions (face vectors).

    Returns
    -------
    Registration; ``ranges`` keys "w", "lambda", "trace", "norm".
    """
    from .curvature import principal_from_shape_operator, surface_hessian
    _check(enabled, "enabled", ("w", "lambda1", "lambda2", "trace", "norm"))
    mesh = as_mesh(V, F)
    _check_screenshot(screenshot, size)
    wv = w(mesh.V.copy()) if callable(w) else w
    wv = np.asarray(wv, dtype=np.float64)
    if wv.shape != (mesh.n_vertices,):
        raise ValueError(f"w must have shape ({mesh.n_vertices},), got {wv.shape}")
    if not np.all(np.isfinite(wv)):
        raise ValueError("w contains NaN or inf values")
    Hw = surface_hessian(mesh.V, mesh.F, wv, boundary_gradient=boundary_gradient)
    d1, d2, l1, l2 = principal_from_shape_operator(Hw, mesh.face_normals)
    tr = np.trace(Hw, axis1=1, axis2=2)
    nrm = np.linalg.norm(Hw, axis=(1, 2))
    ps = _polyscope_for(screenshot)
    reg = Registration()
    reg.ranges = {"w": color_range(wv, symmetric=False),
                  "lambda": color_range(l1, l2, symmetric=symmetric, robust=robust),
                  "trace": color_range(tr, symmetric=symmetric, robust=robust),
                  "norm": color_range(nrm, symmetric=False, robust=robust)}
    names = {"w": label, "lambda1": f"Hess {label} lambda1", "lambda2": f"Hess {label} lambda2",
             "trace": f"Hess {label} trace (surface Laplacian)", "norm": f"|Hess {label}|"}
    _surface(ps, reg, name, mesh.V, mesh.F, offset, view,
             _title(title, label if enabled == "w" else f"HHJ {names[enabled]}, per face", name, mesh))
    for key, vals, where, rng, cm in (("w", wv, "vertices", "w", "viridis"),
                                      ("lambda1", l1, "faces", "lambda", cmap),
                                      ("lambda2", l2, "faces", "lambda", cmap),
                                      ("trace", tr, "faces", "trace", cmap),
                                      ("norm", nrm, "faces", "norm", "viridis")):
        _scalar(reg, name, names[key], vals, where, reg.ranges[rng], cm, enabled=(key == enabled))
    if directions:
        scale = direction_scale * local_edge_length(mesh, "face")[:, None]
        _line_field(reg, name, f"Hess {label} dir1", d1 * scale, mesh.face_normals, "faces")
        _line_field(reg, name, f"Hess {label} dir2", d2 * scale, mesh.face_normals, "faces")
    return _finish(reg, screenshot, size)


_BIHARMONIC_LABELS = {"u1": "u1 (approx. u)", "u2": "u2 (approx. -Laplacian u)", "u": "u exact",
                      "error": "error u1 - u", "f": "f"}


def register_biharmonic(V, F, u1, u2=None, *, exact=None, f=None, name="mesh", enabled="u1", symmetric=None,
                        robust=None, ranges=None, offset=None, view=None, title=None, screenshot=None,
                        size=(1024, 768)) -> Registration:
    """Register a mixed-P1 biharmonic solution (Stein et al.): ``u1 ≈ u``, ``u2 ≈ -Δu``.

    Parameters
    ----------
    u1, u2 : (#V,) array_like (as returned by :func:`igl_hhj.biharmonic_solve`)
    exact : (#V,) array_like or callable ``u(V) -> (#V,)``, optional: also
        registers ``u`` and the error ``u1 - u`` (diverging, symmetric).
    f : (#V,) array_like or callable, optional right-hand side (registered too).
    enabled : {"u1", "u2", "u", "error", "f"}
    symmetric : bool or None; None = symmetric (diverging map) when the values
        change sign, else a sequential ``viridis`` range.
    ranges : dict, optional explicit ranges by key ("u1", "u2", "f", "error").
    offset : (3,), optional translation of the structure.
    view : None, "auto", "+x", "-x", "+y", "-y", "+z", "-z" or (3,), optional:
        turn the mesh for display so that it is seen from that side
        (:func:`view_rotation`; None: as given).
    title : str, optional, the title above the copy in screenshots ("" for
        none; default: method, per face / vertex, name, face count).

    Returns
    -------
    Registration; ``ranges`` keys among "u1", "u2", "f", "error" (u shares u1's).
    """
    mesh = as_mesh(V, F)
    _check_screenshot(screenshot, size)
    n = mesh.n_vertices

    def vertex_values(x, what):
        x = x(mesh.V.copy()) if callable(x) else x
        x = np.broadcast_to(np.asarray(x, dtype=np.float64), (n,)) if np.ndim(x) == 0 else np.asarray(x, float)
        if x.shape != (n,):
            raise ValueError(f"{what} must have shape ({n},), got {x.shape}")
        return x

    fields = {"u1": vertex_values(u1, "u1")}
    if u2 is not None:
        fields["u2"] = vertex_values(u2, "u2")
    if exact is not None:
        fields["u"] = vertex_values(exact, "exact")
        fields["error"] = fields["u1"] - fields["u"]
    if f is not None:
        fields["f"] = vertex_values(f, "f")
    _check(enabled, "enabled", tuple(fields))
    ps = _polyscope_for(screenshot)
    reg = Registration()
    _surface(ps, reg, name, mesh.V, mesh.F, offset, view,
             _title(title, f"mixed P1 biharmonic: {_BIHARMONIC_LABELS[enabled]}", name, mesh))
    for key in ("u1", "u2", "f", "error"):
        if key not in fields:
            continue
        vals = [fields[key]] + ([fields["u"]] if key == "u1" and "u" in fields else [])
        fin = np.concatenate(vals)
        fin = fin[np.isfinite(fin)]
        signed = key == "error" or (fin.size > 0 and fin.min() < 0 < fin.max())
        sym = signed if symmetric is None else bool(symmetric)
        reg.ranges[key] = (_explicit_range(ranges[key]) if ranges and key in ranges
                           else color_range(*vals, symmetric=sym, robust=robust))
        cm = "coolwarm" if sym else "viridis"
        for k in [key] + (["u"] if key == "u1" and "u" in fields else []):
            _scalar(reg, name, _BIHARMONIC_LABELS[k], fields[k], "vertices", reg.ranges[key], cm,
                    enabled=(k == enabled), label="u1 and exact u" if key == "u1" and "u" in fields else None)
    return _finish(reg, screenshot, size)


def register_regge_curvature(V: Any, F: Any = None, *, boundary="natural", mass="consistent", compare=True, name="mesh",
                             enabled="K_h", symmetric=True, robust=None, cmap="coolwarm", vminmax=None,
                             offset=None, view=None, title=None, screenshot=None, size=(1024, 768)) -> Registration:
    """Register the Regge (degree-0, edge-length metric) Gauss curvature K_h (Gopalakrishnan et al. 2024).

    Parameters
    ----------
    boundary, mass : see :func:`igl_hhj.regge.gauss_curvature`.
    compare : bool, also register the pointwise angle defect density
        (libigl ``gaussian_curvature`` / barycentric area, vertices) and the HHJ
        Gauss curvature ``det(S_h + ν⊗ν)`` (faces), all on K_h's colour range.
    enabled : {"K_h", "angle_defect", "hhj"}
    vminmax : (lo, hi), optional explicit range (e.g. shared with other pictures);
        default: :func:`color_range` of K_h.
    offset : (3,), optional translation of the structure.
    view : None, "auto", "+x", "-x", "+y", "-y", "+z", "-z" or (3,), optional:
        turn the mesh for display so that it is seen from that side
        (:func:`view_rotation`; None: as given).
    title : str, optional, the title above the copy in screenshots ("" for
        none; default: method, per face / vertex, name, face count).

    Returns
    -------
    Registration; ``ranges["K"]`` is the shared range.
    """
    import igl

    from .regge import gauss_curvature
    _check(enabled, "enabled", ("K_h", "angle_defect", "hhj") if compare else ("K_h",))
    mesh = as_mesh(V, F)
    _check_screenshot(screenshot, size)
    Kh = gauss_curvature(mesh.V, mesh.F, boundary=boundary, mass=mass)
    fields = {"K_h": ("Regge K_h (vertices)", Kh, "vertices")}
    if compare:
        from .curvature import face_gaussian_curvature
        M = igl.massmatrix(mesh.V, mesh.F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
        M = np.pad(M, (0, mesh.n_vertices - len(M)))
        with np.errstate(divide="ignore", invalid="ignore"):
            defect = np.asarray(igl.gaussian_curvature(mesh.V, mesh.F), dtype=np.float64) / M
        defect = np.pad(defect, (0, mesh.n_vertices - len(defect)), constant_values=np.nan)
        defect[~mesh.referenced_vertices | mesh.boundary_vertices] = np.nan
        fields["angle_defect"] = ("angle defect / area (vertices)", defect, "vertices")
        fields["hhj"] = ("HHJ Gauss K (faces)", face_gaussian_curvature(mesh.V, mesh.F), "faces")
    ps = _polyscope_for(screenshot)
    reg = Registration()
    reg.ranges["K"] = (_explicit_range(vminmax) if vminmax is not None
                       else color_range(Kh, symmetric=symmetric, robust=robust))
    what = {"K_h": "Regge K_h, per vertex", "angle_defect": "angle defect / area, per vertex",
            "hhj": "HHJ Gauss K, per face"}[enabled]
    _surface(ps, reg, name, mesh.V, mesh.F, offset, view, _title(title, what, name, mesh))
    for key, (qname, vals, where) in fields.items():
        _scalar(reg, name, qname, vals, where, reg.ranges["K"], cmap, enabled=(key == enabled),
                label=LONG_LABELS["K"])
    return _finish(reg, screenshot, size)


def register_scalars(V, F, fields, *, name="mesh", enabled=None, shared_range=False, symmetric=True, robust=None,
                     cmap="coolwarm", vminmax=None, offset=None, view=None, title=None, screenshot=None,
                     size=(1024, 768)) -> Registration:
    """Register arbitrary per-vertex / per-face scalar fields (errors, indicators, ...).

    Parameters
    ----------
    fields : dict, quantity name -> (#V,) or (#F,) array_like (the location is
        taken from the length; a mesh with #V == #F takes vertices).
    enabled : quantity name shown first (default: the first one).
    shared_range : bool, one colour range for all fields (else one each).
    symmetric, robust, cmap : colour range and map (:func:`color_range`).
    vminmax : (lo, hi), optional, one explicit range for every field (e.g. the
        same range as another structure's picture).
    offset : (3,) translation of the structure (to lay out several pictures).
    view : as :func:`register_curvature`.
    title : str, optional, the title above the copy in screenshots ("" for
        none; default: ``name`` (or the shown field's name), face count).

    Returns
    -------
    Registration; ``ranges`` keyed by quantity name.
    """
    mesh = as_mesh(V, F)
    _check_screenshot(screenshot, size)
    if not isinstance(fields, dict) or not fields:
        raise TypeError("fields must be a non-empty dict: quantity name -> (#V,) or (#F,) values")
    vals, where = {}, {}
    for k, x in fields.items():
        x = np.asarray(x, dtype=np.float64)
        if x.shape == (mesh.n_vertices,):
            where[k] = "vertices"
        elif x.shape == (mesh.n_faces,):
            where[k] = "faces"
        else:
            raise ValueError(f"field {k!r} has shape {x.shape}; expected ({mesh.n_vertices},) per vertex "
                             f"or ({mesh.n_faces},) per face")
        vals[k] = x
    enabled = next(iter(vals)) if enabled is None else enabled
    _check(enabled, "enabled", tuple(vals))
    ps = _polyscope_for(screenshot)
    reg = Registration()
    if vminmax is not None:
        common = _explicit_range(vminmax)
    else:
        common = color_range(*vals.values(), symmetric=symmetric, robust=robust) if shared_range else None
    _surface(ps, reg, name, mesh.V, mesh.F, offset, view,
             _title(title, name if name != "mesh" else str(enabled), "mesh", mesh))
    for k, x in vals.items():
        reg.ranges[k] = common or color_range(x, symmetric=symmetric, robust=robust)
        _scalar(reg, name, k, x, where[k], reg.ranges[k], cmap, enabled=(k == enabled))
    return _finish(reg, screenshot, size)


def register_creases(V: Any, F: Any = None, creases=None, *, feature_angle=40.0, name="creases",
                     cmap="coolwarm", vminmax=None, radius=0.004, offset=None, view=None,
                     screenshot=None, size=(1024, 768)) -> Registration:
    """Register the crease edges of a mesh as a polyscope curve network coloured by θ_e.

    The creases' own curvature is a line measure (:mod:`igl_hhj.features`): the signed
    dihedral angle θ_e (+ convex, - concave) per crease edge, drawn here in degrees.

    Parameters
    ----------
    V : (#V, 3) array_like, F : (#F, 3) array_like int
    creases : :class:`igl_hhj.features.CreaseNetwork`, optional (e.g.
        ``feature_principal_curvature(V, F).creases``); default: detected with
        ``feature_angle``.
    feature_angle : float, degrees (when ``creases`` is not given).
    name : str, structure name.
    cmap : polyscope colour map (diverging by default: convex red, concave blue).
    vminmax : (lo, hi) in degrees, optional (default symmetric, ± the largest absolute angle).
    radius : curve radius relative to the scene's length scale.
    offset, view : as :func:`register_curvature` (use the same to draw the creases
        on a copy of the surface).
    screenshot, size : as :func:`register_curvature`.

    Returns
    -------
    Registration; ``quantities[(name, "crease angle")]`` holds θ_e in degrees, per edge.

    Examples
    --------
    >>> from igl_hhj import viewer
    >>> from igl_hhj.surfaces.creased import capped_cylinder
    >>> V, F, _ = capped_cylinder(1)
    >>> viewer.init("openGL_mock")                                    # doctest: +ELLIPSIS
    <module 'polyscope' ...>
    >>> reg = viewer.register_creases(V, F)
    >>> reg.quantities[("creases", "crease angle")].values.shape    # the 72 rim edges
    (72,)
    """
    from .features import crease_edges, crease_network
    mesh = as_mesh(V, F)
    _check_screenshot(screenshot, size)
    if creases is None:
        creases = crease_network(mesh, crease_edges(mesh, feature_angle))
    if len(creases.edges) == 0:
        raise ValueError("no crease edges to draw (lower feature_angle)")
    ps = _polyscope_for(screenshot)
    reg = Registration()
    X = _placed(reg, name, mesh.V, mesh.F, offset, view)
    used = np.unique(creases.edges)                       # only the crease vertices as nodes
    nodes = X[used]
    edges = np.searchsorted(used, creases.edges)
    if ps.has_curve_network(name):
        ps.remove_curve_network(name)
    reg.structures[name] = ps.register_curve_network(name, nodes, edges, radius=radius, color=(0.1, 0.1, 0.1))
    _record_bounds(reg, name, nodes)
    deg = np.degrees(creases.theta)
    rng = _explicit_range(vminmax) if vminmax is not None else color_range(deg, symmetric=True)
    reg.ranges["crease angle"] = rng
    _scalar(reg, name, "crease angle", deg, "edges", rng, cmap, enabled=True,
            label="crease angle θ [degrees]")
    return _finish(reg, screenshot, size)


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


# --------------------------------------------------------------------------- rendering
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
    """polyscope's render as a palette PNG (:func:`_save_png`), or as polyscope writes it
    when Pillow is missing."""
    image = np.asarray(ps.screenshot_to_buffer(transparent_bg=False, include_UI=include_UI))
    if not _save_png(path, image):
        ps.screenshot(path, transparent_bg=False, include_UI=include_UI)


PNG_COLOURS = 256
"""Screenshots are written as palette PNGs of at most this many colours (with Pillow)."""


def _save_png(path, image, keep=None):
    """Write an (h, w, 3|4) uint8 image as a palette PNG of at most :data:`PNG_COLOURS`
    colours (several times smaller than full RGB, the picture unchanged to the eye).

    The palette is a median cut of the image plus the colours ``keep`` ((k, 3) uint8,
    e.g. samples of the colour bars' maps, so that a bar stays a smooth ramp); every
    pixel gets its nearest palette colour (no dithering: smooth shading compresses
    well and shows no noise).  Returns False (nothing written) when Pillow is missing.
    """
    try:
        from PIL import Image
    except ImportError:
        return False
    img = Image.fromarray(np.ascontiguousarray(np.asarray(image, dtype=np.uint8)[..., :3]), "RGB")
    keep = np.zeros((0, 3), np.uint8) if keep is None else np.asarray(keep, dtype=np.uint8).reshape(-1, 3)
    keep = np.unique(keep, axis=0)[: PNG_COLOURS // 2]
    cut = img.quantize(colors=PNG_COLOURS - len(keep), method=0)            # 0: median cut
    flat = np.asarray(cut.getpalette() or [], dtype=np.uint8)
    found = flat[: len(flat) // 3 * 3].reshape(-1, 3)
    used = np.unique(np.asarray(cut)).astype(np.int64)
    colours = np.concatenate([found[used[used < len(found)]], keep])
    palette = Image.new("P", (1, 1))
    palette.putpalette(colours.ravel().tolist() + colours[:1].ravel().tolist() * (256 - len(colours)))
    img.quantize(palette=palette, dither=0).save(os.fspath(path), format="PNG", optimize=True)
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
    ramps = [_mpl_cmap(cmap)(np.linspace(0.0, 1.0, 48))[:, :3] for _, _, cmap in bars]
    keep = np.round(255 * np.concatenate(ramps)) if ramps else None
    if not _save_png(path, np.asarray(canvas.buffer_rgba()), keep):
        fig.savefig(path, dpi=dpi, facecolor="white")
    return None


def _frame(ps, bounds, width, height, margin=0.04, top_px=0, left_px=0):
    """Orthographic camera on +z (looking down -z, y up) framing the box ``bounds``:
    its x or y extent, whichever is binding, fills the picture up to ``margin``,
    leaving ``top_px`` pixels free at the top (titles) and ``left_px`` at the
    left (polyscope's panel in the interactive window).

    Orthographic so that copies laid side by side are seen from the same
    direction.  polyscope's own home view frames the bounding-box diagonal,
    which leaves wide pictures mostly empty and crops tall objects.  In
    polyscope's orthographic mode the visible half-height is
    ``2 tan(fov/2) × length_scale`` (measured), so the length scale sets the zoom.

    Returns
    -------
    ((cx, cy), wpp): the world point at the picture's centre and the world
    length of one pixel.
    """
    lo, hi = np.asarray(bounds[0], dtype=np.float64), np.asarray(bounds[1], dtype=np.float64)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    tan_v = np.tan(np.radians(ps.get_vertical_fov_degrees()) / 2.0)
    free_h, free_w = max(height - top_px, 1), max(width - left_px, 1)
    wpp = (1.0 + margin) * 2.0 * max(half[1] / free_h, half[0] / free_w, 1e-9 * diag / height)
    half_height = 0.5 * height * wpp
    scale = half_height / (2.0 * tan_v)
    ps.set_automatically_compute_scene_extents(False)   # hidden structures must not count
    ps.set_bounding_box(lo, hi)
    ps.set_length_scale(scale)
    ps.set_view_projection_mode("orthographic")
    target = centre + np.array([-0.5 * left_px * wpp, 0.5 * top_px * wpp, 0.0])
    # clip planes are multiples of the length scale: keep the camera just in front of the box
    ps.look_at(target + np.array([0.0, 0.0, half[2] + 0.5 * scale]), target)
    return (float(target[0]), float(target[1])), wpp


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
    """The picture :func:`screenshot` would write, as an array instead of a PNG file (in full
    colour: the file is reduced to a palette of at most :data:`PNG_COLOURS` colours).

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
