"""Curvature results read back: :func:`read_curvature` (``igl-hhj view``)."""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import MeshFileError
from ..results import QUANTITIES, CurvatureEstimate
from .extensions import RESULT_EXTENSIONS, VTK_EXTENSIONS
from .guards import _HEADER_BYTES, _check_input_file_any
from .ply import _parse_ply_header, _ply_head, _ply_scalar
from .readers import read_mesh_file


_METHOD_NAMES = {"hhj": "hhj", "igl": "libigl_quadric", "heine": "heine"}


@dataclass
class CurvatureFile:
    """A curvature result read back by :func:`read_curvature`.

    Attributes
    ----------
    V : (#V, 3) float64, F : (#F, 3) int64
    estimate : igl_hhj.baselines.CurvatureEstimate
        k1, k2, H, K (and d1, d2 when stored) per ``estimate.location``.
    method : str, the method stored in the file ("" when the file does not say)
    quantity : str, what the file was written to show (PLY ``quality``, the VTK active
        scalars; "H" when it does not say)
    S : (#F, 3, 3) float64 or None, the HHJ shape operator when stored (``.npz``, VTK
        cell tensor ``S``)
    fields : dict name -> array, every numeric per-element array of the file
    """

    V: NDArray[np.float64]
    F: NDArray[np.int64]
    estimate: CurvatureEstimate
    method: str = ""
    quantity: str = "H"
    S: np.ndarray | None = None
    fields: dict = field(default_factory=dict)


def _ply_values(path):
    """{"vertex": {name: (nV,)}, "face": {name: (nF,)}}: the scalar properties of a PLY of
    triangles (binary or ascii, checked by ``_check_ply``), and its comment lines."""
    head = open(path, "rb").read(_HEADER_BYTES)
    fmt, elements, body_start = _parse_ply_header(path, head)
    comments = [ln[8:].decode("ascii", "replace") for ln in _ply_head(path, head).split(b"\n")
                if ln.startswith(b"comment ")]
    order = {"ascii": "<", "binary_little_endian": "<", "binary_big_endian": ">"}[fmt]

    def scalar(t):
        return _ply_scalar(order, t)

    dtypes = []
    for name, n, props in elements:
        fields = []
        for p, t in props:
            if t[0] == "list":
                if name != "face":
                    return {}, comments                    # lists we cannot lay out
                fields += [("_count", scalar(t[1])), ("_index", scalar(t[2]), (3,))]
            else:
                fields.append((p, scalar(t[0])))
        dtypes.append((name, n, np.dtype(fields)))
    out = {}
    if fmt == "ascii":
        flat = np.fromstring(open(path, "rb").read()[body_start:], sep=" ")
        start = 0
        for name, n, dt in dtypes:
            width = sum(int(np.prod(dt[k].shape)) if dt[k].shape else 1 for k in dt.names)
            rows = flat[start:start + n * width].reshape(n, width)
            start += n * width
            cols, j = {}, 0
            for k in dt.names:
                w = int(np.prod(dt[k].shape)) if dt[k].shape else 1
                if not k.startswith("_"):
                    cols[k] = rows[:, j]
                j += w
            out[name] = cols
    else:
        offset = body_start
        for name, n, dt in dtypes:
            rec = np.fromfile(path, dtype=dt, count=n, offset=offset)
            offset += n * dt.itemsize
            out[name] = {k: rec[k].astype(np.float64) for k in dt.names if not k.startswith("_")}
    return out, comments


def _npz_arrays(p):
    """Every array of an ``.npz`` archive; a damaged one (truncated, empty, not a zip, an
    entry that is not an array) is a :class:`MeshFileError` saying so."""
    import zipfile
    import zlib
    try:
        with np.load(p, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error,
            NotImplementedError, UnicodeError) as exc:
        text = " ".join(str(exc).split())[:150]
        raise MeshFileError(f"{p}: not a readable .npz archive (truncated, empty or damaged: "
                            f"{type(exc).__name__}{': ' + text if text else ''})") from None


def _read_own_vtk(p):
    """The arrays of a VTK file as :func:`igl_hhj.vtk_files.write_vtk` writes them (numpy only,
    so the plain install re-opens its own outputs); None for another layout."""
    from ..vtk_files import NotWrittenHere, read_vtk
    _check_input_file_any(p)
    try:
        return read_vtk(p)
    except NotWrittenHere:
        return None
    except (ValueError, OSError, EOFError) as exc:
        raise MeshFileError(f"{p}: damaged VTK file: {' '.join(str(exc).split())[:200]}") from None


def _real(p, name, a):
    """``a`` as float64 if it holds real numbers, else a MeshFileError naming it."""
    a = np.asarray(a)
    if a.dtype.kind not in "fiub":
        raise MeshFileError(f"{p}: " * bool(p) + f"array {name} holds {a.dtype} values, not real numbers")
    return a.astype(np.float64)


def _checked_mesh(p, V, F):
    """V (#V, 3) real and finite, F (#F, 3) integer indices into V: else a MeshFileError."""
    V, F = np.asarray(V), np.asarray(F)
    V = _real(p, "V", V)
    if V.ndim != 2 or V.shape[1] != 3 or not len(V):
        raise MeshFileError(f"{p}: V must be (#V, 3) points, it has shape {V.shape}")
    if not np.isfinite(V).all():
        raise MeshFileError(f"{p}: V holds {int((~np.isfinite(V)).any(axis=1).sum())} points that are not finite")
    if F.dtype.kind not in "iu" and not (F.dtype.kind == "f" and np.isfinite(F).all()
                                         and (F == np.round(F)).all()):
        raise MeshFileError(f"{p}: F must hold integer vertex indices, it holds {F.dtype} values")
    if F.ndim != 2 or F.shape[1] != 3 or not len(F):
        raise MeshFileError(f"{p}: F must be (#F, 3) triangles, it has shape {F.shape}")
    if F.min() < 0 or F.max() >= len(V):
        raise MeshFileError(f"{p}: F refers to vertex {int(F.min()) if F.min() < 0 else int(F.max())}, "
                            f"the file has vertices 0 .. {len(V) - 1}")
    return V, F.astype(np.int64)


def _estimate_from(fields, location, method):
    have = [q for q in QUANTITIES if q in fields]
    if len(have) < len(QUANTITIES):
        raise MeshFileError(f"no curvature arrays {', '.join(q for q in QUANTITIES if q not in have)} per "
                            f"{location} (it holds: {', '.join(sorted(fields)) or 'nothing'}); "
                            f"write one with 'igl-hhj curvature MESH -o OUT'")
    vals = {q: _real("", q, fields[q]).reshape(-1) for q in QUANTITIES}
    if all(f"{k}{c}" in fields for k in ("d1", "d2") for c in "xyz"):          # PLY columns d1x ...
        d = [np.column_stack([fields[f"{k}{c}"] for c in "xyz"]) for k in ("d1", "d2")]
    else:
        d = [np.asarray(fields[k], dtype=np.float64).reshape(-1, 3) if k in fields else None
             for k in ("d1", "d2")]
    if d[0] is not None and np.isnan(d[0]).all():                          # written without directions
        d = [None, None]
    name = _METHOD_NAMES.get(method, method) or "stored"       # the VTK files do not say
    if name == "hhj":
        name = f"hhj_{location}"
    return CurvatureEstimate(location, vals["k1"], vals["k2"], vals["H"], vals["K"], d[0], d[1],
                             np.flatnonzero(np.isnan(vals["k1"])), name)


def read_curvature(path: str | os.PathLike) -> CurvatureFile:
    """Read back a curvature result written by :func:`write_curvature` (``igl-hhj curvature -o``).

    Parameters
    ----------
    path : str or os.PathLike, extension one of :data:`RESULT_EXTENSIONS`
        ``.npz``; ``.ply`` (the named vertex or face properties, read with numpy);
        ``.vtp`` / ``.vtu`` / ``.vtk`` (point or cell data, through
        :func:`read_mesh_file`: pyvista, or meshio for ``.vtu`` / ``.vtk``).

    Returns
    -------
    CurvatureFile

    Raises
    ------
    MeshFileError
        Not such a file, or one without the arrays k1, k2, H, K per vertex or per face.
    """
    p = Path(path)
    ext = p.suffix.lower()
    if ext not in RESULT_EXTENSIONS:
        raise MeshFileError(f"{p}: cannot re-open a {p.suffix or 'extension-less'} file: results with "
                            f"their mesh are {', '.join(RESULT_EXTENSIONS)}"
                            + (" (a .csv holds no mesh)" if ext == ".csv" else
                               " (an .obj holds colours, no values)" if ext == ".obj" else ""))
    method, quantity, S = "", "H", None
    try:
        if ext == ".npz":
            _check_input_file_any(p)
            fields = _npz_arrays(p)
            V, F = fields.pop("V", None), fields.pop("F", None)
            if V is None or F is None:
                raise MeshFileError(f"{p}: no arrays V and F (it holds: {', '.join(sorted(fields))})")
            location = str(fields.pop("per", "vertex"))
            if location not in ("vertex", "face"):
                raise MeshFileError(f"{p}: per = {location[:30]!r}, expected 'vertex' or 'face'")
            method = str(fields.pop("method", ""))
            S = fields.pop("S", None)
        elif ext in VTK_EXTENSIONS and (ours := _read_own_vtk(p)) is not None:
            V, F, ((pdata, pscalars), (cdata, cscalars)) = ours
            quantity = pscalars or cscalars or "H"
            S = cdata.get("S")
            location = "vertex" if "H" in pdata else "face"
            fields = pdata if location == "vertex" else cdata
        else:
            mf = read_mesh_file(p)
            V, F = mf.V, mf.F
            if ext == ".ply":
                values, comments = _ply_values(p)
                pdata = {k: v for k, v in values.get("vertex", {}).items() if k not in ("x", "y", "z")}
                cdata = values.get("face", {})
                for c in comments:
                    m = re.search(r"method (\S+), per (vertex|face); quality = (\w+)", c)
                    if m:
                        method, quantity = m.group(1), m.group(3)
            else:
                pdata, cdata = mf.point_data, mf.cell_data
                quantity = mf.active_scalars or "H"
                S = cdata.get("S")
            location = "vertex" if "H" in pdata else "face"
            fields = pdata if location == "vertex" else cdata
        est = _estimate_from(fields, location, method)
    except MeshFileError as exc:
        msg = str(exc)
        raise MeshFileError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None
    V, F = _checked_mesh(p, V, F)
    n = len(V) if est.location == "vertex" else len(F)
    if len(est.k1) != n:
        raise MeshFileError(f"{p}: {len(est.k1)} values per {est.location}, the mesh has {n} {est.location}s")
    if S is not None:
        S = _real(p, "S", S)
        if S.size != 9 * len(F):
            raise MeshFileError(f"{p}: the shape operator S has {S.size} values, 9 per face need {9 * len(F)}")
        S = S.reshape(-1, 3, 3)
    if method.startswith("hhj"):
        method = "hhj"
    elif method.startswith("libigl"):
        method = "igl"
    return CurvatureFile(V, F, est, method, quantity if quantity in QUANTITIES else "H", S, dict(fields))
