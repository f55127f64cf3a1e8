"""The checks a mesh file passes *before* libigl reads it (OBJ, OFF, STL, .mesh / .msh;
PLY in :mod:`.ply`): the file exists, is regular, readable, has a known extension, and every
count and token of its body is what the reader will trust (see :mod:`igl_hhj.mesh_io`).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import MeshFileError
from ..polygon_io import EXTRA_EXTENSIONS
from .extensions import MESH_EXTENSIONS, READ_EXTENSIONS
from .scan import _Lines, _check_rows, _first_bad, _line_tokens, _long_lines, _too_short


_HEADER_BYTES = 1 << 16
"""The first bytes of a file read to tell its kind and check its header."""


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
        _check_blank(path, head)
    return path, ext, head


def _check_blank(path, head):
    """The first bytes are blank: an empty file, or one of blanks only, is refused in words;
    one with a mesh after a blank start goes on."""
    if not head:
        raise MeshFileError(f"{path}: the file is empty (0 bytes): there is no mesh in it")
    with open(path, "rb") as fh:
        fh.seek(len(head))
        while True:
            block = fh.read(1 << 22)
            if not block:
                break
            if block.strip():
                return
    size = path.stat().st_size
    raise MeshFileError(f"{path}: the file holds only blanks (spaces, tabs, line breaks; {size} "
                        f"bytes): there is no mesh in it")


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


STL_LINE_LIMIT = 256
"""libigl's ascii STL reader reads a line into a 256-byte buffer (``std::istream::getline``): on a
line of 256 bytes or more the stream fails without reaching its end and the reader loops
forever.  :func:`_check_stl` refuses (or trims, after ``endsolid``) such lines first."""


def _check_stl(path, head, size):
    """Binary STL: 84 + 50 × count bytes exactly; ascii STL: numeric vertex lines and no
    line libigl's reader would loop on (:data:`STL_LINE_LIMIT`).

    Returns None, or for an ascii STL whose over-long lines all come after its last
    ``endsolid`` line (an interrupted copy padded with NUL bytes, text appended to the
    file), ``(keep, note)``: read the first ``keep`` bytes followed by ``endsolid``, and say
    ``note``."""
    if size >= 84:
        n = int(np.frombuffer(head[80:84], dtype="<u4")[0]) if len(head) >= 84 else -1
        if n >= 0 and 84 + 50 * n == size:
            if n == 0:
                raise MeshFileError(f"{path}: binary STL with 0 triangles")
            return None
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
    return _stl_long_lines(path, L, size)


def _stl_long_lines(path, L, size):
    offset, length, lineno = _long_lines(path, STL_LINE_LIMIT)
    if not offset.size:
        return None
    last_end = None                                # the last 'endsolid' line: offset, number
    with open(path, "rb") as fh:
        for i in np.flatnonzero((L.c0 == ord("e")) & (L.flen >= 8))[::-1]:
            fh.seek(int(L.offset[i]))
            if fh.read(1 << 16).lstrip().startswith(b"endsolid"):
                last_end = (int(L.offset[i]), int(L.lineno[i]))
                break
    why = (f"libigl's ascii STL reader reads at most {STL_LINE_LIMIT - 1} bytes a line (a longer "
           f"one makes it loop forever)")
    if last_end is None or offset[0] < last_end[0]:
        raise MeshFileError(f"{path}: line {int(lineno[0])} is {int(length[0])} bytes long"
                            + (f" ({offset.size} such lines)" if offset.size > 1 else "")
                            + f": {why}; shorten or remove it")
    keep = last_end[0]
    return keep, (f"ignored the {size - keep} bytes from line {last_end[1]} ('endsolid') on, "
                  f"which hold a line of {int(length[0])} bytes: {why}")


def _msh_binary_header(path):
    """``(data_size)`` of a binary Gmsh 2 ``.msh`` (``$MeshFormat`` then ``2.2 1 8``), None for ascii."""
    with open(path, "rb") as fh:
        head = fh.read(256)
    lines = head.split(b"\n")
    if len(lines) < 3 or lines[0].strip() != b"$MeshFormat":
        return None
    words = lines[1].split()
    if len(words) >= 3 and words[1] == b"1":
        try:
            return int(words[2])
        except ValueError:
            raise MeshFileError(f"{path}: corrupt $MeshFormat line {lines[1][:40]!r}: the data size "
                                f"is not an integer") from None
    return None


def _check_msh_binary(path, size, data_size):
    """A binary Gmsh 2 ``.msh``: the counts of ``$Nodes`` (each ``4 + 3 data_size`` bytes) and
    ``$Elements`` (at least 8 bytes each) against the bytes that follow them.  Counting text
    lines in a binary file is meaningless (its numbers contain newline bytes)."""
    if data_size not in (4, 8):
        raise MeshFileError(f"{path}: binary .msh with data size {data_size} (Gmsh writes 8)")
    with open(path, "rb") as fh:
        data_at = {}
        for key, each in ((b"$Nodes", 4 + 3 * data_size), (b"$Elements", 8)):
            fh.seek(0)
            pos, tail = 0, b""
            found = -1
            while True:                                    # the keyword, in 4 MB blocks
                block = fh.read(1 << 22)
                if not block:
                    break
                hit = (tail + block).find(key + b"\n")
                if hit >= 0:
                    found = pos - len(tail) + hit
                    break
                tail = block[-16:]
                pos += len(block)
            if found < 0:
                raise MeshFileError(f"{path}: binary .msh without a {key.decode()} section")
            fh.seek(found + len(key) + 1)
            line = fh.readline(40)
            try:
                n = int(line.split()[0])
            except (IndexError, ValueError):
                raise MeshFileError(f"{path}: {key.decode()} is not followed by its count "
                                    f"({line[:20]!r})") from None
            rest = size - fh.tell()
            if n < 0 or n * each > rest:
                raise MeshFileError(f"{path}: section {key.decode()} declares {n} records, which need "
                                    f"at least {n * each} bytes, the file has {rest} more "
                                    f"(truncated or corrupt)")
            data_at[key] = n
    return data_at


def _check_keyword_counts(path, size):
    """.mesh / .msh: a count after a section keyword (``Vertices``, ``$Nodes``, ...) must
    not exceed the lines that follow (libigl allocates what the count says); a binary
    ``.msh``: against the bytes that follow (:func:`_check_msh_binary`)."""
    if path.suffix.lower() == ".msh":
        data_size = _msh_binary_header(path)
        if data_size is not None:
            _check_msh_binary(path, size, data_size)
            return
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


def _check_input_file_any(path):
    if not path.exists():
        raise MeshFileError(f"{path}: no such file")
    if not path.is_file():
        raise MeshFileError(f"{path}: not a regular file")
