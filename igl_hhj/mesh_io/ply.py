"""PLY headers and the checks of a PLY body against them, before libigl reads it.

libigl 2.6's PLY reader (tinyply) aborts or returns garbage on headers that declare
an element or a property twice, on properties read together with different types, on
bodies shorter than the header says and on polygons; :func:`_check_ply` finds each of
these first and names it.
"""
from __future__ import annotations

import numpy as np

from ..errors import MeshFileError
from .scan import _Lines, _check_rows, _first_bad, _too_short


_PLY_HEADER_MAX = 1 << 26           # a PLY header may be long (comments), not unbounded
_PLY_SIZES = {"char": 1, "int8": 1, "uchar": 1, "uint8": 1, "short": 2, "int16": 2,
              "ushort": 2, "uint16": 2, "int": 4, "int32": 4, "uint": 4, "uint32": 4,
              "float": 4, "float32": 4, "double": 8, "float64": 8}


def _ply_scalar(order, t):
    """The numpy dtype string of PLY scalar type ``t`` in byte order ``order`` ("<" or ">")."""
    kind = "f" if t in ("float", "float32", "double", "float64") else ("u" if t.startswith("u") else "i")
    return order + kind + str(_PLY_SIZES[t])


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
