"""Guarded mesh reading: :func:`read_mesh` and :func:`read_mesh_file` (see :mod:`igl_hhj.mesh_io`)."""
from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..capture import CapturedOutput
from ..errors import MeshFileError
from ..polygon_io import EXTRA_EXTENSIONS, PolygonSplit, polygon_split, read_polygon_mesh, split_polygons
from .guards import _check_input_file, _check_keyword_counts, _check_obj, _check_off_header, _check_stl
from .ply import _PLY_SIZES, _check_ply, _parse_ply_header, _ply_scalar
from .scan import _Lines


def _libigl_says(lines):
    if not lines:
        return ""
    first = lines[0] if len(lines[0]) <= 120 else lines[0][:117] + "..."
    return f" (libigl: {first})"


@dataclass
class MeshFile:
    """A mesh file as :func:`read_mesh_file` read it.

    Attributes
    ----------
    V : (#V, 3) float64
    F : (#F, 3) int64, polygons split into triangles (:func:`igl_hhj.polygon_io.split_polygons`:
        the fan from each polygon's first corner, the rule of libigl's OBJ / OFF readers)
    messages : list of str
        What the reader printed (libigl's warnings, at most 20 lines), cells it
        ignored, coincident ``.stl`` / glTF vertices it merged.
    split : PolygonSplit
        The corner counts of the file's faces (``split.describe()``: "12 quads split into
        24 triangles"; empty when the file holds triangles only).
    reader : str
        ``"libigl"`` or the optional package that read the file.
    point_data, cell_data : dict name -> array
        Arrays stored with the mesh (VTK files); ``cell_data`` rows follow ``F`` (a split
        polygon's row repeated for each of its triangles).
    active_scalars : str or None, the array a VTK file marks active (read with pyvista)
    """

    V: NDArray[np.float64]
    F: NDArray[np.int64]
    messages: list = field(default_factory=list)
    split: PolygonSplit = field(default_factory=PolygonSplit)
    reader: str = "libigl"
    point_data: dict = field(default_factory=dict)
    cell_data: dict = field(default_factory=dict)
    active_scalars: str | None = None

    def notes(self) -> list[str]:
        """:attr:`messages` plus the split line when polygons were split."""
        return list(self.messages) + ([self.split.describe()] if self.split.n_split else [])


def read_mesh(path: str | os.PathLike) -> tuple[NDArray[np.float64], NDArray[np.int64], list[str]]:
    """Read a triangle mesh, guarded: libigl's formats with ``igl.read_triangle_mesh``,
    the others through optional packages (:mod:`igl_hhj.polygon_io`).

    Parameters
    ----------
    path : str or os.PathLike
        A file with one of :data:`READ_EXTENSIONS`.

    Returns
    -------
    V : (#V, 3) float64
    F : (#F, k) int64 as libigl returns it (k = 3 for triangle meshes; not
        validated further: use :class:`igl_hhj.mesh.TriangleMesh`); polygons split
        into triangles by one rule for every format (the fan from each polygon's
        first corner, :func:`igl_hhj.polygon_io.split_polygons`).
    messages : list of str
        What libigl printed while reading (warnings; at most 20 lines), a note when
        coincident ``.stl`` / glTF vertices were merged, and one when polygons were
        split ("12 quads split into 24 triangles ...").

    Raises
    ------
    MeshFileError
        Missing / unreadable / empty file, a directory, an unknown extension,
        a header that does not match the file, a read failure, or a file from
        which libigl read no faces.
    ModuleNotFoundError
        A format libigl lacks and none of the packages that read it is installed (the
        message names the install command).

    See Also
    --------
    read_mesh_file : the same with the split counts, the reader and the stored arrays.
    """
    mf = read_mesh_file(path)
    return mf.V, mf.F, mf.notes()


def read_mesh_file(path: str | os.PathLike) -> MeshFile:
    """Read a mesh file like :func:`read_mesh`, keeping what was split and stored.

    Returns
    -------
    MeshFile
    """
    path, ext, head = _check_input_file(path)
    if head.startswith(_BOM) and ext in (".obj", ".off", ".ply"):
        return _read_without_bom(path)
    return _read_checked(path, ext, head)


_BOM = b"\xef\xbb\xbf"


def _read_without_bom(path):
    """A UTF-8 byte-order mark in front of an OBJ / OFF / PLY: libigl would lose the first
    line (OBJ: the first vertex, then a misleading index error) or reject the file, so read
    a copy without the three bytes; messages name the original file."""
    return _read_copy(path, len(_BOM), None, b"")


def _read_copy(path, start, stop, tail, note=None):
    """Read a copy of bytes ``start:stop`` of ``path`` followed by ``tail`` (the guards' repair
    of what libigl cannot read); messages name the original file, ``note`` is added to them."""
    import shutil
    tmpdir = tempfile.mkdtemp(prefix="igl_hhj_copy_")
    copy = Path(tmpdir) / path.name
    try:
        with open(path, "rb") as src, open(copy, "wb") as dst:
            src.seek(start)
            left = None if stop is None else stop - start
            while left is None or left > 0:
                block = src.read(1 << 20 if left is None else min(1 << 20, left))
                if not block:
                    break
                dst.write(block)
                if left is not None:
                    left -= len(block)
            dst.write(tail)
        _, ext, head = _check_input_file(copy)
        try:
            mf = _read_checked(copy, ext, head)
        except MeshFileError as exc:
            raise MeshFileError(str(exc).replace(str(copy), str(path))) from None
        mf.messages = [m.replace(str(copy), str(path)) for m in mf.messages] + ([note] if note else [])
        return mf
    finally:
        shutil.rmtree(tmpdir, ignore_errors=True)


def _read_checked(path, ext, head):
    size = path.stat().st_size
    sizes = None
    if ext in EXTRA_EXTENSIONS:
        return _read_polygons(path, ext)
    if ext == ".off":
        sizes = _check_off_header(path, head, size)
    elif ext == ".ply":
        sizes = _check_ply(path, head, size)
        if sizes is not None:                        # libigl's PLY reader aborts on polygons
            return _read_polygon_ply(path, head, sizes)
    elif ext == ".obj":
        sizes = _check_obj(path)
    elif ext == ".stl":
        trim = _check_stl(path, head, size)
        if trim is not None:                         # a tail libigl would loop on
            return _read_copy(path, 0, trim[0], b"endsolid\n", trim[1])
    elif ext in (".mesh", ".msh"):
        _check_keyword_counts(path, size)
    import igl
    with CapturedOutput() as cap:
        try:
            V, F = igl.read_triangle_mesh(str(path))
            exc = None
        except (RuntimeError, ValueError, MemoryError) as e:
            exc = e
    if exc is not None:
        raise MeshFileError(f"{path}: libigl could not read it: {exc}{_libigl_says(cap.lines)}")
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if F.size == 0:
        raise MeshFileError(f"{path}: libigl read no faces from this {ext} file"
                            f"{_libigl_says(cap.lines)}")
    if V.ndim != 2 or V.shape[1] != 3:
        raise MeshFileError(f"{path}: vertices are not 3D points (shape {V.shape})")
    messages = list(cap.lines)
    if ext == ".stl" and F.ndim == 2 and F.size and F.min() >= 0 and F.max() < len(V):
        V, F, _ = _weld(V, F, messages, "STL")
    split = polygon_split(sizes if sizes is not None and int(np.sum(np.asarray(sizes) - 2)) == len(F)
                          else np.full(len(F), F.shape[1] if F.ndim == 2 else 3))
    return MeshFile(V, F, messages, split)


def _weld(V, F, messages, what):
    """Merge exactly coincident points (STL, glTF store corners per triangle / per seam)."""
    import igl
    V2, _, J = igl.remove_duplicate_vertices(V, 0.0)
    if len(V2) == len(V):
        return V, F, np.arange(len(V))
    messages.append(f"merged coincident {what} vertices: {len(J)} -> {len(V2)}")
    return V2, J[F], J


def _read_polygon_ply(path, head, sizes):
    """A PLY of polygons (checked by ``_check_ply``), read with numpy: the vertex x, y, z
    as stored (float64 exactly; VTK's PLY reader would round them to float32) and the
    faces in file order, split like every other format."""
    fmt, elements, body_start = _parse_ply_header(path, head)
    names = [name for name, _, _ in elements]
    if names[:2] != ["vertex", "face"] or any(t[0] == "list" for _, t in elements[0][2]):
        return _read_polygons(path, ".ply")                  # an unusual layout: VTK's reader
    nV, vprops = elements[0][1], [p for p, _ in elements[0][2]]
    fprops = elements[1][2]
    xyz = [vprops.index(c) for c in "xyz"]
    if fmt == "ascii":
        with open(path, "rb") as fh:
            n_head = fh.read(body_start).count(b"\n")
            body = fh.read()                                     # the rest: the body
        L = _Lines(path, body_start, comments=False, first_line=n_head + 1)
        cut = int(L.offset[nV] - body_start) if len(L) > nV else len(body)
        V = np.fromstring(body[:cut], sep=" ").reshape(nV, len(vprops))[:, xyz]
        end = int(L.offset[nV + len(sizes)] - body_start) if len(L) > nV + len(sizes) else len(body)
        flat = np.fromstring(body[cut:end], sep=" ")
        ntok = L.ntok[nV:nV + len(sizes)]
        lead = next(j for j, (p, t) in enumerate(fprops) if t[0] == "list")   # values before the list
        starts = np.concatenate([[0], np.cumsum(ntok)[:-1]]) + lead + 1
        C = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        I = flat[np.repeat(starts, sizes) + np.arange(C[-1]) - np.repeat(C[:-1], sizes)].astype(np.int64)
    else:
        order = "<" if fmt == "binary_little_endian" else ">"
        kinds = {1: "i1", 2: "i2", 4: "i4", 8: "i8"}
        vdt = np.dtype([(p, _ply_scalar(order, t[0])) for p, t in elements[0][2]])
        vert = np.fromfile(path, dtype=vdt, count=nV, offset=body_start)
        V = np.column_stack([vert[c].astype(np.float64) for c in "xyz"])
        k = int(sizes[0])
        fields = []
        for j, (p, t) in enumerate(fprops):
            if t[0] == "list":
                fields += [("count", order + kinds[_PLY_SIZES[t[1]]]),
                           ("index", order + ("u" if t[2].startswith("u") else "i") + str(_PLY_SIZES[t[2]]), (k,))]
            else:
                fields.append((f"p{j}", f"V{_PLY_SIZES[t[0]]}"))
        face = np.fromfile(path, dtype=np.dtype(fields), count=len(sizes), offset=body_start + nV * vdt.itemsize)
        I = face["index"].astype(np.int64).ravel()
        C = np.arange(0, I.size + 1, k, dtype=np.int64)
    if I.size and (I.min() < 0 or I.max() >= nV):
        raise MeshFileError(f"{path}: a face index is outside 0 .. {nV - 1}")
    F, _, split = split_polygons(I, C)
    return MeshFile(np.ascontiguousarray(V, dtype=np.float64), F, [], split, "igl_hhj (numpy PLY reader)")


def _read_polygons(path, ext):
    """A format libigl lacks (or a polygon PLY) through :mod:`igl_hhj.polygon_io`."""
    pm = read_polygon_mesh(path)
    if pm.C.size < 2:
        raise MeshFileError(f"{path}: no polygons in this {ext} file ({pm.reader})"
                            + (f": {pm.messages[0]}" if pm.messages else ""))
    V = pm.V
    if V.ndim != 2 or V.shape[1] != 3 or not len(V):
        raise MeshFileError(f"{path}: vertices are not 3D points (shape {V.shape})")
    if pm.I.size and (pm.I.min() < 0 or pm.I.max() >= len(V)):
        raise MeshFileError(f"{path}: a face index is outside 0 .. {len(V) - 1}")
    try:
        F, J, split = split_polygons(pm.I, pm.C)
    except ValueError as exc:
        raise MeshFileError(f"{path}: {exc}") from None
    messages = list(pm.messages)
    point_data = dict(pm.point_data)
    if ext in (".gltf", ".glb", ".3mf") and not point_data:
        V, F, _ = _weld(V, F, messages, "glTF" if ext != ".3mf" else "3MF")
    return MeshFile(V, np.ascontiguousarray(F), messages, split, pm.reader, point_data,
                    {k: v[J] for k, v in pm.cell_data.items()}, pm.active_scalars)
