"""Registering into polyscope: a surface placed and titled, scalar quantities recorded and
added (the shown one last), principal directions as line fields."""
from __future__ import annotations

import numpy as np

from .backend import _REGISTERED, _add_scalar
from .camera import _rotation_for, _union_bounds
from .registration import QuantityInfo
from .render import _render
from .values import LABELS, LONG_LABELS, QUANTITIES, local_edge_length


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


def _finish(reg, screenshot, size):
    _add_scalars(reg)
    if screenshot is not None:
        _render(reg, screenshot, size)
    return reg
