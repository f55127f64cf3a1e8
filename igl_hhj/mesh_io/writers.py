"""Curvature output files: :func:`write_curvature` (``.npz``, ``.csv``, ``.ply``, ``.vtp``,
``.vtu``, ``.vtk``, ``.obj``) and the checks of an output path before any computation."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshFileError
from ..results import QUANTITIES
from .extensions import OUTPUT_EXTENSIONS, VTK_EXTENSIONS


CURVATURE_COLUMNS = ("k1", "k2", "H", "K", "d1x", "d1y", "d1z", "d2x", "d2y", "d2z")
"""Per-element columns of the ``.csv`` and ``.ply`` outputs (after ``index`` in the csv)."""


def check_output_path(path: str | os.PathLike) -> str:
    """Check before any computation that ``path`` has a known extension and can be written.

    Opens the file for appending (so an existing file is not truncated) and
    removes it again if it did not exist.  Returns the extension (lower case).
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in OUTPUT_EXTENSIONS:
        raise MeshFileError(f"{path}: unknown output extension {path.suffix!r} "
                            f"(use {', '.join(OUTPUT_EXTENSIONS)})")
    probe_writable(path)
    return ext


def probe_writable(path):
    """Raise :class:`MeshFileError` unless ``path`` can be opened for writing.

    Opens it for appending (an existing file is not truncated) and removes it
    again if it did not exist, so nothing is left behind if a later step fails.
    """
    path = Path(path)
    if path.is_dir():
        raise MeshFileError(f"{path}: is a directory")
    existed = path.exists()
    try:
        with open(path, "ab"):
            pass
    except OSError as exc:
        raise MeshFileError(f"{path}: cannot write: {exc.strerror or exc}") from None
    if not existed:
        path.unlink()


def _columns(est):
    """(n, 10) float64: k1, k2, H, K, d1, d2 (NaN directions if the method has none)."""
    n = len(est.k1)
    d1 = est.d1 if est.d1 is not None else np.full((n, 3), np.nan)
    d2 = est.d2 if est.d2 is not None else np.full((n, 3), np.nan)
    return np.column_stack([est.k1, est.k2, est.H, est.K, d1, d2])


def _ply_header(V, F, est, quantity, fmt):
    # double like the rest: libigl 2.6's PLY reader aborts when one element's properties differ in type
    extra = "".join(f"property double {c}\n" for c in CURVATURE_COLUMNS + ("quality",))
    per_vertex = est.location == "vertex"
    return ("ply\n"
            f"format {fmt} 1.0\n"
            f"comment igl_hhj curvature, method {est.name}, per {est.location}; quality = {quantity}\n"
            f"element vertex {len(V)}\nproperty double x\nproperty double y\nproperty double z\n"
            + (extra if per_vertex else "")
            + f"element face {len(F)}\nproperty list uchar int vertex_indices\n"
            + ("" if per_vertex else extra) + "end_header\n")


def _write_ply(path, V, F, est, quantity="H"):
    """Binary little-endian PLY, the values as vertex or face properties plus ``quality``.

    Binary also per face: libigl 2.6's ascii PLY reader aborts the process on face
    properties (and meshio 5.3's binary reader cannot read them; use .vtu there)."""
    cols = [(c, "<f8") for c in CURVATURE_COLUMNS + ("quality",)]
    per_vertex = est.location == "vertex"
    vert = np.empty(len(V), dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8")] + (cols if per_vertex else []))
    face = np.empty(len(F), dtype=[("n", "u1"), ("vertex_indices", "<i4", (3,))] + ([] if per_vertex else cols))
    vert["x"], vert["y"], vert["z"] = V.T
    face["n"] = 3
    face["vertex_indices"] = F
    target = vert if per_vertex else face
    data = _columns(est)
    for j, c in enumerate(CURVATURE_COLUMNS):
        target[c] = data[:, j]
    target["quality"] = getattr(est, quantity)
    with open(path, "wb") as fh:
        fh.write(_ply_header(V, F, est, quantity, "binary_little_endian").encode("ascii"))
        fh.write(vert.tobytes())
        fh.write(face.tobytes())


def _fields(est):
    """{name: (n,) or (n, 3) array}: k1, k2, H, K and the directions d1, d2 when present."""
    out = {q: np.asarray(getattr(est, q), dtype=np.float64) for q in QUANTITIES}
    if est.d1 is not None:
        out.update(d1=np.asarray(est.d1, dtype=np.float64), d2=np.asarray(est.d2, dtype=np.float64))
    return out


def _write_vtk(path, V, F, est, S=None, quantity="H"):
    """``.vtp`` / ``.vtu`` / ``.vtk``: the fields as point or cell data, ``quantity`` the
    active scalars, the shape operator ``S`` (when given) as a 9-component cell tensor."""
    from ..vtk_files import write_vtk
    fields = _fields(est)
    fields = {quantity: fields.pop(quantity), **fields}          # the active scalars first
    per_vertex = est.location == "vertex"
    cells = {} if per_vertex else dict(fields)
    if S is not None:
        cells["S"] = np.asarray(S, dtype=np.float64)
    write_vtk(path, V, F, point_data=fields if per_vertex else None, cell_data=cells, scalars=quantity,
              title=f"igl_hhj curvature, method {est.name}, per {est.location}")


_DIVERGING = np.array([[0.230, 0.299, 0.754], [0.865, 0.865, 0.865], [0.706, 0.016, 0.150]])
"""Blue, grey-white, red: the end and middle points of the coolwarm colour map."""


def quantity_colours(values: Any, robust: float = 1.0) -> np.ndarray:
    """(n, 3) float RGB in [0, 1]: a diverging map symmetric about 0 (blue < 0 < red),
    the range being the largest magnitude of the ``[robust, 100 - robust]``
    percentiles; NaN values are grey."""
    x = np.asarray(values, dtype=np.float64)
    fin = x[np.isfinite(x)]
    m = float(np.max(np.abs(np.percentile(fin, [robust, 100 - robust])))) if fin.size else 1.0
    t = np.clip(np.nan_to_num(x, nan=0.0) / (m if m > 0 else 1.0), -1.0, 1.0)
    lo, mid, hi = _DIVERGING
    w = np.abs(t)[:, None]
    rgb = np.where((t < 0)[:, None], mid + w * (lo - mid), mid + w * (hi - mid))
    rgb[~np.isfinite(x)] = 0.5
    return rgb


def _write_obj(path, V, F, est, quantity="H"):
    """Wavefront OBJ with ``v x y z r g b`` lines (the colour extension MeshLab,
    trimesh, Blender read); per-face values are area-averaged to the vertices."""
    import igl
    values = np.asarray(getattr(est, quantity), dtype=np.float64)
    if est.location == "face":
        area = 0.5 * np.asarray(igl.doublearea(V, F)).ravel()
        w = np.where(np.isfinite(values), area, 0.0)
        num = np.bincount(F.ravel(), weights=np.repeat(np.nan_to_num(values) * w, 3), minlength=len(V))
        den = np.bincount(F.ravel(), weights=np.repeat(w, 3), minlength=len(V))
        values = np.full(len(V), np.nan)
        np.divide(num, den, out=values, where=den > 0)
    with open(path, "w") as fh:
        fh.write(f"# igl_hhj curvature, method {est.name}, per {est.location}; vertex colours: {quantity} "
                 f"(coolwarm, symmetric about 0)\n")
        np.savetxt(fh, np.column_stack([V, quantity_colours(values)]), fmt="v %.17g %.17g %.17g %.4f %.4f %.4f")
        np.savetxt(fh, F + 1, fmt="f %d %d %d")


def write_curvature(path: str | os.PathLike, V: np.ndarray, F: np.ndarray, est: Any, *, method: str,
                    S: np.ndarray | None = None, quantity: str = "H") -> None:
    """Write curvatures per face or per vertex to ``.npz``, ``.csv``, ``.ply``, ``.vtp``, ``.vtu``, ``.vtk``
    or ``.obj``.

    Parameters
    ----------
    path : str or os.PathLike, extension one of :data:`OUTPUT_EXTENSIONS`
    V : (#V, 3) float64, F : (#F, 3) int64
    est : igl_hhj.baselines.CurvatureEstimate
        ``est.location`` ("vertex" or "face") says which element the rows are.
    method : str
        The method name stored in the file (``hhj``, ``igl``, ``heine``).
    S : (#F, 3, 3) float64, optional
        The HHJ shape operator, stored in the ``.npz`` and (9-component cell
        tensor ``S``) in the VTK files.
    quantity : {"k1", "k2", "H", "K"}
        What the ``.ply`` ``quality`` property and the ``.obj`` colours hold, and
        the active scalars of the VTK files (what ParaView and pyvista show).

    Files
    -----
    ``.npz``: arrays ``k1, k2, H, K (n,)``, ``d1, d2 (n, 3)``, ``V``, ``F``,
    ``per`` and ``method`` (0-d strings), ``S`` when given.
    ``.csv``: header ``index,k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z``, one row per
    element, full float64 precision.
    ``.ply``: ``vertex`` x, y, z and ``face`` vertex_indices (uchar count, int
    indices); the columns of the csv as ``double`` properties of the vertices
    or of the faces, and ``quantity`` again as ``double quality`` (what MeshLab
    colours by); binary little-endian.  Read by libigl, pymeshlab/MeshLab,
    trimesh; meshio 5.3 reads the per-vertex file but not binary face
    properties (write ``.vtu`` for meshio/pyvista per face).
    ``.vtp`` (VTK XML PolyData: pyvista, ParaView), ``.vtu`` (XML
    UnstructuredGrid: ParaView, pyvista, meshio), ``.vtk`` (legacy binary):
    k1, k2, H, K and the vectors d1, d2 as point data (per vertex) or cell data
    (per face), ``quantity`` the active scalars, d1 the active vectors
    (:func:`igl_hhj.vtk_files.write_vtk`).
    ``.obj``: vertices coloured by ``quantity`` (``v x y z r g b``, a
    diverging map symmetric about 0 over the 1st-99th percentile magnitude;
    per-face values area-averaged to the vertices): a quick look, no values.

    Examples
    --------
    >>> from igl_hhj import baselines, mesh_io                  # doctest: +SKIP
    >>> est = baselines.hhj_vertex(V, F)                         # doctest: +SKIP
    >>> mesh_io.write_curvature("bunny_H.ply", V, F, est, method="hhj")   # doctest: +SKIP
    """
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {QUANTITIES}, got {quantity!r}")
    ext = Path(path).suffix.lower()
    if ext == ".npz":
        arrays = dict(k1=est.k1, k2=est.k2, H=est.H, K=est.K, V=V, F=F,
                      per=np.array(est.location), method=np.array(method))
        if est.d1 is not None:
            arrays.update(d1=est.d1, d2=est.d2)
        if S is not None:
            arrays["S"] = S
        np.savez(path, **arrays)
    elif ext == ".csv":
        data = _columns(est)
        table = np.column_stack([np.arange(len(data)), data])
        np.savetxt(path, table, delimiter=",", fmt=["%d"] + ["%.17g"] * data.shape[1],
                   header=",".join(("index",) + CURVATURE_COLUMNS), comments="")
    elif ext == ".ply":
        _write_ply(path, V, F, est, quantity)
    elif ext in VTK_EXTENSIONS:
        _write_vtk(path, V, F, est, S, quantity)
    elif ext == ".obj":
        _write_obj(path, V, F, est, quantity)
    else:
        raise MeshFileError(f"{path}: unknown output extension (use {', '.join(OUTPUT_EXTENSIONS)})")
