"""Guarded mesh reading and curvature output files (used by the ``igl-hhj`` command line).

Reading goes through ``igl.read_triangle_mesh``; this module only checks the
file *before* libigl sees it, because libigl 2.6's readers misbehave on some
bad inputs instead of raising (measured with libigl 2.6.3):

* a directory or a missing file: C++ messages on stderr (the directory case
  prints uninitialised memory) and a bare ``RuntimeError``;
* ``.obj``, ``.ply`` or ``.mesh`` garbage: *no* error, empty arrays;
* an ascii ``.ply`` with fewer faces than its header declares, or with
  mixed triangles and quads: ``free(): double free`` — the process aborts;
* a ``.ply`` header declaring 10¹¹ vertices in a 150-byte file: an endless
  loop; 10⁸ vertices: 4.7 GB of memory before returning;
* an ``.off`` header declaring 10⁸ vertices: 5.5 GB of memory, 15 s;
* a truncated binary ``.ply``: uninitialised memory returned as face indices.

* an ``.off`` face line claiming 2·10⁹ corners in a 45-byte file: 15.7 GB
  of memory, then ``std::bad_alloc``;
* an ascii ``.ply`` with a non-numeric token: uninitialised indices;
* ``.obj`` faces written 0-based: index -1 after libigl's 1-based shift;
* a ``.ply`` header declaring a property or an element twice, or an ascii face
  line without the values of a second list property (``texcoord``): the
  process aborts (``free(): double free``).

:func:`read_mesh` therefore checks existence, regular file, readability and
extension, then checks *every* count and token of the body before libigl
sees it, with numpy in bounded chunks (memory O(#lines), time linear in the
file size): the element counts an ``.off`` / ``.ply`` header declares against
the lines or bytes that follow, every corner count of an ``.off`` face line
against the indices it lists, that every ascii token that must be a number is
one, ``.obj`` faces 1-based, binary ``.ply`` face records triangles, binary
``.stl`` sizes ``84 + 50 × count``, ``.mesh`` / ``.msh`` section counts
against the lines that follow.  It reads with libigl's C++ messages captured
and raises :class:`MeshFileError` (a ``ValueError``) with one line naming the
problem.

The formats libigl lacks (``.gltf .glb .3mf .vtp .vtu .vtk``) and PLYs of quads or
other polygons (libigl's reader aborts on them) are read by :mod:`igl_hhj.polygon_io`
(optional trimesh / pyvista / meshio) and by a numpy PLY reader; every format splits
polygons by one rule, the fan from each polygon's first corner (what libigl's OBJ / OFF
readers do).  :func:`read_mesh_file` returns the counts (:class:`MeshFile`).

:func:`read_curvature` reads a result back (``.npz``, ``.ply``, ``.vtp``, ``.vtu``,
``.vtk``; ``igl-hhj view``).

:func:`write_curvature` writes a
:class:`igl_hhj.baselines.CurvatureEstimate` as ``.npz``, ``.csv``, ``.ply``
(with MeshLab's ``quality``), ``.vtp`` / ``.vtu`` / ``.vtk``
(:mod:`igl_hhj.vtk_files`, the displayed quantity as the active scalars) or
``.obj`` with per-vertex colours, in forms that meshio, pyvista/VTK/ParaView,
pymeshlab/MeshLab, trimesh and Blender read (numpy only, no per-element Python
loops, no optional dependency).
"""
from __future__ import annotations

import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .polygon_io import EXTRA_EXTENSIONS, PolygonSplit, polygon_split, read_polygon_mesh, split_polygons

if TYPE_CHECKING:
    from .baselines import CurvatureEstimate

__all__ = ["MeshFileError", "MeshFile", "read_mesh_file", "READ_EXTENSIONS", "CapturedOutput", "MESH_EXTENSIONS", "OUTPUT_EXTENSIONS", "read_mesh",
           "check_output_path", "probe_writable", "write_curvature", "read_curvature", "CurvatureFile",
           "RESULT_EXTENSIONS", "CURVATURE_COLUMNS", "MESHIO_EXTENSIONS",
           "VTK_EXTENSIONS",
           "quantity_colours"]

MESH_EXTENSIONS = (".obj", ".off", ".ply", ".stl", ".wrl", ".mesh", ".msh")
"""Extensions ``igl.read_triangle_mesh`` dispatches on (case-insensitive)."""

READ_EXTENSIONS = MESH_EXTENSIONS + tuple(EXTRA_EXTENSIONS)
"""Extensions :func:`read_mesh` reads: libigl's, and through optional packages those of
:data:`igl_hhj.polygon_io.EXTRA_EXTENSIONS` (glTF/GLB, 3MF, VTP, VTU, VTK)."""

OUTPUT_EXTENSIONS = (".npz", ".csv", ".ply", ".vtp", ".vtu", ".vtk", ".obj")
VTK_EXTENSIONS = (".vtp", ".vtu", ".vtk")
"""Output extensions written as VTK files (:mod:`igl_hhj.vtk_files`, numpy only)."""
MESHIO_EXTENSIONS: tuple[str, ...] = ()
"""Output extensions that need meshio: none any more (``.vtu`` / ``.vtk`` are written with
numpy since issue 26); kept for scripts that check it."""

CURVATURE_COLUMNS = ("k1", "k2", "H", "K", "d1x", "d1y", "d1z", "d2x", "d2y", "d2z")
"""Per-element columns of the ``.csv`` and ``.ply`` outputs (after ``index`` in the csv)."""

_HEADER_BYTES = 1 << 16
_PLY_HEADER_MAX = 1 << 26           # a PLY header may be long (comments), not unbounded
_PLY_SIZES = {"char": 1, "int8": 1, "uchar": 1, "uint8": 1, "short": 2, "int16": 2,
              "ushort": 2, "uint16": 2, "int": 4, "int32": 4, "uint": 4, "uint32": 4,
              "float": 4, "float32": 4, "double": 8, "float64": 8}


def _ply_scalar(order, t):
    """The numpy dtype string of PLY scalar type ``t`` in byte order ``order`` ("<" or ">")."""
    kind = "f" if t in ("float", "float32", "double", "float64") else ("u" if t.startswith("u") else "i")
    return order + kind + str(_PLY_SIZES[t])


class MeshFileError(ValueError):
    """A mesh or output file the command line cannot use (message: one line)."""


# --------------------------------------------------------------------------- reading
def _check_input_file(path):
    path = Path(path)
    if not path.exists():
        raise MeshFileError(f"{path}: no such file")
    if path.is_dir():
        raise MeshFileError(f"{path}: is a directory, not a mesh file")
    if not path.is_file():
        raise MeshFileError(f"{path}: not a regular file")
    ext = path.suffix.lower()
    if ext not in READ_EXTENSIONS:
        raise MeshFileError(f"{path}: unknown mesh file extension {path.suffix!r} "
                            f"(libigl reads {', '.join(MESH_EXTENSIONS)}; with trimesh, pyvista or "
                            f"meshio also {', '.join(EXTRA_EXTENSIONS)})")
    try:
        with open(path, "rb") as fh:
            head = fh.read(_HEADER_BYTES)
    except OSError as exc:
        raise MeshFileError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if not head.strip():
        raise MeshFileError(f"{path}: file is empty")
    return path, ext, head


def _too_short(path, what, need, have):
    raise MeshFileError(f"{path}: truncated or corrupt: the header declares {what}, which needs "
                        f"at least {need} bytes after the header, but the file has {have}")


# --------------------------------------------------------------------------- body scan
_CHUNK = 1 << 22          # bytes of the file per vectorised pass (bounds temporary memory)


def _char_table(chars):
    t = np.zeros(256, dtype=bool)
    t[list(chars)] = True
    return t


_WS = _char_table(b" \t\r\n\v\f")
_NUMBER = _char_table(b"0123456789+-.eE")
_DIGIT = _char_table(b"0123456789")
_CORNER = _char_table(b"0123456789-/")


class _Lines:
    """A text body summarised per non-empty line, with numpy in bounded chunks.

    Memory is O(number of lines) plus O(``_CHUNK``); time is linear in the
    file size.  Everything after ``#`` on a line is a comment (``comments``).

    Attributes (arrays, one entry per non-empty line in file order)
    ----------
    offset : byte offset of the line in the file
    lineno : 1-based line number in the file
    ntok : number of whitespace-separated tokens
    c0, flen : first byte and length of the first token
    first : value of the first token if it is an integer of ≤ 18 digits, else -1
    n_num : how many tokens are numbers (float syntax)
    n_corner : how many tokens are OBJ face corners (``i``, ``i/j``, ``i//k``, ``-i``)
    zero_corner : one of those corners contains the index 0
    int_k : how many of tokens 2 .. 1 + first are non-negative integers (OFF face lines)
    maxlen : length of the longest token
    """

    FIELDS = ("offset", "lineno", "ntok", "c0", "flen", "first", "n_num", "n_corner",
              "zero_corner", "int_k", "maxlen")

    def __init__(self, path, start, comments=True, first_line=1, corners=False):
        parts = {k: [] for k in self.FIELDS}
        line0, pos0 = first_line, start
        with open(path, "rb") as fh:
            fh.seek(start)
            carry = b""
            while True:
                block = fh.read(_CHUNK)
                data = carry + block
                if block:
                    cut = data.rfind(b"\n") + 1
                    if cut == 0:
                        carry = data
                        continue
                    data, carry = data[:cut], data[cut:]
                if data:
                    for k, v in self._scan(data, comments, corners).items():
                        parts[k].append(v)
                    parts["lineno"][-1] += line0
                    parts["offset"][-1] += pos0
                    line0 += data.count(b"\n")
                    pos0 += len(data)
                if not block:
                    break
        for k, v in parts.items():
            setattr(self, k, np.concatenate(v) if v else np.zeros(0, dtype=np.int64))

    def __len__(self):
        return len(self.ntok)

    @staticmethod
    def _scan(data, comments, corners):
        buf = np.frombuffer(data, dtype=np.uint8)
        n = buf.size
        space = _WS[buf]
        nl = np.flatnonzero(buf == 10)
        if comments and b"#" in data:
            hashes = np.flatnonzero(buf == 35)
            ends = np.append(nl, n)[np.searchsorted(nl, hashes)]     # end of each comment
            delta = np.zeros(n + 1, dtype=np.int32)
            np.add.at(delta, hashes, 1)
            np.add.at(delta, ends, -1)
            space |= np.cumsum(delta[:n]) > 0
        inside = ~space
        before = np.empty(n, dtype=bool)                            # previous char is space
        before[0] = True
        before[1:] = space[:-1]
        s = np.flatnonzero(inside & before)                         # token starts
        before[:-1] = space[1:]                                     # (reused: next char is space)
        before[-1] = True
        e = np.flatnonzero(inside & before) + 1                     # token ends (exclusive)
        del before
        line = np.searchsorted(nl, s)                               # line of each token (block)
        head = np.flatnonzero(np.concatenate([[True], line[1:] != line[:-1]])) if s.size \
            else np.zeros(0, dtype=np.int64)
        ntok = np.diff(np.append(head, s.size))
        owner = np.repeat(np.arange(head.size), ntok)               # line (table row) of each token
        pos = np.arange(s.size) - head[owner] if s.size else np.zeros(0, dtype=np.int64)
        starts = np.concatenate([[0], nl + 1])[line[head]] if head.size else head

        pre = np.empty(n + 1, dtype=np.int32)                       # n ≤ 2 × _CHUNK < 2³¹
        pre[0] = 0

        def count(mask):                                            # per token: chars in mask
            np.cumsum(mask & inside, dtype=np.int32, out=pre[1:])
            return pre[e] - pre[s]

        def every(table):                                           # every character of the token
            return count(~table[buf]) == 0

        has_digit = count(_DIGIT[buf]) > 0
        digits = every(_DIGIT)
        number = every(_NUMBER) & has_digit
        corner = np.zeros(s.size, dtype=bool)
        zero = np.zeros(s.size, dtype=bool)
        if corners:                                                 # OBJ face corners
            corner = every(_CORNER) & has_digit
            zc = np.flatnonzero(buf == 48)                          # a component "0" of a corner
            before = np.where(zc > 0, buf[np.maximum(zc - 1, 0)], 32)
            after = np.where(zc < n - 1, buf[np.minimum(zc + 1, n - 1)], 32)
            zc = zc[((before == 47) | _WS[before]) & ((after == 47) | _WS[after])]
            if zc.size and s.size:
                t = np.searchsorted(s, zc, side="right") - 1
                zero[t[(t >= 0) & (zc < e[np.maximum(t, 0)])]] = True
        fs, flen = s[head], (e - s)[head]
        first = np.where(digits[head] & (flen <= 18), 0, -1).astype(np.int64)
        for j in range(18):
            m = (first >= 0) & (j < flen)
            first[m] = first[m] * 10 + (buf[fs[m] + j].astype(np.int64) - 48)
        kk = first[owner] if s.size else pos

        def per_line(x):
            return np.bincount(owner, weights=x, minlength=head.size).astype(np.int64)

        return {"offset": starts.astype(np.int64), "lineno": line[head].astype(np.int64),
                "ntok": ntok.astype(np.int64), "c0": buf[fs].astype(np.int64),
                "flen": flen.astype(np.int64), "first": first,
                "n_num": per_line(number), "n_corner": per_line(corner),
                "zero_corner": per_line(corner & zero) > 0,
                "int_k": per_line((pos > 0) & (pos <= kk) & digits),
                "maxlen": (np.maximum.reduceat(e - s, head) if head.size
                           else np.zeros(0, dtype=np.int64)).astype(np.int64)}

    def text(self, path, i, limit=60):
        """The i-th non-empty line (at most ``limit`` characters), for messages."""
        with open(path, "rb") as fh:
            fh.seek(int(self.offset[i]))
            raw = fh.readline(limit + 1).rstrip(b"\r\n")
        txt = raw[:limit].decode("ascii", "replace")
        return txt + ("..." if len(raw) > limit else "")


def _first_bad(path, lines, bad, what):
    """Raise MeshFileError naming the first line where ``bad`` holds."""
    i = int(np.flatnonzero(bad)[0])
    n = int(bad.sum())
    more = f" ({n} such lines)" if n > 1 else ""
    raise MeshFileError(f"{path}: line {int(lines.lineno[i])}: {what}{more}: "
                        f"{lines.text(path, i)!r}")


def _check_off_body(path, nV, nF):
    """Every vertex line numeric, every face line a polygon whose corner count its
    indices back up (libigl allocates whatever a face line claims).  Returns the
    corner count of every face ((nF,) int64)."""
    L = _Lines(path, 0)
    h = 1 if L.ntok[0] >= 3 else 2                 # counts on the OFF line or the next one
    if len(L) < h + nV + nF:
        raise MeshFileError(f"{path}: truncated: the header declares {nV} vertices and {nF} "
                            f"faces, the file has {max(len(L) - h, 0)} lines after it")
    v = slice(h, h + nV)
    _check_rows(path, L, v, (L.ntok[v] < 3) | (L.n_num[v] != L.ntok[v]),
                "vertex line is not three (or more) numbers")
    f = slice(h + nV, h + nV + nF)
    k = L.first[f]
    wrapped = np.flatnonzero((k >= 3) & (L.ntok[f] < 1 + k))
    if wrapped.size:                               # a face record continues on the next lines
        w = h + nV + int(wrapped[0])
        f = slice(h + nV, w)
        k = L.first[f]
    _check_rows(path, L, f, k < 0, "face line does not start with its corner count")
    _check_rows(path, L, f, k < 3, "face with fewer than 3 corners")
    _check_rows(path, L, f, L.int_k[f] != k, "face corner is not a non-negative integer index")
    if wrapped.size:
        k = np.concatenate([k, _check_off_wrapped_faces(path, L, w, nF - int(wrapped[0]))])
    return k


def _line_tokens(fh, L, i):
    """Tokens of the i-th non-empty line (comments removed), read from the open file."""
    fh.seek(int(L.offset[i]))
    return fh.readline().split(b"#")[0].split()


def _check_off_wrapped_faces(path, L, start, n):
    """OFF face records from line ``start`` on, token by token as libigl reads them: the
    corner count, then that many indices over as many lines as they take (the rest of the
    line of the last index is ignored).  Only reached when some record wraps a line."""
    with open(path, "rb") as fh:
        return _wrapped_faces(path, fh, L, start, n)


def _wrapped_faces(path, fh, L, start, n):
    i = start
    sizes = np.zeros(n, dtype=np.int64)
    for r in range(n):
        if i >= len(L):
            raise MeshFileError(f"{path}: truncated: the file ends before its last face records")
        line = i
        if L.first[i] < 0:
            _first_bad(path, L, np.arange(len(L)) == i, "face line does not start with its corner count")
        k = int(L.first[i])
        if k < 3:
            _first_bad(path, L, np.arange(len(L)) == i, "face with fewer than 3 corners")
        sizes[r] = k
        need = k
        toks = _line_tokens(fh, L, i)[1:]
        while True:
            take = toks[:need]
            if not all(t.isdigit() for t in take):
                _first_bad(path, L, np.arange(len(L)) == i,
                           "face corner is not a non-negative integer index")
            need -= len(take)
            if need == 0:
                break
            i += 1
            if i >= len(L):
                _first_bad(path, L, np.arange(len(L)) == line,
                           "face line claims more corners than it lists (truncated or corrupt)")
            toks = _line_tokens(fh, L, i)
        if i > line:                               # libigl's reader crashes on a '#' in a record
            fh.seek(int(L.offset[line]))
            if b"#" in fh.read(int(L.offset[i] - L.offset[line])):
                _first_bad(path, L, np.arange(len(L)) == line,
                           "comment inside a face record that continues on the next line")
        i += 1
    return sizes


def _check_rows(path, L, rows, bad, what):
    if bad.any():
        mask = np.zeros(len(L), dtype=bool)
        mask[rows] = bad
        _first_bad(path, L, mask, what)


def _check_obj(path):
    """``v`` lines numeric, ``f`` lines made of corner indices, and 1-based.  Returns the
    corner count of every face ((#f lines,) int64)."""
    L = _Lines(path, 0, corners=True)
    one = L.flen == 1
    v = one & (L.c0 == ord("v"))
    f = one & (L.c0 == ord("f"))
    bad = v & ((L.ntok < 4) | (L.n_num != L.ntok - 1))
    if bad.any():
        _first_bad(path, L, bad, "vertex line is not 'v' and three (or more) numbers")
    bad = f & ((L.ntok < 4) | (L.n_corner != L.ntok - 1))
    if bad.any():
        _first_bad(path, L, bad, "face line is not 'f' and three or more vertex indices "
                                 "(i, i/t, i/t/n or i//n)")
    bad = f & L.zero_corner
    if bad.any():
        _first_bad(path, L, bad, "face uses vertex index 0, but OBJ indices start at 1: the file "
                                 "is 0-based (add 1 to every face index, or write it with a "
                                 "1-based OBJ writer)")
    return (L.ntok - 1)[f]


def _check_stl(path, head, size):
    """Binary STL: 84 + 50 × count bytes exactly; ascii STL: numeric vertex lines."""
    if size >= 84:
        n = int(np.frombuffer(head[80:84], dtype="<u4")[0]) if len(head) >= 84 else -1
        if n >= 0 and 84 + 50 * n == size:
            if n == 0:
                raise MeshFileError(f"{path}: binary STL with 0 triangles")
            return
    if not head.lstrip().lower().startswith(b"solid"):
        n = int(np.frombuffer(head[80:84], dtype="<u4")[0]) if len(head) >= 84 else 0
        raise MeshFileError(f"{path}: not an STL file: a binary STL declaring {n} triangles needs "
                            f"{84 + 50 * n} bytes, the file has {size}, and it does not start "
                            f"with 'solid' (ascii STL)")
    L = _Lines(path, 0)
    vert = (L.c0 == ord("v")) & (L.flen == 6)
    bad = vert & ((L.ntok != 4) | (L.n_num != 3))
    if bad.any():
        _first_bad(path, L, bad, "vertex line is not 'vertex' and three numbers")
    nv = int(vert.sum())
    if nv == 0 or nv % 3:
        raise MeshFileError(f"{path}: ascii STL with {nv} vertex lines (need a positive multiple "
                            f"of 3: three per facet); truncated or corrupt")


def _check_keyword_counts(path, size):
    """.mesh / .msh: a count after a section keyword (``Vertices``, ``$Nodes``, ...) must
    not exceed the lines that follow (libigl allocates what the count says)."""
    L = _Lines(path, 0)
    letter = ((L.c0 | 32) >= ord("a")) & ((L.c0 | 32) <= ord("z")) | (L.c0 == ord("$"))
    kw = np.flatnonzero(letter & (L.first < 0) & (L.ntok <= 2))
    for i in kw[:200]:                                  # section keywords: a handful
        if L.ntok[i] == 2:
            words = L.text(path, i, 200).split()
            n = int(words[1]) if len(words) > 1 and words[1].isdigit() else -1
            rest = len(L) - i - 1
        elif i + 1 < len(L) and L.ntok[i + 1] >= 1:
            n, rest = int(L.first[i + 1]), len(L) - i - 2
        else:
            continue
        if n > max(rest, 0) + 1:
            raise MeshFileError(f"{path}: line {int(L.lineno[i])}: section "
                                f"{L.text(path, i, 30)!r} declares {n} records, the file has "
                                f"{max(rest, 0)} more lines (truncated or corrupt)")


def _check_off_header(path, head, size):
    """Declared ``nV nF`` of an ascii OFF against the file size (≥ 6 bytes a vertex, 8 a face)."""
    lines = [ln.split(b"#")[0].split() for ln in head.split(b"\n")[:64]]
    tokens = [t for ln in lines for t in ln]
    if not tokens or not re.fullmatch(rb"[A-Z]*OFF", tokens[0]):
        return None                                          # libigl reports this itself
    if b"BINARY" in tokens[:2]:
        raise MeshFileError(f"{path}: binary OFF is not supported by libigl's reader")
    try:
        nV, nF = int(tokens[1]), int(tokens[2])
    except (IndexError, ValueError):
        raise MeshFileError(f"{path}: corrupt OFF header: expected the counts '#V #F #E' after "
                            f"{tokens[0].decode()!r}, got {b' '.join(tokens[1:4]).decode(errors='replace')!r}"
                            ) from None
    if nV < 0 or nF < 0:
        raise MeshFileError(f"{path}: corrupt OFF header: negative counts {nV} {nF}")
    need = 6 * nV + 8 * nF - 1          # "0 0 0\n" per vertex, "3 0 1 2\n" per face
    if need > size:
        _too_short(path, f"{nV} vertices and {nF} faces", need, size)
    return _check_off_body(path, nV, nF)


def _ply_head(path, head):
    """The file's first bytes up to and including the line of ``end_header`` (any length
    up to ``_PLY_HEADER_MAX``)."""
    if not head.startswith(b"ply"):
        raise MeshFileError(f"{path}: not a PLY file (it does not start with 'ply')")
    if b"end_header" in head:
        return head
    with open(path, "rb") as fh:
        data = b""
        while len(data) < _PLY_HEADER_MAX:
            block = fh.read(1 << 20)
            if not block:
                break
            data += block
            if data.find(b"end_header", max(len(data) - len(block) - 16, 0)) >= 0:
                return data
    raise MeshFileError(f"{path}: not a PLY file (no 'end_header' line in the first "
                        f"{min(len(data), _PLY_HEADER_MAX)} bytes)")


def _parse_ply_header(path, head):
    head = _ply_head(path, head)
    end = head.find(b"end_header")
    body_start = head.index(b"\n", end) + 1 if b"\n" in head[end:] else len(head)
    fmt, elements = None, []
    for raw in head[:end].split(b"\n")[1:]:
        w = raw.decode("ascii", "replace").split()
        if not w or w[0] in ("comment", "obj_info"):
            continue
        try:
            if w[0] == "format":
                fmt = w[1]
            elif w[0] == "element":
                elements.append([w[1], int(w[2]), []])
            elif w[0] == "property":
                elements[-1][2].append((w[-1], w[1:-1]))
        except (IndexError, ValueError):
            raise MeshFileError(f"{path}: corrupt PLY header line {raw[:60]!r}") from None
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise MeshFileError(f"{path}: unknown PLY format {fmt!r}")
    if any(n < 0 for _, n, _ in elements):
        raise MeshFileError(f"{path}: corrupt PLY header: negative element count")
    _check_ply_properties(path, elements)
    return fmt, elements, body_start


_PLY_INT_TYPES = ("char", "int8", "uchar", "uint8", "short", "int16", "ushort", "uint16", "int",
                  "int32", "uint", "uint32")


def _check_ply_properties(path, elements):
    """Known property types, vertex x/y/z and face vertex_indices (libigl's PLY reader
    segfaults when they are missing)."""
    seen = set()
    for name, _, props in elements:
        if name in seen:
            raise MeshFileError(f"{path}: corrupt PLY header: element {name!r} is declared twice "
                                f"(libigl's PLY reader aborts on that)")
        seen.add(name)
        names = [pname for pname, _ in props]
        twice = sorted({pname for pname in names if names.count(pname) > 1})
        if twice:
            raise MeshFileError(f"{path}: corrupt PLY header: element {name!r} declares property "
                                f"{twice[0]!r} more than once (libigl's PLY reader aborts on that)")
        for pname, types in props:
            scalar = types[1:] if types and types[0] == "list" else types
            if not scalar or any(t not in _PLY_SIZES for t in scalar) or                     (types[0] == "list" and (len(types) != 3 or types[1] not in _PLY_INT_TYPES)):
                raise MeshFileError(f"{path}: corrupt PLY header: property {pname!r} of element "
                                    f"{name!r} has unknown type {' '.join(types)!r}")
    named = {name: props for name, _, props in elements}
    _check_ply_property_groups(path, named)
    if "vertex" not in named or not {"x", "y", "z"} <= {p for p, t in named["vertex"] if t[0] != "list"}:
        raise MeshFileError(f"{path}: PLY header has no 'element vertex' with properties x, y, z")
    if "face" not in named or not any(p in ("vertex_indices", "vertex_index") and t[0] == "list"
                                      and t[2] in _PLY_INT_TYPES for p, t in named["face"]):
        raise MeshFileError(f"{path}: PLY header has no 'element face' with an integer list "
                            f"property vertex_indices")


# Scalar properties that libigl 2.6's PLY reader requests together must share one type,
# else tinyply's "all requested properties must share the same type" ends in a double
# free (abort) or, for x/y/z, an empty V.  Measured groups: x/y/z, the colours, and all
# the remaining scalar properties of the element; normals and texture coordinates of
# mixed types read fine, so they are neither checked nor counted as remaining.
_PLY_GROUPS = {"vertex": ({"x", "y", "z"}, {"red", "green", "blue", "alpha"}), "face": ()}
_PLY_FREE = {"nx", "ny", "nz", "u", "v", "s", "t", "texture_u", "texture_v"}


def _check_ply_property_groups(path, named):
    """Properties libigl reads together must share one type (see ``_PLY_GROUPS``)."""
    for element, groups in _PLY_GROUPS.items():
        scalars = [(p, t[0]) for p, t in named.get(element, ()) if t[0] != "list"]
        known = set().union(_PLY_FREE, *groups)
        for group in groups + (None,):
            members = [(p, t) for p, t in scalars if (p in group if group else p not in known)]
            if len({t for _, t in members}) > 1:
                listed = ", ".join(f"{p} {t}" for p, t in members)
                raise MeshFileError(
                    f"{path}: PLY properties of element {element!r} read together have "
                    f"different types ({listed}); libigl's PLY reader cannot read that "
                    f"(it aborts): store them with one type")


def _check_ply(path, head, size):
    """PLY element counts against the body.  Returns None for a triangle mesh, else the corner
    count of every face ((#faces,) int64: polygons, which libigl's reader aborts on, so
    :func:`read_mesh_file` reads them with pyvista); a binary PLY may hold triangles or
    k-gons of one k, an ascii PLY any polygons."""
    fmt, elements, body_start = _parse_ply_header(path, head)
    body = size - body_start
    counts = {name: n for name, n, _ in elements}
    what = "elements " + ", ".join(f"{name} {n}" for name, n, _ in elements)
    if fmt != "ascii":
        need, exact = 0, True
        for name, n, props in elements:
            rec = 0
            for pname, types in props:
                if types[0] == "list":          # list <count type> <item type>
                    if name != "face" or pname not in ("vertex_indices", "vertex_index"):
                        exact = False
                        rec += _PLY_SIZES.get(types[1], 1)
                    else:                       # a triangle: count + 3 indices
                        rec += _PLY_SIZES.get(types[1], 1) + 3 * _PLY_SIZES.get(types[2], 4)
                else:
                    rec += _PLY_SIZES.get(types[0], 1)
            need += n * rec
        corners = 3
        if exact and need < body and counts.get("face", 0):
            # k-gons of one k: (k - 3) more indices per face record
            index = next(_PLY_SIZES.get(t[2], 4) for p, t in dict(_ply_element_props(elements))["face"]
                         if t[0] == "list")
            extra, per = body - need, counts["face"] * index
            if extra % per == 0:
                corners = 3 + extra // per
                need = body
        if need > body or (exact and need != body):
            raise MeshFileError(
                f"{path}: truncated or not a triangle mesh: the header declares {what}, "
                f"a triangle mesh with those needs {need} body bytes, the file has {body} "
                f"(libigl's PLY reader crashes or returns garbage on such files; binary PLYs "
                f"of mixed polygons are not supported: store them as ascii PLY, OBJ or OFF)")
        if exact:
            _check_binary_ply_faces(path, fmt, elements, body_start, corners)
        return None if corners == 3 else np.full(counts.get("face", 0), corners, dtype=np.int64)
    # ascii: one line per element; check the count first (bounded memory), then the lines
    total = sum(counts.values())
    if 2 * total - 1 > body:
        _too_short(path, what, 2 * total - 1, body)
    with open(path, "rb") as fh:
        n_head = fh.read(body_start).count(b"\n")
    L = _Lines(path, body_start, comments=False, first_line=n_head + 1)
    if len(L) != total:
        raise MeshFileError(f"{path}: truncated or corrupt: the header declares {what} "
                            f"({total} lines) but the body has {len(L)} lines "
                            f"(libigl's PLY reader aborts on such files)")
    if (L.n_num != L.ntok).any():
        _first_bad(path, L, L.n_num != L.ntok, "non-numeric value in the body of an ascii PLY")
    start, sizes = 0, None
    for name, n, props in elements:
        rows = slice(start, start + n)
        lists = [p for p, types in props if types[0] == "list"]
        if name == "face" and n:
            k = L.first[rows]
            _check_rows(path, L, rows, k < 3, "face line does not start with a corner count of 3 or more")
            sizes = k
            # an index of 10 or more digits is beyond any vertex count a PLY header can
            # declare here, and from 2³¹ on libigl's reader overflows and aborts
            _check_rows(path, L, rows, L.maxlen[rows] >= 10,
                        f"face line has a vertex index of 10 or more digits (the header declares "
                        f"{counts.get('vertex', 0)} vertices)")
            if len(lists) == 1 and lists == [p for p, _ in props if p in ("vertex_indices", "vertex_index")]:
                want = 1 + k + (len(props) - len(lists))
                _check_rows(path, L, rows, L.ntok[rows] != want,
                            "face line does not have the values its properties need (its corner "
                            "count, that many indices, one value per other property)")
            else:           # more list properties (texture coordinates...): line by line
                _check_ascii_ply_lists(path, L, rows, props)
        elif not lists and n:
            _check_rows(path, L, rows, L.ntok[rows] != len(props),
                        f"{name} line does not have the {len(props)} values its properties need")
        start += n
    return None if sizes is None or (sizes == 3).all() else sizes


def _check_ascii_ply_lists(path, L, rows, props):
    """Each line of an ascii PLY element with several list properties must hold exactly
    the values its properties need, each list its count and that many values (libigl's
    reader aborts otherwise).  A pass over those lines in Python."""
    with open(path, "rb") as fh:
        for row in range(rows.start, rows.stop):
            fh.seek(int(L.offset[row]))
            tok = fh.readline().split()
            at = 0
            for _, types in props:
                if types[0] != "list":
                    at += 1
                    continue
                count = int(float(tok[at])) if at < len(tok) else -1
                if count < 0 or float(tok[at]) != count:
                    at = len(tok) + 1
                    break
                at += 1 + count
            if at != len(tok):
                mask = np.zeros(len(L), dtype=bool)
                mask[row] = True
                _first_bad(path, L, mask, "face line does not have the values its properties need "
                                          "(each list its count and that many values)")


def _ply_element_props(elements):
    """[(element name, its properties)] of a parsed PLY header."""
    return [(name, props) for name, _, props in elements]


def _check_binary_ply_faces(path, fmt, elements, body_start, corners=3):
    """Every face record of a binary PLY of known layout must have ``corners`` corners (a
    corrupt count makes libigl read indices out of the following records)."""
    order = "<" if fmt == "binary_little_endian" else ">"
    kinds = {1: "u1", 2: "u2", 4: "u4", 8: "u8"}
    offset = body_start
    for name, n, props in elements:
        fields, ok = [], True
        for k, (pname, types) in enumerate(props):
            if types[0] == "list":
                if name != "face" or pname not in ("vertex_indices", "vertex_index"):
                    ok = False
                    break
                fields.append(("count", order + kinds.get(_PLY_SIZES.get(types[1], 1), "u1")))
                fields.append((f"i{k}", order + kinds.get(_PLY_SIZES.get(types[2], 4), "u4"), (corners,)))
            else:
                fields.append((f"p{k}", f"V{_PLY_SIZES.get(types[0], 1)}"))
        if not ok:
            return
        dt = np.dtype(fields)
        if name == "face" and n and "count" in dt.names:
            rec = np.fromfile(path, dtype=dt, count=n, offset=offset)
            bad = np.flatnonzero(rec["count"] != corners)
            if bad.size:
                raise MeshFileError(f"{path}: face {int(bad[0])} declares {int(rec['count'][bad[0]])} "
                                    f"corners where the file size says {corners}: corrupt, or "
                                    f"mixed polygons (binary PLYs must hold faces of one corner "
                                    f"count)")
        offset += n * dt.itemsize


def _flush_c_stdio():
    """Flush C stdio buffers (libigl's readers print with printf to a buffered stdout)."""
    try:
        import ctypes
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):  # no C runtime handle (e.g. Windows)
        pass


class CapturedOutput:
    """Context manager: redirect file descriptors 1 and 2 into a temporary file.

    Silences C/C++ libraries (libigl's readers, polyscope's EGL start-up)
    that print to the process's stdout/stderr; afterwards ``lines`` holds
    their first 20 non-empty lines, non-ASCII characters replaced by '?'.
    """

    def __enter__(self):
        import sys
        sys.stdout.flush()
        sys.stderr.flush()
        _flush_c_stdio()
        self._tmp = tempfile.TemporaryFile()
        self._saved = [os.dup(1), os.dup(2)]
        os.dup2(self._tmp.fileno(), 1)
        os.dup2(self._tmp.fileno(), 2)
        return self

    def __exit__(self, *exc):
        _flush_c_stdio()
        for fd, saved in zip((1, 2), self._saved):
            os.dup2(saved, fd)
            os.close(saved)
        self._tmp.seek(0)
        text = self._tmp.read(_HEADER_BYTES).decode("utf-8", "replace")
        self._tmp.close()
        lines = [" ".join("".join(c if " " <= c <= "~" else "?" for c in ln).split())
                 for ln in text.splitlines()[:20]]
        self.lines = [ln for ln in lines if ln]
        return False


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
    import shutil
    tmpdir = tempfile.mkdtemp(prefix="igl_hhj_bom_")
    copy = Path(tmpdir) / path.name
    try:
        with open(path, "rb") as src, open(copy, "wb") as dst:
            src.seek(len(_BOM))
            shutil.copyfileobj(src, dst, 1 << 20)
        _, ext, head = _check_input_file(copy)
        try:
            return _read_checked(copy, ext, head)
        except MeshFileError as exc:
            raise MeshFileError(str(exc).replace(str(copy), str(path))) from None
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
        _check_stl(path, head, size)
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


# --------------------------------------------------------------------------- writing
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


QUANTITIES = ("k1", "k2", "H", "K")
"""Values ``quantity=`` can put into PLY ``quality`` and OBJ colours."""


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
    from .vtk_files import write_vtk
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


# --------------------------------------------------------------------------- reading results back
RESULT_EXTENSIONS = (".npz", ".ply", ".vtp", ".vtu", ".vtk")
"""Outputs of :func:`write_curvature` that :func:`read_curvature` (and ``igl-hhj view``) re-open:
those that hold the mesh with its values (``.csv`` holds no mesh, ``.obj`` only colours)."""

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


def _estimate_from(fields, location, method):
    from .baselines import CurvatureEstimate
    have = [q for q in QUANTITIES if q in fields]
    if len(have) < len(QUANTITIES):
        raise MeshFileError(f"no curvature arrays {', '.join(q for q in QUANTITIES if q not in have)} per "
                            f"{location} (it holds: {', '.join(sorted(fields)) or 'nothing'}); "
                            f"write one with 'igl-hhj curvature MESH -o OUT'")
    vals = {q: np.asarray(fields[q], dtype=np.float64).reshape(-1) for q in QUANTITIES}
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
            try:
                z = np.load(p, allow_pickle=False)
                fields = {k: z[k] for k in z.files}
            except (OSError, ValueError) as exc:
                raise MeshFileError(f"{p}: not an .npz archive: {exc}") from None
            V, F = fields.pop("V", None), fields.pop("F", None)
            if V is None or F is None:
                raise MeshFileError(f"{p}: no arrays V and F (it holds: {', '.join(sorted(fields))})")
            location = str(fields.pop("per", "vertex"))
            method = str(fields.pop("method", ""))
            S = fields.pop("S", None)
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
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    n = len(V) if est.location == "vertex" else len(F)
    if len(est.k1) != n:
        raise MeshFileError(f"{p}: {len(est.k1)} values per {est.location}, the mesh has {n} {est.location}s")
    if S is not None:
        S = np.asarray(S, dtype=np.float64).reshape(-1, 3, 3)
    if method.startswith("hhj"):
        method = "hhj"
    elif method.startswith("libigl"):
        method = "igl"
    return CurvatureFile(V, F, est, method, quantity if quantity in QUANTITIES else "H", S, dict(fields))


def _check_input_file_any(path):
    if not path.exists():
        raise MeshFileError(f"{path}: no such file")
    if not path.is_file():
        raise MeshFileError(f"{path}: not a regular file")
