"""Triangle meshes with data as VTK files, written with numpy alone.

Three forms, chosen by the extension of the path:

* ``.vtp``: VTK XML PolyData, the surface format of pyvista and ParaView;
* ``.vtu``: VTK XML UnstructuredGrid (triangle cells);
* ``.vtk``: legacy VTK (binary, ``DATASET UNSTRUCTURED_GRID``, version 4.2: the
  form every VTK reader since VTK 4 and meshio read).

Per-vertex arrays become point data, per-face arrays cell data.  A ``(n,)``
array is one component, ``(n, k)`` has ``k`` components, a ``(n, 3, 3)``
tensor is written as 9 components (row-major, VTK's tensor layout; ParaView
shows it as a tensor, pyvista reads it back as ``(n, 9)``); values are
written as float64.  One scalar array
per location is marked *active* (XML ``Scalars=`` attribute, the first
``SCALARS`` section of a legacy file): what ParaView and ``pyvista.plot()``
colour by without being told; 3-vectors and 3×3 tensors are likewise the
active ``Vectors`` / ``Tensors`` when there is one of them.

The XML files hold their arrays inline as base64 binary (``UInt64`` size
headers, little endian, no compression), the legacy file as big-endian
binary, so values round-trip exactly (NaN included).

Examples
--------
>>> import numpy as np
>>> from igl_hhj import vtk_files
>>> V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
>>> vtk_files.write_vtk("tri.vtp", V, F, point_data={"u": V[:, 0]}, scalars="u")  # doctest: +SKIP
"""
from __future__ import annotations

import base64
import os
from pathlib import Path
from typing import Any, Mapping

import numpy as np

__all__ = ["VTK_EXTENSIONS", "write_vtk", "read_vtk", "NotWrittenHere"]

VTK_EXTENSIONS = (".vtp", ".vtu", ".vtk")
"""Extensions :func:`write_vtk` writes."""

_VTK_TRIANGLE = 5


def _components(name, a, n):
    """``a`` as a C-contiguous (n, k) float64 array; tensors (n, 3, 3) -> (n, 9)."""
    a = np.asarray(a)
    if a.ndim == 0 or len(a) != n:
        raise ValueError(f"array {name!r} has shape {a.shape}: its first axis must have {n} entries")
    if not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)
            or a.dtype == np.bool_):
        raise TypeError(f"array {name!r} must be numeric, got dtype {a.dtype}")
    a = a.astype(np.float64, copy=False)
    return np.ascontiguousarray(a.reshape(n, -1) if a.ndim != 1 else a[:, None])


def _fields(data, n, where):
    out = {}
    for name, a in (data or {}).items():
        name = str(name)
        if not name or any(c in name for c in "\"<>&\n"):
            raise ValueError(f"{where} array name {name!r}: must be non-empty, without quotes, <, >, & "
                             f"or line breaks")
        out[name] = _components(name, a, n)
    return out


def _active(fields, scalars):
    """{"Scalars": name, "Vectors": name, "Tensors": name} of one location's arrays."""
    out = {}
    if scalars is not None and scalars in fields:
        if fields[scalars].shape[1] != 1:
            raise ValueError(f"scalars={scalars!r} must name a one-component array, "
                             f"it has {fields[scalars].shape[1]}")
        out["Scalars"] = scalars
    elif fields:
        first = [k for k, v in fields.items() if v.shape[1] == 1]
        if first:
            out["Scalars"] = first[0]
    for attr, k in (("Vectors", 3), ("Tensors", 9)):
        named = [name for name, v in fields.items() if v.shape[1] == k]
        if named:
            out[attr] = named[0]
    return out


# --------------------------------------------------------------------------- XML
_XML_TYPES = {np.dtype("<f8"): "Float64", np.dtype("<i8"): "Int64", np.dtype("u1"): "UInt8"}


def _data_array(name, a, components=None):
    a = np.ascontiguousarray(a, dtype=a.dtype.newbyteorder("<"))
    raw = a.tobytes()
    blob = base64.b64encode(np.array([len(raw)], dtype="<u8").tobytes() + raw).decode("ascii")
    comps = f' NumberOfComponents="{components}"' if components else ""
    return (f'        <DataArray type="{_XML_TYPES[a.dtype]}" Name="{name}"{comps} format="binary">\n'
            f"          {blob}\n        </DataArray>\n")


def _xml_data(tag, fields, scalars):
    if not fields:
        return f"      <{tag}>\n      </{tag}>\n"
    attrs = "".join(f' {k}="{v}"' for k, v in _active(fields, scalars).items())
    body = "".join(_data_array(name, a, a.shape[1] if a.shape[1] > 1 else None) for name, a in fields.items())
    return f"      <{tag}{attrs}>\n{body}      </{tag}>\n"


def _write_xml(path, V, F, pdata, cdata, scalars, polydata):
    kind = "PolyData" if polydata else "UnstructuredGrid"
    conn = np.ascontiguousarray(F, dtype="<i8").ravel()
    offsets = 3 * np.arange(1, len(F) + 1, dtype="<i8")
    if polydata:
        piece = (f'    <Piece NumberOfPoints="{len(V)}" NumberOfVerts="0" NumberOfLines="0" '
                 f'NumberOfStrips="0" NumberOfPolys="{len(F)}">\n')
        cells = ("      <Polys>\n" + _data_array("connectivity", conn) + _data_array("offsets", offsets)
                 + "      </Polys>\n")
    else:
        piece = f'    <Piece NumberOfPoints="{len(V)}" NumberOfCells="{len(F)}">\n'
        cells = ("      <Cells>\n" + _data_array("connectivity", conn) + _data_array("offsets", offsets)
                 + _data_array("types", np.full(len(F), _VTK_TRIANGLE, dtype="u1")) + "      </Cells>\n")
    text = ('<?xml version="1.0"?>\n'
            f'<VTKFile type="{kind}" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n'
            f"  <{kind}>\n" + piece
            + _xml_data("PointData", pdata, scalars) + _xml_data("CellData", cdata, scalars)
            + "      <Points>\n" + _data_array("Points", np.asarray(V, dtype="<f8"), 3) + "      </Points>\n"
            + cells + "    </Piece>\n" + f"  </{kind}>\n</VTKFile>\n")
    with open(path, "w", encoding="ascii") as fh:
        fh.write(text)


# --------------------------------------------------------------------------- legacy
def _legacy_data(fh, header, fields, scalars):
    if not fields:
        return
    fh.write(f"{header}\n".encode("ascii"))
    active = _active(fields, scalars).get("Scalars")
    order = ([active] if active else []) + [k for k in fields if k != active]
    for name in order:
        a = fields[name]
        k = a.shape[1]
        typ = "double"
        if k == 1:
            fh.write(f"SCALARS {name} {typ} 1\nLOOKUP_TABLE default\n".encode("ascii"))
        elif k == 3:
            fh.write(f"VECTORS {name} {typ}\n".encode("ascii"))
        elif k == 9:
            fh.write(f"TENSORS {name} {typ}\n".encode("ascii"))
        else:
            fh.write(f"SCALARS {name} {typ} {k}\nLOOKUP_TABLE default\n".encode("ascii"))
        fh.write(a.astype(a.dtype.newbyteorder(">")).tobytes())
        fh.write(b"\n")


def _write_legacy(path, V, F, pdata, cdata, scalars, title):
    n = len(F)
    cells = np.column_stack([np.full(n, 3), F]).astype(">i4")
    with open(path, "wb") as fh:
        fh.write(f"# vtk DataFile Version 4.2\n{title[:255]}\nBINARY\nDATASET UNSTRUCTURED_GRID\n"
                 f"POINTS {len(V)} double\n".encode("ascii"))
        fh.write(np.asarray(V, dtype=">f8").tobytes())
        fh.write(f"\nCELLS {n} {4 * n}\n".encode("ascii"))
        fh.write(cells.tobytes())
        fh.write(f"\nCELL_TYPES {n}\n".encode("ascii"))
        fh.write(np.full(n, _VTK_TRIANGLE, dtype=">i4").tobytes())
        fh.write(b"\n")
        _legacy_data(fh, f"CELL_DATA {n}", cdata, scalars)
        _legacy_data(fh, f"POINT_DATA {len(V)}", pdata, scalars)


def write_vtk(path: str | os.PathLike, V: Any, F: Any, *, point_data: Mapping[str, Any] | None = None,
              cell_data: Mapping[str, Any] | None = None, scalars: str | None = None,
              title: str = "igl_hhj") -> None:
    """Write a triangle mesh and its per-vertex / per-face arrays as ``.vtp``, ``.vtu`` or ``.vtk``.

    Parameters
    ----------
    path : str or os.PathLike, extension one of :data:`VTK_EXTENSIONS` (case-insensitive)
    V : (#V, 3) array_like float, F : (#F, 3) array_like int
    point_data, cell_data : dict name -> (#V, ...) / (#F, ...) array, optional
        ``(n,)`` scalars, ``(n, k)`` k-component arrays, ``(n, 3, 3)`` tensors
        (written as 9 components).
    scalars : str, optional
        The array to make the active scalars (of whichever location has it);
        default: the first one-component array of each location.
    title : str
        The legacy file's title line (``.vtk`` only).

    Raises
    ------
    ValueError
        Unknown extension, an array whose first axis is not #V / #F, a bad name,
        ``scalars`` naming a multi-component array.
    TypeError
        A non-numeric array.
    """
    ext = Path(path).suffix.lower()
    if ext not in VTK_EXTENSIONS:
        raise ValueError(f"{path}: not a VTK extension {Path(path).suffix!r} (use {', '.join(VTK_EXTENSIONS)})")
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"V must be (#V, 3), got shape {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3 or not np.issubdtype(F.dtype, np.integer):
        raise ValueError(f"F must be (#F, 3) integer, got shape {F.shape} dtype {F.dtype}")
    pdata = _fields(point_data, len(V), "point")
    cdata = _fields(cell_data, len(F), "cell")
    if scalars is not None and scalars not in pdata and scalars not in cdata:
        raise ValueError(f"scalars={scalars!r} is not one of the arrays "
                         f"({', '.join(list(pdata) + list(cdata)) or 'none'})")
    if ext == ".vtk":
        _write_legacy(path, V, F, pdata, cdata, scalars, " ".join(title.split()) or "igl_hhj")
    else:
        _write_xml(path, V, F, pdata, cdata, scalars, polydata=ext == ".vtp")


# --------------------------------------------------------------------------- reading back
class NotWrittenHere(ValueError):
    """A VTK file in a layout :func:`write_vtk` does not write (compressed, appended, ascii,
    other types): read it with pyvista or meshio instead."""


def _base64_array(path, text, dtype, count):
    """A ``format="binary"`` DataArray body: base64 of a UInt64 byte count, then the bytes."""
    try:
        raw = base64.b64decode("".join(text.split()), validate=True)
    except ValueError:
        raise ValueError(f"{path}: a DataArray is not valid base64") from None
    if len(raw) < 8:
        raise ValueError(f"{path}: a DataArray is shorter than its size header")
    nbytes = int(np.frombuffer(raw[:8], dtype="<u8")[0])
    dt = np.dtype(dtype)
    if nbytes != len(raw) - 8 or nbytes != count * dt.itemsize:
        raise ValueError(f"{path}: a DataArray holds {len(raw) - 8} bytes, its header says {nbytes}, "
                         f"the counts of the file need {count * dt.itemsize}")
    return np.frombuffer(raw, dtype=dt, offset=8, count=count).copy()


_READ_TYPES = {"Float64": "<f8", "Int64": "<i8", "UInt8": "u1"}


def _read_xml(path, polydata):
    import xml.etree.ElementTree as ET
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ValueError(f"{path}: not well-formed XML ({exc})") from None
    kind = "PolyData" if polydata else "UnstructuredGrid"
    a = root.attrib
    if (root.tag != "VTKFile" or a.get("type") != kind or a.get("header_type") != "UInt64"
            or a.get("byte_order") != "LittleEndian" or "compressor" in a):
        raise NotWrittenHere(path)
    pieces = root.findall(f"{kind}/Piece")
    if len(pieces) != 1:
        raise NotWrittenHere(path)
    piece = pieces[0]

    def count(name):
        try:
            n = int(piece.get(name, "0"))
        except ValueError:
            raise ValueError(f"{path}: {name}={piece.get(name)!r} is not a count") from None
        if n < 0:
            raise ValueError(f"{path}: negative {name}")
        return n

    nV = count("NumberOfPoints")
    if polydata:
        if any(count(k) for k in ("NumberOfVerts", "NumberOfLines", "NumberOfStrips")):
            raise NotWrittenHere(path)
        nF = count("NumberOfPolys")
    else:
        nF = count("NumberOfCells")

    def array(el, n):
        if el is None or el.get("format") != "binary" or el.get("type") not in _READ_TYPES:
            raise NotWrittenHere(path)
        try:
            k = int(el.get("NumberOfComponents", "1"))
        except ValueError:
            raise ValueError(f"{path}: NumberOfComponents is not a count") from None
        if k < 1:
            raise ValueError(f"{path}: NumberOfComponents {k}")
        out = _base64_array(path, el.text or "", _READ_TYPES[el.get("type")], n * k)
        return out.reshape(n, k) if k > 1 else out

    V = array(piece.find("Points/DataArray"), nV)
    V = V.reshape(nV, -1) if nV else np.zeros((0, 3))
    cells = piece.find("Polys" if polydata else "Cells")
    if cells is None:
        raise NotWrittenHere(path)
    named = {el.get("Name"): el for el in cells.findall("DataArray")}
    conn = array(named.get("connectivity"), 3 * nF)
    offsets = array(named.get("offsets"), nF)
    if not np.array_equal(offsets, 3 * np.arange(1, nF + 1)):
        raise NotWrittenHere(path)                            # polygons other than triangles
    if not polydata and not (array(named.get("types"), nF) == _VTK_TRIANGLE).all():
        raise NotWrittenHere(path)
    data = []
    for tag, n in (("PointData", nV), ("CellData", nF)):
        el = piece.find(tag)
        fields = {}
        for da in (el.findall("DataArray") if el is not None else []):
            fields[str(da.get("Name"))] = array(da, n)
        data.append((fields, el.get("Scalars") if el is not None else None))
    return V, conn.reshape(nF, 3), data


def _read_legacy(path):
    size = os.path.getsize(path)
    with open(path, "rb") as fh:
        def line():
            text = fh.readline(300)
            if not text:
                raise ValueError(f"{path}: the file ends before its data")
            return text.decode("ascii", "replace").split()

        head = [fh.readline(300) for _ in range(4)]
        if (not head[0].startswith(b"# vtk DataFile") or head[2].strip() != b"BINARY"
                or head[3].split() != [b"DATASET", b"UNSTRUCTURED_GRID"]):
            raise NotWrittenHere(path)

        def block(dtype, n):
            nbytes = n * np.dtype(dtype).itemsize
            if n < 0 or nbytes > size - fh.tell():
                raise ValueError(f"{path}: a section declares {n} values, more than the file holds")
            out = np.frombuffer(fh.read(nbytes), dtype=dtype).copy()
            fh.readline(2)                                   # the line break after the block
            return out

        def number(word):
            try:
                return int(word)
            except ValueError:
                raise ValueError(f"{path}: {word!r} is not a count") from None

        w = line()
        if w[:1] != ["POINTS"] or len(w) != 3 or w[2] != "double":
            raise NotWrittenHere(path)
        nV = number(w[1])
        V = block(">f8", 3 * nV).reshape(nV, 3)
        w = line()
        if w[:1] != ["CELLS"] or len(w) != 3:
            raise NotWrittenHere(path)
        nF = number(w[1])
        if number(w[2]) != 4 * nF:
            raise NotWrittenHere(path)
        cells = block(">i4", 4 * nF).reshape(nF, 4)
        if nF and (cells[:, 0] != 3).any():
            raise NotWrittenHere(path)
        w = line()
        if w[:1] != ["CELL_TYPES"] or number(w[1]) != nF or not (block(">i4", nF) == _VTK_TRIANGLE).all():
            raise NotWrittenHere(path)
        data = {"CELL_DATA": ({}, None), "POINT_DATA": ({}, None)}
        where, n = None, 0
        while True:
            text = fh.readline(300)
            if not text:
                break
            w = text.decode("ascii", "replace").split()
            if not w:
                continue
            if w[0] in data and len(w) == 2:
                where, n = w[0], number(w[1])
                if n != (nF if where == "CELL_DATA" else nV):
                    raise ValueError(f"{path}: {w[0]} {n} does not match the mesh")
                continue
            if where is None or len(w) < 3 or w[2] != "double":
                raise NotWrittenHere(path)
            fields, active = data[where]
            if w[0] == "SCALARS":
                k = number(w[3]) if len(w) > 3 else 1
                if line() != ["LOOKUP_TABLE", "default"]:
                    raise NotWrittenHere(path)
                if active is None and k == 1:
                    data[where] = (fields, w[1])
            elif w[0] in ("VECTORS", "TENSORS"):
                k = 3 if w[0] == "VECTORS" else 9
            else:
                raise NotWrittenHere(path)
            if k < 1:
                raise ValueError(f"{path}: {k} components")
            a = block(">f8", n * k)
            fields[w[1]] = a if k == 1 else a.reshape(n, k)
    return V, cells[:, 1:], [data["POINT_DATA"], data["CELL_DATA"]]


def read_vtk(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray, list]:
    """Read back a file :func:`write_vtk` wrote, with numpy alone (no VTK, pyvista or meshio).

    Parameters
    ----------
    path : str or os.PathLike, ``.vtp``, ``.vtu`` or ``.vtk``

    Returns
    -------
    V : (#V, 3) float64
    F : (#F, 3) int64
    data : [(point_data, active point scalars), (cell_data, active cell scalars)]
        dicts name -> (n,) or (n, k) float64 / int64 arrays; the active names or None.

    Raises
    ------
    NotWrittenHere
        A layout :func:`write_vtk` does not write (read it with pyvista or meshio).
    ValueError
        A damaged file: counts that do not match the data, invalid base64 or XML.
    """
    ext = Path(path).suffix.lower()
    if ext not in VTK_EXTENSIONS:
        raise ValueError(f"{path}: not a VTK extension {Path(path).suffix!r} (use {', '.join(VTK_EXTENSIONS)})")
    V, F, data = _read_legacy(path) if ext == ".vtk" else _read_xml(path, polydata=ext == ".vtp")
    V = np.asarray(V, dtype=np.float64)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"{path}: points are not 3D (shape {V.shape})")
    return V, np.asarray(F, dtype=np.int64), data
