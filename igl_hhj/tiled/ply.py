"""Streaming mesh files: binary PLY memory-mapped where its records lie, ascii PLY and
OFF converted in one pass, a binary PLY writer that takes the mesh in chunks.

What each format allows (out of core):

* **binary PLY** whose elements before the faces have fixed-size records and whose
  faces all have the same corner count k (the file size says so; every count is
  checked): the vertex and face records are read through ``np.memmap`` in place, with
  no copy; k-gons are split into the fan from their first corner on the fly (the rule
  of :func:`igl_hhj.polygon_io.split_polygons`).  Other properties (normals, colours)
  are skipped by the record layout.
* **ascii PLY, OFF** with one corner count: one streaming pass converts them to
  ``.npy`` files (memory: one block of lines).
* anything else (binary PLY of mixed polygons, OBJ, STL, glTF, ...): read whole by
  :func:`igl_hhj.mesh_io.read_mesh` and written to ``.npy`` (the mesh must fit in memory
  once; OBJ interleaves vertex, normal, texture and face lines, STL repeats every
  vertex per face and must be welded globally).
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["PlyLayout", "ply_layout", "convert_text_mesh", "write_binary_ply", "BLOCK_LINES"]

BLOCK_LINES = 1 << 20
"""Lines per block of the text conversion."""


@dataclass(frozen=True)
class PlyLayout:
    """Where the vertices and faces of a binary PLY lie: byte offsets and record dtypes
    (``vertex_dtype`` has fields x, y, z; ``face_dtype`` has ``count`` and ``idx`` (k,))."""

    path: str
    n_vertices: int
    n_polygons: int
    corners: int
    vertex_offset: int
    vertex_dtype: np.dtype
    face_offset: int
    face_dtype: np.dtype

    @property
    def n_faces(self) -> int:
        """Triangles: ``n_polygons × (corners - 2)``."""
        return self.n_polygons * (self.corners - 2)


def _record_dtype(order, props, corners=None):
    from ..mesh_io.ply import _PLY_SIZES, _ply_scalar
    fields = []
    for pname, types in props:
        if types[0] == "list":
            if corners is None or pname not in ("vertex_indices", "vertex_index"):
                return None                       # a list of unknown length: not fixed-size
            fields.append(("count", _ply_scalar(order, types[1])))
            fields.append(("idx", _ply_scalar(order, types[2]), (corners,)))
        else:
            fields.append((pname if pname in ("x", "y", "z") else f"_{len(fields)}",
                           _ply_scalar(order, types[0]) if pname in ("x", "y", "z")
                           else f"V{_PLY_SIZES[types[0]]}"))
    return np.dtype(fields)


def ply_layout(path) -> PlyLayout | None:
    """The layout of a binary PLY whose vertices and faces can be memory-mapped, or None
    (ascii, or a variable-size element: convert with :func:`convert_text_mesh` or read
    whole).

    Raises
    ------
    igl_hhj.mesh_io.MeshFileError
        Not a PLY, a corrupt header, a body shorter than the header declares, or face
        records whose corner counts differ from the one the file size implies (first
        such face named; checked in blocks, so memory stays bounded).
    """
    from ..mesh_io.ply import _parse_ply_header
    from ..errors import MeshFileError
    path = str(path)
    with open(path, "rb") as fh:
        head = fh.read(1 << 16)
    fmt, elements, body_start = _parse_ply_header(path, head)
    if fmt == "ascii":
        return None
    order = "<" if fmt == "binary_little_endian" else ">"
    counts = {name: n for name, n, _ in elements}
    props = {name: p for name, _, p in elements}
    other = 0
    for name, n, p in elements:
        if name != "face":
            dt = _record_dtype(order, p)
            if dt is None:
                return None
            other += n * dt.itemsize
    tri = _record_dtype(order, props["face"], 3)
    if tri is None:
        return None
    nf, body = counts["face"], os.path.getsize(path) - body_start
    per = nf * tri.fields["idx"][0].base.itemsize
    extra = body - other - nf * tri.itemsize
    corners = 3 + extra // per if nf and extra > 0 and extra % per == 0 else 3
    fdt = _record_dtype(order, props["face"], corners)
    if body < other + nf * fdt.itemsize:
        raise MeshFileError(f"{path}: truncated: the header declares "
                            f"{', '.join(f'{n} {name}' for name, n, _ in elements)} elements, which "
                            f"need {other + nf * fdt.itemsize} body bytes; the file has {body}")
    offsets, at = {}, body_start
    for name, n, p in elements:
        offsets[name] = at
        at += n * (fdt if name == "face" else _record_dtype(order, p)).itemsize
    layout = PlyLayout(path, counts["vertex"], nf, int(corners), offsets["vertex"],
                       _record_dtype(order, props["vertex"]), offsets["face"], fdt)
    _check_counts(layout)
    return layout


def _check_counts(layout, block=1 << 22):
    """Every face record declares ``layout.corners`` corners (in blocks of ``block`` records)."""
    from ..errors import MeshFileError
    for a in range(0, layout.n_polygons, block):
        b = min(a + block, layout.n_polygons)
        rec = np.memmap(layout.path, dtype=layout.face_dtype, mode="r",
                        offset=layout.face_offset + a * layout.face_dtype.itemsize, shape=(b - a,))
        bad = np.flatnonzero(rec["count"] != layout.corners)
        if bad.size:
            i = int(bad[0])
            raise MeshFileError(f"{layout.path}: face {a + i} declares {int(rec['count'][i])} corners "
                                f"where the file size says {layout.corners}: corrupt, or mixed polygons "
                                f"(binary PLYs must hold faces of one corner count to be streamed)")
        del rec


def _text_lines(fh, n, what, path):
    """Yield blocks of up to BLOCK_LINES non-empty, non-comment lines (bytes), n lines in all."""
    from ..errors import MeshFileError
    left = n
    while left > 0:
        lines = []
        while len(lines) < min(left, BLOCK_LINES):
            line = fh.readline()
            if not line:
                raise MeshFileError(f"{path}: truncated: {n - left + len(lines)} of {n} {what} lines")
            s = line.split(b"#", 1)[0].strip()
            if s:
                lines.append(s)
        left -= len(lines)
        yield lines


def _numbers(lines, width, what, path, first):
    from ..errors import MeshFileError
    try:
        a = np.array(b" ".join(lines).split(), dtype=np.float64)
    except ValueError:
        raise MeshFileError(f"{path}: non-numeric value in the {what} lines {first}..{first + len(lines)}") from None
    if a.size != width * len(lines):
        raise MeshFileError(f"{path}: {what} lines {first}..{first + len(lines)} do not all have "
                            f"{width} values (streaming needs one corner count for every face)")
    return a.reshape(len(lines), width)


def convert_text_mesh(path, v_out, f_out):
    """Convert an ascii PLY or OFF with one corner count into ``v_out`` (#V, 3) float64 and
    ``f_out`` (#F, 3) int64 ``.npy`` files in one streaming pass (k-gons: fans).

    Returns ``(n_vertices, n_faces)``, or None when the file is not such a mesh (read it whole)."""
    from ..mesh_io.ply import _parse_ply_header
    path = str(path)
    with open(path, "rb") as fh:
        head = fh.read(1 << 16)
    if Path(path).suffix.lower() == ".ply":
        fmt, elements, body_start = _parse_ply_header(path, head)
        if fmt != "ascii" or [e[0] for e in elements] != ["vertex", "face"] or len(elements[1][2]) != 1:
            return None
        nv, nf = elements[0][1], elements[1][1]
        vcols = [p for p, _ in elements[0][2]]
        cols = [vcols.index(c) for c in "xyz"]
        fh = open(path, "rb")
        fh.seek(body_start)
    elif Path(path).suffix.lower() == ".off":
        fh = open(path, "rb")
        tok = []
        while len(tok) < 4:
            line = fh.readline()
            if not line:
                return None
            tok += line.split(b"#", 1)[0].split()
        if not re.fullmatch(rb"[A-Z]*OFF", tok[0]):
            fh.close()
            return None
        nv, nf = int(tok[1]), int(tok[2])
        vcols, cols = None, [0, 1, 2]
    else:
        return None
    with fh:
        V = np.lib.format.open_memmap(v_out, mode="w+", dtype=np.float64, shape=(nv, 3))
        at = 0
        for lines in _text_lines(fh, nv, "vertex", path):
            width = len(vcols) if vcols else len(lines[0].split())
            V[at:at + len(lines)] = _numbers(lines, width, "vertex", path, at)[:, cols]
            at += len(lines)
        V.flush()
        del V
        F = None
        at = 0
        for lines in _text_lines(fh, nf, "face", path):
            if F is None:
                k = int(float(lines[0].split()[0]))
                if k < 3:
                    return None
                F = np.lib.format.open_memmap(f_out, mode="w+", dtype=np.int64, shape=(nf * (k - 2), 3))
            P = _numbers(lines, k + 1, "face", path, at).astype(np.int64)
            if (P[:, 0] != k).any():
                return None
            F[at * (k - 2):(at + len(lines)) * (k - 2)] = _fan(P[:, 1:])
            at += len(lines)
        if F is None:
            k = 3
            F = np.lib.format.open_memmap(f_out, mode="w+", dtype=np.int64, shape=(0, 3))
        F.flush()
        del F
    return nv, nf * (k - 2)


def _fan(P):
    """Triangles (m (k-2), 3) of k-gons (m, k): the fan from the first corner."""
    k = P.shape[1]
    if k == 3:
        return P
    j = np.arange(1, k - 1)
    return np.stack([np.repeat(P[:, 0], k - 2), P[:, j].ravel(), P[:, j + 1].ravel()], axis=1)


def write_binary_ply(path, n_vertices, n_faces, vertex_blocks, face_blocks, *, vertex_properties=()):
    """Write a binary little-endian PLY from blocks, holding one block at a time.

    Parameters
    ----------
    n_vertices, n_faces : int, the totals (the header comes first).
    vertex_blocks : iterable of (m, 3 + p) float64 arrays: x, y, z and the ``p`` properties.
    face_blocks : iterable of (m, 3) int arrays.
    vertex_properties : names of the p extra (double) vertex properties.
    """
    names = ("x", "y", "z") + tuple(vertex_properties)
    head = ["ply", "format binary_little_endian 1.0", "comment written by igl_hhj.tiled",
            f"element vertex {n_vertices}", *[f"property double {p}" for p in names],
            f"element face {n_faces}", "property list uchar int vertex_indices", "end_header"]
    rec = np.dtype([("n", "u1"), ("i", "<i4", (3,))])
    nv = nf = 0
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "wb") as fh:
        fh.write(("\n".join(head) + "\n").encode("ascii"))
        for B in vertex_blocks:
            B = np.ascontiguousarray(B, dtype="<f8")
            if B.ndim != 2 or B.shape[1] != len(names):
                raise ValueError(f"vertex blocks must have {len(names)} columns, got shape {B.shape}")
            fh.write(B.tobytes())
            nv += len(B)
        for B in face_blocks:
            r = np.empty(len(B), dtype=rec)
            r["n"] = 3
            r["i"] = B
            fh.write(r.tobytes())
            nf += len(B)
    if (nv, nf) != (n_vertices, n_faces):
        os.remove(tmp)
        raise ValueError(f"blocks hold {nv} vertices and {nf} faces, the header says "
                         f"{n_vertices} and {n_faces}")
    os.replace(tmp, path)
