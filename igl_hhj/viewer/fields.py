"""Other fields in the viewer: a surface Hessian, a biharmonic solution, the Regge Gauss
curvature, arbitrary scalars, and the crease network of sharp features."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..mesh import as_mesh
from .backend import _polyscope_for
from .registration import Registration
from .render import _check_screenshot
from .structures import _finish, _line_field, _placed, _record_bounds, _scalar, _surface, _title
from .values import LONG_LABELS, _check, _explicit_range, color_range, local_edge_length


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
    from ..curvature import principal_from_shape_operator, surface_hessian
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

    from ..regge import gauss_curvature
    _check(enabled, "enabled", ("K_h", "angle_defect", "hhj") if compare else ("K_h",))
    mesh = as_mesh(V, F)
    _check_screenshot(screenshot, size)
    Kh = gauss_curvature(mesh.V, mesh.F, boundary=boundary, mass=mass)
    fields = {"K_h": ("Regge K_h (vertices)", Kh, "vertices")}
    if compare:
        from ..curvature import face_gaussian_curvature
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
    from ..features import crease_edges, crease_network
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
