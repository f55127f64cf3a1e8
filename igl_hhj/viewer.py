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

Principal directions are line fields (polyscope tangent-vector quantities
with 2-fold symmetry, ``vectortype="ambient"``) on faces or vertices: a
principal direction has no sign, so it is drawn as a line, not an arrow, and
its length is ``direction_scale`` times the local mean edge length so the
lines stay readable on graded meshes.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from .mesh import as_mesh

__all__ = [
    "ViewerUnavailable", "QuantityInfo", "Registration", "QUANTITIES", "METHODS",
    "init", "show", "color_range", "curvature_estimate", "local_edge_length",
    "register_curvature", "register_comparison", "register_hessian", "register_biharmonic",
    "register_regge_curvature", "register_scalars", "merge", "screenshot",
]

QUANTITIES = ("k1", "k2", "H", "K")
METHODS = ("hhj", "igl", "heine")
LABELS = {"k1": "kappa1", "k2": "kappa2", "H": "mean H", "K": "Gauss K"}
_TAG = {"hhj": "HHJ", "igl": "libigl", "heine": "Heine"}
_EGL_HINT = ("headless rendering needs EGL: on Debian/Ubuntu `apt-get install libegl1 libegl-mesa0 "
             "libgl1-mesa-dri`")
_REGISTERED = {}  # name -> (2, 3) bounds of the structures this module registered (they may since be removed)


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
    """

    values: np.ndarray
    defined_on: str
    kind: str
    vminmax: tuple | None = None
    cmap: str | None = None
    enabled: bool = False


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
    """

    structures: dict = field(default_factory=dict)
    quantities: dict = field(default_factory=dict)
    ranges: dict = field(default_factory=dict)
    screenshot: str | None = None
    bounds: np.ndarray | None = None

    def names(self, structure):
        """Quantity names registered on ``structure``."""
        return [q for s, q in self.quantities if s == structure]

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


def init(backend="auto"):
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


def show():
    """Open polyscope's interactive window on everything registered (needs a display).

    Raises
    ------
    ViewerUnavailable : polyscope runs a backend without a window (mock, EGL)
        or cannot open one.
    """
    ps = init("auto")
    if _backend_name(ps) in ("openGL_mock", "openGL3_egl"):
        raise ViewerUnavailable(f"polyscope is running the windowless {_backend_name(ps)!r} backend; "
                                "use screenshot=... or run with a display")
    ps.show()


# --------------------------------------------------------------------------- values
def color_range(*arrays, symmetric=True, robust=None):
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


def local_edge_length(mesh, location):
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


def curvature_estimate(V, F, *, method="hhj", per="face", **kwargs):
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


# --------------------------------------------------------------------------- registration helpers
def _surface(ps, reg, name, V, F, offset=None):
    """Register a surface mesh under ``name`` (translated by ``offset``), replacing one of the same name."""
    if offset is not None:
        off = np.asarray(offset, dtype=np.float64)
        if off.shape != (3,) or not np.all(np.isfinite(off)):
            raise ValueError(f"offset must be 3 finite numbers, got {offset!r}")
        V = V + off
    if ps.has_surface_mesh(name):
        ps.remove_surface_mesh(name)
    s = ps.register_surface_mesh(name, V, F, color=(0.75, 0.75, 0.75))  # grey: no quantity shown
    reg.structures[name] = s
    box = np.stack([V.min(axis=0), V.max(axis=0)])
    reg.bounds = _union_bounds(reg.bounds, box)
    _REGISTERED[name] = box
    return s


def _union_bounds(*boxes):
    """Bounding box (2, 3) of several (2, 3) boxes (None entries ignored; None if all are)."""
    boxes = [b for b in boxes if b is not None]
    if not boxes:
        return None
    boxes = np.stack(boxes)
    return np.stack([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])


def _scalar(reg, sname, qname, values, defined_on, vminmax, cmap, enabled=False):
    """Record a scalar quantity; :func:`_add_scalars` hands them to polyscope."""
    values = np.asarray(values, dtype=np.float64)
    reg.quantities[(sname, qname)] = QuantityInfo(values, defined_on, "scalar", tuple(float(x) for x in vminmax),
                                                  cmap, bool(enabled))


def _add_scalars(reg):
    """Add the recorded scalar quantities, the enabled one of each structure last.

    polyscope shows one colour quantity per structure and remembers a
    quantity's "enabled" flag by name across re-registration; adding the
    wanted one last makes it win regardless of what an earlier picture showed.
    """
    items = sorted(((k, q) for k, q in reg.quantities.items() if q.kind == "scalar"),
                   key=lambda kq: kq[1].enabled)
    for (sname, qname), q in items:
        reg.structures[sname].add_scalar_quantity(
            qname, np.nan_to_num(q.values, nan=0.0, posinf=0.0, neginf=0.0), defined_on=q.defined_on,
            vminmax=q.vminmax, cmap=q.cmap, enabled=q.enabled)


def _line_field(reg, sname, qname, vectors, normals, defined_on, enabled=False):
    """A principal-direction field drawn as tangent *lines* (polyscope tangent
    vectors with 2-fold symmetry): ``vectors`` (n, 3) tangent to ``normals``
    (n, 3), their length is the drawn length."""
    vectors = np.asarray(vectors, dtype=np.float64)
    vectors = np.where(np.isfinite(vectors), vectors, 0.0)
    length = np.linalg.norm(vectors, axis=1)
    bx = np.zeros_like(vectors)
    np.divide(vectors, length[:, None], out=bx, where=length[:, None] > 0)
    bx[length == 0] = (1.0, 0.0, 0.0)
    by = np.cross(np.asarray(normals, dtype=np.float64), bx)     # tangent frame (bx, by)
    values = np.stack([length, np.zeros_like(length)], axis=1)
    reg.structures[sname].add_tangent_vector_quantity(qname, values, bx, by, n_sym=2, defined_on=defined_on,
                                                      vectortype="ambient", enabled=bool(enabled))
    reg.quantities[(sname, qname)] = QuantityInfo(vectors, defined_on, "line", None, None, bool(enabled))


def _add_estimate(reg, sname, mesh, est, tag, ranges, cmap, directions, direction_scale, enabled=None,
                  show_directions=False):
    """Scalar (k1, k2, H, K) and direction quantities of one CurvatureEstimate."""
    where = "faces" if est.location == "face" else "vertices"
    for q in QUANTITIES:
        _scalar(reg, sname, f"{LABELS[q]} ({tag} {where})", getattr(est, q), where, ranges[q], cmap,
                enabled=(q == enabled))
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
def register_curvature(V, F, estimate=None, *, method="hhj", per="both", name="mesh", enabled="H",
                       directions=True, show_directions=False, symmetric=True, robust=None, cmap="coolwarm", ranges=None,
                       direction_scale=0.5, offset=None, screenshot=None, size=(1024, 768), **estimator_kwargs):
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
        values of one quantity.
    cmap : polyscope colour map name (diverging by default).
    ranges : dict, optional, explicit ``{quantity: (lo, hi)}`` overriding the
        computed ranges (e.g. to match another picture).
    direction_scale : float, direction length in units of the local mean edge length.
    offset : (3,), optional translation of the structure (to lay out several pictures).
    screenshot : path, optional: render headless to this PNG (see :func:`screenshot`).
    size : (width, height) of the screenshot in pixels.
    **estimator_kwargs : passed to the estimator (boundary data, ``radius``...).

    Returns
    -------
    Registration (``ranges`` has keys "k1", "k2", "H", "K").
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
    _surface(ps, reg, name, mesh.V, mesh.F, offset)
    for i, (est, tag) in enumerate(zip(ests, tags)):
        _add_estimate(reg, name, mesh, est, tag, reg.ranges, cmap, directions, direction_scale,
                      enabled=enabled if i == 0 else None, show_directions=show_directions and i == 0)
    return _finish(reg, screenshot, size)


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


def register_comparison(V, F, *, hhj=None, libigl=None, per="face", layout="copy", name="mesh", enabled="H",
                        directions=True, show_directions=False, symmetric=True, robust=None, cmap="coolwarm", offset=None,
                        direction_scale=0.5, radius=5, screenshot=None, size=(1600, 800)):
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
    other parameters : as :func:`register_curvature`.

    Returns
    -------
    Registration; ``ranges[q]`` is the one range used by both estimators.
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
    if layout == "copy":
        if offset is None:
            ext = mesh.V.max(axis=0) - mesh.V.min(axis=0)
            offset = np.array([1.15 * ext[0], 0.0, 0.0])
        sh, si = f"{name} HHJ", f"{name} libigl"
        _surface(ps, reg, sh, mesh.V, mesh.F)
        _surface(ps, reg, si, mesh.V, mesh.F, np.asarray(offset, dtype=np.float64).reshape(3))
    else:
        sh = si = name
        _surface(ps, reg, name, mesh.V, mesh.F)
    _add_estimate(reg, sh, mesh, hhj, "HHJ", reg.ranges, cmap, directions, direction_scale, enabled=enabled,
                  show_directions=show_directions)
    _add_estimate(reg, si, mesh, libigl, "libigl", reg.ranges, cmap, directions, direction_scale,
                  enabled=enabled if layout == "copy" else None, show_directions=show_directions and layout == "copy")
    return _finish(reg, screenshot, size)


# --------------------------------------------------------------------------- other fields
def register_hessian(V, F, w, *, boundary_gradient=None, name="mesh", label="w", enabled="trace",
                     directions=True, symmetric=True, robust=None, cmap="coolwarm", direction_scale=0.5,
                     offset=None, screenshot=None, size=(1024, 768)):
    """Register a P1 function ``w`` and its HHJ surface Hessian (Walker eq. 4.9).

    Parameters
    ----------
    w : (#V,) array_like or callable ``w(V: (#V, 3)) -> (#V,)``
    boundary_gradient : optional clamped data, see :func:`igl_hhj.surface_hessian`.
    label : str, name of the function in the quantity names.
    enabled : {"w", "lambda1", "lambda2", "trace", "norm"}, quantity shown first.
    offset : (3,), optional translation of the structure.

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
    _surface(ps, reg, name, mesh.V, mesh.F, offset)
    names = {"w": label, "lambda1": f"Hess {label} lambda1", "lambda2": f"Hess {label} lambda2",
             "trace": f"Hess {label} trace (surface Laplacian)", "norm": f"|Hess {label}|"}
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
                        robust=None, ranges=None, offset=None, screenshot=None, size=(1024, 768)):
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
    _surface(ps, reg, name, mesh.V, mesh.F, offset)
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
                    enabled=(k == enabled))
    return _finish(reg, screenshot, size)


def register_regge_curvature(V, F, *, boundary="natural", mass="consistent", compare=True, name="mesh",
                             enabled="K_h", symmetric=True, robust=None, cmap="coolwarm", vminmax=None,
                             offset=None, screenshot=None, size=(1024, 768)):
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
    _surface(ps, reg, name, mesh.V, mesh.F, offset)
    for key, (qname, vals, where) in fields.items():
        _scalar(reg, name, qname, vals, where, reg.ranges["K"], cmap, enabled=(key == enabled))
    return _finish(reg, screenshot, size)


def register_scalars(V, F, fields, *, name="mesh", enabled=None, shared_range=False, symmetric=True, robust=None,
                     cmap="coolwarm", vminmax=None, offset=None, screenshot=None, size=(1024, 768)):
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
    _surface(ps, reg, name, mesh.V, mesh.F, offset)
    for k, x in vals.items():
        reg.ranges[k] = common or color_range(x, symmetric=symmetric, robust=robust)
        _scalar(reg, name, k, x, where[k], reg.ranges[k], cmap, enabled=(k == enabled))
    return _finish(reg, screenshot, size)


def merge(*registrations):
    """One :class:`Registration` holding several (e.g. to screenshot them together)."""
    out = Registration()
    for r in registrations:
        out.structures.update(r.structures)
        out.quantities.update(r.quantities)
        out.ranges.update(r.ranges)
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
    try:
        w, h = (int(x) for x in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be (width, height) in pixels, got {size!r}") from None
    if w < 16 or h < 16:
        raise ValueError(f"screenshot size must be at least 16 x 16 pixels, got {size!r}")
    return path


def _render(reg, path, size):
    """Write a PNG of the structures of ``reg`` (others hidden during the shot)."""
    path = _check_screenshot(path, size)
    w, h = (int(x) for x in size)
    import polyscope as ps
    if not ps.is_initialized() or _backend_name(ps) == "openGL_mock":
        raise ViewerUnavailable("polyscope's mock backend draws nothing; register with screenshot=... "
                                "(which starts the EGL backend) or call viewer.init('openGL3_egl') first")
    ps.set_window_size(w, h)
    ps.set_ground_plane_mode("none")
    projection = ps.get_view_projection_mode()
    # look structures up by name: a Python handle of a removed structure must never be touched
    missing = [n for n in reg.structures if not ps.has_surface_mesh(n)]
    if missing:
        raise ValueError(f"cannot render: structure(s) {missing} are no longer registered in polyscope")
    others = (ps.get_surface_mesh(n) for n in sorted(set(_REGISTERED) - set(reg.structures))
              if ps.has_surface_mesh(n))
    hidden = [s for s in others if s.is_enabled()]
    for s in hidden:
        s.set_enabled(False)
    for n in reg.structures:
        ps.get_surface_mesh(n).set_enabled(True)
    try:
        if reg.bounds is not None:
            _frame(ps, reg.bounds, w, h)
        else:
            ps.reset_camera_to_home_view()
        ps.screenshot(path, transparent_bg=False)
    finally:
        for s in hidden:
            s.set_enabled(True)
        ps.set_automatically_compute_scene_extents(True)
        ps.set_view_projection_mode(projection)
    reg.screenshot = path
    return path


def _frame(ps, bounds, width, height, margin=0.04):
    """Orthographic camera on +z (looking down -z, y up) framing the box ``bounds``:
    its x or y extent, whichever is binding, fills the picture up to ``margin``.

    Orthographic so that copies laid side by side are seen from the same
    direction.  polyscope's own home view frames the bounding-box diagonal,
    which leaves wide pictures mostly empty and crops tall objects.  In
    polyscope's orthographic mode the visible half-height is
    ``2 tan(fov/2) × length_scale`` (measured), so the length scale sets the zoom.
    """
    lo, hi = np.asarray(bounds[0], dtype=np.float64), np.asarray(bounds[1], dtype=np.float64)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    tan_v = np.tan(np.radians(ps.get_vertical_fov_degrees()) / 2.0)
    half_height = (1.0 + margin) * max(half[1], half[0] * height / width, 1e-9 * diag)
    scale = half_height / (2.0 * tan_v)
    ps.set_automatically_compute_scene_extents(False)   # hidden structures must not count
    ps.set_bounding_box(lo, hi)
    ps.set_length_scale(scale)
    ps.set_view_projection_mode("orthographic")
    # clip planes are multiples of the length scale: keep the camera just in front of the box
    ps.look_at(centre + np.array([0.0, 0.0, half[2] + 0.5 * scale]), centre)


def screenshot(path, registration=None, *, size=(1024, 768)):
    """Render headless (EGL, unless an interactive backend is running) and save a PNG.

    Parameters
    ----------
    path : str or path-like, the PNG to write (its directory must exist).
    registration : Registration or list of them, optional: only their
        structures are drawn (everything registered through this module
        otherwise).
    size : (width, height) in pixels.

    Returns
    -------
    str, the path written.

    Raises
    ------
    ViewerUnavailable : no backend can render (e.g. EGL libraries missing).
    ValueError : unwritable path or bad size.
    """
    if registration is None:
        import polyscope as ps
        names = [n for n in _REGISTERED if ps.has_surface_mesh(n)]
        registration = Registration(structures={n: None for n in names},
                                    bounds=_union_bounds(*(_REGISTERED[n] for n in names)))
    elif isinstance(registration, (list, tuple)):
        registration = merge(*registration)
    return _render(registration, path, size)
