"""Polygon meshes: the formats libigl does not read, and the one rule that splits polygons.

libigl 2.6 reads ``.obj .off .ply .stl .wrl .mesh .msh`` (:func:`igl_hhj.mesh_io.read_mesh`
guards it).  This module reads the rest through optional packages, imported only
when such a file is read:

==============  ===========================================  ==================
extension       what                                         read with
==============  ===========================================  ==================
``.gltf .glb``  glTF 2.0 (scenes flattened, transforms       trimesh
                applied)
``.3mf``        3D Manufacturing Format                      trimesh (+ lxml)
``.vtp``        VTK XML PolyData                             pyvista
``.vtu .vtk``   VTK XML UnstructuredGrid, legacy VTK         pyvista, else meshio
``.ply``        a PLY with quads or other polygons (libigl    pyvista
                aborts on them; triangle PLYs stay with
                libigl)
==============  ===========================================  ==================

A missing package is a ``ModuleNotFoundError`` whose message names the file and the
command that installs it (:func:`igl_hhj.errors.install_hint`; all of them are in
the ``io`` extra: ``pip install ".[io]"`` in a checkout).

Splitting polygons
------------------
Every reader hands its faces on as polygons in the compressed form
``(I, C)`` of :func:`igl.polygons_to_triangles` (corner indices ``I``, cumulative
sizes ``C``: polygon ``p`` is ``I[C[p]:C[p+1]]``), and every polygon with
``k > 3`` corners becomes the ``k - 2`` triangles of the *fan from its first
corner*,

.. math::  (i_0, i_1, \\dots, i_{k-1}) \\mapsto (i_0, i_{j}, i_{j+1}),\\quad j = 1, \\dots, k-2,

in file order (``igl.polygons_to_triangles``).  It is the rule libigl's own OBJ and
OFF readers apply, so a quad mesh gives the same triangles whatever format it was
stored in (tested); a quad ``(a, b, c, d)`` is split along its diagonal ``a c``.
Triangles are kept as they are.  :class:`PolygonSplit` counts what was split
(``igl-hhj info``: "12 quads split into 24 triangles").
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .capture import CapturedOutput
from .errors import MeshFileError, install_hint

__all__ = ["EXTRA_EXTENSIONS", "SPLIT_RULE", "PolygonSplit", "PolygonMesh", "polygon_split",
           "split_polygons", "read_polygon_mesh"]

EXTRA_EXTENSIONS: dict[str, tuple[str, ...]] = {
    ".gltf": ("trimesh",), ".glb": ("trimesh",), ".3mf": ("trimesh",),
    ".vtp": ("pyvista",), ".vtu": ("pyvista", "meshio"), ".vtk": ("pyvista", "meshio"),
}
"""Extension -> the optional packages that read it, in order of preference."""

SPLIT_RULE = "fan from each polygon's first corner, as libigl's OBJ/OFF readers"
"""How polygons with more than three corners become triangles (:func:`split_polygons`)."""

_NAMES = {4: "quad", 5: "pentagon", 6: "hexagon"}

# VTK cell types of surface cells
_VTK_TRIANGLE, _VTK_POLYGON, _VTK_QUAD = 5, 7, 9
_VTK_SURFACE = (_VTK_TRIANGLE, _VTK_POLYGON, _VTK_QUAD)
_VTK_NAMES = {1: "vertex", 2: "poly_vertex", 3: "line", 4: "poly_line", 6: "triangle_strip",
              8: "pixel", 10: "tetra", 11: "voxel", 12: "hexahedron", 13: "wedge", 14: "pyramid"}


def _plural(n, name):
    return f"{n} {name}" + ("" if n == 1 else ("es" if name.endswith("x") else "s"))


@dataclass(frozen=True)
class PolygonSplit:
    """What splitting a polygon mesh into triangles did.

    Attributes
    ----------
    corners : dict {k: count}
        Number of faces of the file with ``k`` corners (triangles included).
    """

    corners: dict = field(default_factory=dict)

    @property
    def n_polygons(self) -> int:
        """Faces of the file (all corner counts)."""
        return int(sum(self.corners.values()))

    @property
    def n_quads(self) -> int:
        """Faces with four corners."""
        return int(self.corners.get(4, 0))

    @property
    def n_split(self) -> int:
        """Faces with more than three corners (the ones split)."""
        return int(sum(n for k, n in self.corners.items() if k > 3))

    @property
    def n_triangles(self) -> int:
        """Triangles after the split: ``sum (k - 2)`` over the faces."""
        return int(sum((k - 2) * n for k, n in self.corners.items()))

    @property
    def n_from_split(self) -> int:
        """Triangles made from the split faces: ``sum (k - 2)`` over ``k > 3``."""
        return int(sum((k - 2) * n for k, n in self.corners.items() if k > 3))

    def describe(self) -> str:
        """One line, e.g. ``"12 quads split into 24 triangles"`` (empty when nothing was split)."""
        if not self.n_split:
            return ""
        parts = [_plural(n, _NAMES.get(k, f"{k}-gon")) for k, n in sorted(self.corners.items()) if k > 3]
        kept = self.corners.get(3, 0)
        return (", ".join(parts) + f" split into {self.n_from_split} triangles ({SPLIT_RULE})"
                + (f"; {_plural(kept, 'triangle')} kept" if kept else ""))


def polygon_split(sizes: Any) -> PolygonSplit:
    """:class:`PolygonSplit` of faces with ``sizes[p]`` corners ((#P,) int)."""
    k, n = np.unique(np.asarray(sizes, dtype=np.int64), return_counts=True)
    return PolygonSplit({int(a): int(b) for a, b in zip(k, n)})


def split_polygons(I: Any, C: Any) -> tuple[NDArray[np.int64], NDArray[np.int64], PolygonSplit]:
    """Triangles of a polygon mesh: the fan from each polygon's first corner.

    Parameters
    ----------
    I : (#I,) int, corner indices of all polygons one after the other
    C : (#P + 1,) int, cumulative sizes, ``C[0] = 0``: polygon ``p`` is ``I[C[p]:C[p+1]]``

    Returns
    -------
    F : (#F, 3) int64, ``#F = sum (k_p - 2)``, the triangles of each polygon consecutive
        and in polygon order (``igl.polygons_to_triangles``)
    J : (#F,) int64, the polygon each triangle comes from
    split : PolygonSplit

    Raises
    ------
    ValueError
        ``C`` not starting at 0, decreasing, not ending at ``len(I)``, or a polygon
        with fewer than 3 corners.
    """
    I = np.ascontiguousarray(I, dtype=np.int64).ravel()
    C = np.ascontiguousarray(C, dtype=np.int64).ravel()
    if C.size < 1 or C[0] != 0 or C[-1] != I.size:
        raise ValueError(f"C must run from 0 to len(I) = {I.size}, got {C[:1].tolist()} ... {C[-1:].tolist()}")
    sizes = np.diff(C)
    if (sizes < 3).any():
        p = int(np.flatnonzero(sizes < 3)[0])
        raise ValueError(f"polygon {p} has {int(sizes[p])} corners (a face needs at least 3)")
    split = polygon_split(sizes)
    if sizes.size and (sizes == 3).all():                 # triangles: nothing to split
        return I.reshape(-1, 3), np.arange(sizes.size, dtype=np.int64), split
    import igl
    F, J = igl.polygons_to_triangles(I, C)
    return np.asarray(F, dtype=np.int64), np.asarray(J, dtype=np.int64), split


@dataclass
class PolygonMesh:
    """A polygon mesh read by :func:`read_polygon_mesh`.

    Attributes
    ----------
    V : (#V, 3) float64
    I, C : polygons in the form of :func:`split_polygons`
    point_data : dict name -> (#V, ...) array
    cell_data : dict name -> (#P, ...) array, one row per polygon
    reader : str, the package that read the file
    active_scalars : str or None, the array the file marks active (pyvista only)
    messages : list of str, what was dropped or merged while reading
    """

    V: NDArray[np.float64]
    I: NDArray[np.int64]
    C: NDArray[np.int64]
    point_data: dict = field(default_factory=dict)
    cell_data: dict = field(default_factory=dict)
    reader: str = ""
    messages: list = field(default_factory=list)
    active_scalars: str | None = None


def _import(package, path):
    """Import an optional reader package; a ModuleNotFoundError naming the file and the fix."""
    import importlib
    try:
        return importlib.import_module(package)
    except ModuleNotFoundError as exc:
        missing = (exc.name or package).split(".")[0]
        raise ModuleNotFoundError(f"{path}: reading {Path(path).suffix} files needs {missing}: "
                                  f"{install_hint(missing)}", name=missing) from None


_FORMATS = {".gltf": "glTF file", ".glb": "binary glTF (.glb) file", ".3mf": "3MF file",
            ".vtp": "VTK XML PolyData (.vtp) file", ".vtu": "VTK XML UnstructuredGrid (.vtu) file",
            ".vtk": "legacy VTK (.vtk) file", ".ply": "PLY file"}

_KINDS = {AssertionError: "a consistency check of the reader failed",
          IndexError: "an index or count points past the data the file holds",
          KeyError: "a required entry is missing",
          StopIteration: "the file ends before the data its header announces",
          EOFError: "the file ends before the data its header announces",
          UnicodeError: "text that is not valid UTF-8 / ASCII",
          TypeError: "a value has the wrong type", AttributeError: "an element is missing or has the wrong kind",
          OverflowError: "a count or size is too large", ZeroDivisionError: "a zero size or count"}


def _error(path, exc, reader=None):
    """A :class:`MeshFileError` naming the file, its format and the parser's complaint in words.

    Parsers raise many kinds of exception, some with one word or none (``AssertionError``,
    ``list index out of range``, ``StopIteration``): the message always says what kind of
    problem it is, then the parser's own text when it has one."""
    path = Path(path)
    what = _FORMATS.get(path.suffix.lower(), f"{path.suffix} file")
    text = " ".join(str(exc).split())
    kind = next((v for k, v in _KINDS.items() if isinstance(exc, k)), None)
    if kind is None:
        kind = "the file is corrupt or not a valid " + what
    by = f" ({reader})" if reader else ""
    detail = f": {text[:200]}" if len(text.split()) > 3 else (f" ({type(exc).__name__}: {text[:100]})"
                                                              if text else f" ({type(exc).__name__})")
    return MeshFileError(f"{path}: could not read this {what}{by}: {kind}{detail}")


def read_polygon_mesh(path: str | os.PathLike, readers: tuple[str, ...] | None = None) -> PolygonMesh:
    """Read a mesh in one of :data:`EXTRA_EXTENSIONS` (or a polygon ``.ply``) as polygons.

    Parameters
    ----------
    path : str or os.PathLike
    readers : tuple of package names, optional
        Which packages to try (default: those of :data:`EXTRA_EXTENSIONS`, for
        ``.ply`` pyvista); the first importable one reads the file.

    Returns
    -------
    PolygonMesh

    Raises
    ------
    ModuleNotFoundError
        None of the packages is installed (the message names the install command).
    igl_hhj.errors.MeshFileError (also igl_hhj.mesh_io.MeshFileError)
        The package could not read the file, or it holds no surface cells.
    """
    path = Path(path)
    ext = path.suffix.lower()
    if readers is None:
        readers = EXTRA_EXTENSIONS.get(ext, ("pyvista",))
    import importlib
    chosen = readers[0]
    for r in readers:
        try:
            importlib.import_module(r)
        except ImportError:
            continue
        chosen = r
        break
    read = {"trimesh": _read_trimesh, "pyvista": _read_pyvista, "meshio": _read_meshio}.get(chosen)
    if read is None:
        raise ValueError(f"unknown reader {chosen!r} (use trimesh, pyvista or meshio)")
    _import(chosen, path)                 # imported here: the child process only parses
    if chosen == "pyvista":
        _warm_pyvista(path)
    return _in_child_process(read, path, chosen)


# ----------------------------------------------------------------------------- isolation
ISOLATE_READERS = True
"""Parse with the third-party packages in a forked child process (:func:`_in_child_process`).
Costs about one ``fork`` per file (measured in igl_hhj/docs/io.md); False parses in this
process, where a hostile file can crash it."""

READER_MEMORY = (8, 1 << 30)
"""``(a, b)``: a child process parsing a file of ``s`` bytes may grow its address space by
``a * s + b`` bytes (an ascii file's numbers take up to 4x its bytes as float64; VTK and
the Python wrappers reserve a few hundred MB).  A file declaring more than that is refused
with a :class:`MeshFileError` instead of exhausting the machine's memory."""


READER_SECONDS = (60, 1 << 20)
"""``(t, r)``: a child process parsing a file of ``s`` bytes is killed after ``t + s / r``
seconds (60 s, plus one per MB, which a slow parser of a large ascii file stays within): a
parser that loops on a hostile file, or a child that deadlocks after ``fork`` in a process
with threads, becomes a :class:`MeshFileError` instead of a hang of the caller."""


def _reader_seconds(size):
    return int(READER_SECONDS[0] + -(-size // READER_SECONDS[1]))


_VTK_MODULES = ("vtkmodules.util.numpy_support", "vtkmodules.vtkIOXML", "vtkmodules.vtkIOXMLParser",
                "vtkmodules.vtkIOLegacy", "vtkmodules.vtkIOCore", "vtkmodules.vtkIOPLY")
"""Modules pyvista imports lazily on its first read."""

_warmed: set = set()


def _warm_pyvista(path):
    """Once per process, before the first fork: import what pyvista imports lazily and let it
    scan its reader plug-ins (``importlib.metadata`` entry points, ~60 ms) by reading a
    one-triangle file written here, so that the forked children, which lose whatever they
    initialise, do not pay that on every file."""
    if "pyvista" in _warmed:
        return
    for module in _VTK_MODULES:
        _import(module, path)
    import tempfile
    from .vtk_files import write_vtk
    pv = _import("pyvista", path)
    with tempfile.TemporaryDirectory(prefix="igl_hhj_warm_") as tmp:
        tiny = os.path.join(tmp, "tiny.vtp")
        write_vtk(tiny, np.eye(3), np.array([[0, 1, 2]]))
        with CapturedOutput():
            pv.read(tiny)
    _warmed.add("pyvista")


def _vm_size():
    """The address space of this process in bytes (Linux ``/proc``), or None."""
    try:
        with open("/proc/self/status", "rb") as fh:
            for line in fh:
                if line.startswith(b"VmSize:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _limit_memory(size):
    try:
        import resource
    except ImportError:                                    # not a POSIX system
        return
    vm = _vm_size()
    if vm is None:
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = vm + READER_MEMORY[0] * size + READER_MEMORY[1]
    for limit in (soft, hard):
        if limit != resource.RLIM_INFINITY:
            cap = min(cap, limit)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))


def _child_result(read, path):
    """What the child sends back: ("ok", PolygonMesh) or (exception class name, message, name)."""
    try:
        return ("ok", read(path))
    except MeshFileError as exc:
        return ("MeshFileError", str(exc), None)
    except ModuleNotFoundError as exc:
        return ("ModuleNotFoundError", str(exc), exc.name)
    except MemoryError:
        return ("MeshFileError", f"{path}: could not read it: {_FORMATS.get(path.suffix.lower(), 'the file')} "
                                 f"declares more data than fits in memory (the file is corrupt or "
                                 f"its counts are larger than its contents)", None)
    except Exception as exc:                                # a reader bug: still a sentence
        return ("MeshFileError", str(_error(path, exc)), None)


def _in_child_process(read, path, reader):
    """``read(path)`` in a forked child process with a memory cap (:data:`READER_MEMORY`).

    Third-party parsers (VTK above all) abort or segfault on hostile files and
    allocate whatever a header declares; in a child, a crash or an exhausted memory
    cap becomes a :class:`MeshFileError` naming the file, the format and what happened,
    and this process is untouched.  The result comes back pickled through a pipe.
    Without ``os.fork`` (Windows) the file is parsed in this process.
    """
    import pickle
    import signal
    import warnings
    if not ISOLATE_READERS or not hasattr(os, "fork"):
        return read(path)
    size = path.stat().st_size
    seconds = _reader_seconds(size)
    r, w = os.pipe()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)   # fork with threads (Python 3.12)
        pid = os.fork()
    if pid == 0:                                           # the child: parse, send, exit
        code = 1
        try:
            os.close(r)
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, 1)                               # a crash's last words stay quiet
            os.dup2(null, 2)
            import faulthandler
            faulthandler.disable()                         # its own copy of stderr: quiet too
            _limit_memory(size)
            signal.signal(signal.SIGALRM, signal.SIG_DFL)  # the alarm kills, whatever the parser does
            signal.alarm(seconds)
            data = pickle.dumps(_child_result(read, path), protocol=pickle.HIGHEST_PROTOCOL)
            with os.fdopen(w, "wb") as fh:
                fh.write(data)
            code = 0
        finally:
            os._exit(code)
    os.close(w)
    chunks = []
    with os.fdopen(r, "rb") as fh:
        while True:
            block = fh.read(1 << 20)
            if not block:
                break
            chunks.append(block)
    _, status = os.waitpid(pid, 0)
    what = _FORMATS.get(path.suffix.lower(), f"{path.suffix} file")
    if os.WIFSIGNALED(status) or os.WEXITSTATUS(status) != 0 or not chunks:
        if os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGALRM:
            raise MeshFileError(f"{path}: could not read it: {reader} did not finish this {what} "
                                f"within {seconds} s (a parser that loops on a corrupt file): "
                                f"the file is corrupt or truncated")
        if os.WIFSIGNALED(status):
            sig = os.WTERMSIG(status)
            try:
                how = f"it crashed ({signal.Signals(sig).name})"
            except ValueError:
                how = f"it was killed by signal {sig}"
        else:
            how = "it stopped without an answer (out of memory?)"
        raise MeshFileError(f"{path}: could not read it: {reader} failed on this {what}: {how}; "
                            f"the file is corrupt, truncated or declares more data than it holds")
    result = pickle.loads(b"".join(chunks))
    if result[0] == "ok":
        return result[1]
    kind, message, name = result
    if kind == "ModuleNotFoundError":
        raise ModuleNotFoundError(message, name=name)
    raise MeshFileError(message)


def _triangles(F):
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    return F.ravel(), np.arange(0, F.size + 1, 3, dtype=np.int64)


def _read_trimesh(path):
    trimesh = _import("trimesh", path)
    try:
        with CapturedOutput():
            mesh = trimesh.load(str(path), force="mesh", process=False)
    except ModuleNotFoundError as exc:                      # lxml, networkx for 3MF
        missing = (exc.name or "lxml").split(".")[0]
        raise ModuleNotFoundError(f"{path}: reading {path.suffix} files needs {missing}: "
                                  f"{install_hint(missing)}", name=missing) from None
    except Exception as exc:                               # trimesh raises many kinds
        raise _error(path, exc, "trimesh") from None
    V = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64)
    F = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    I, C = _triangles(F)
    return PolygonMesh(V, I, C, reader=f"trimesh {trimesh.__version__}")


def _cell_array(offsets, connectivity):
    return (np.asarray(connectivity, dtype=np.int64).ravel(), np.asarray(offsets, dtype=np.int64).ravel())


def _arrays(data, rows=None):
    out = {}
    for name in data.keys():
        a = np.asarray(data[name])
        if a.ndim == 2 and a.shape[1] == 1:                # meshio's legacy reader: (n, 1) scalars
            a = a[:, 0]
        if a.dtype.kind in "fiub":
            out[str(name)] = a if rows is None else a[rows]
    return out


def _read_pyvista(path):
    pv = _import("pyvista", path)
    from vtkmodules.util.numpy_support import vtk_to_numpy
    import warnings
    try:
        with warnings.catch_warnings(record=True) as caught, CapturedOutput():
            warnings.simplefilter("always")
            ds = pv.read(str(path))
    except Exception as exc:                               # VTK readers raise many kinds
        raise _error(path, exc, "pyvista") from None
    messages = [" ".join(str(w.message).split())[:200] for w in caught]
    if isinstance(ds, pv.MultiBlock):
        ds = ds.combine()
    if not isinstance(ds, (pv.PolyData, pv.UnstructuredGrid)):
        raise MeshFileError(f"{path}: holds a VTK {type(ds).__name__} (a grid of points or cells), not a "
                            f"surface mesh of polygons: extract its surface first (e.g. pyvista's "
                            f"extract_surface()) and save that")
    if isinstance(ds, pv.PolyData):
        polys = ds.GetPolys()
        I, C = _cell_array(vtk_to_numpy(polys.GetOffsetsArray()), vtk_to_numpy(polys.GetConnectivityArray()))
        first = ds.n_verts + ds.n_lines                     # VTK numbers cells verts, lines, polys, strips
        rows = np.arange(first, first + C.size - 1)
        dropped = {"vertex": ds.n_verts, "line": ds.n_lines, "triangle_strip": ds.n_strips}
    else:
        types = np.asarray(ds.celltypes)
        offsets = np.asarray(ds.cell_offsets if hasattr(ds, "cell_offsets") else ds.offset, dtype=np.int64)
        conn = np.asarray(ds.cell_connectivity, dtype=np.int64)
        rows = np.flatnonzero(np.isin(types, _VTK_SURFACE))
        other, n_other = np.unique(types[~np.isin(types, _VTK_SURFACE)], return_counts=True)
        dropped = {_VTK_NAMES.get(int(t), f"type {int(t)}"): int(n) for t, n in zip(other, n_other)}
        sizes = offsets[rows + 1] - offsets[rows]
        C = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        take = np.repeat(offsets[rows], sizes) + (np.arange(C[-1]) - np.repeat(C[:-1], sizes))
        I = conn[take]
    dropped = {k: int(n) for k, n in dropped.items() if n}
    if dropped:
        messages.append("ignored cells that are not polygons: "
                        + ", ".join(f"{n} {k}" for k, n in dropped.items()))
    V = np.asarray(ds.points, dtype=np.float64).reshape(-1, 3)
    active = ds.point_data.active_scalars_name or ds.cell_data.active_scalars_name
    return PolygonMesh(V, I, C, point_data=_arrays(ds.point_data), cell_data=_arrays(ds.cell_data, rows),
                       reader=f"pyvista {pv.__version__}", messages=messages, active_scalars=active)


def _read_meshio(path):
    meshio = _import("meshio", path)
    try:
        with CapturedOutput():
            m = meshio.read(str(path))
    except Exception as exc:                               # meshio raises many kinds
        raise _error(path, exc, "meshio") from None
    keep = [j for j, b in enumerate(m.cells) if b.type in ("triangle", "quad") or b.type.startswith("polygon")]
    dropped = {}
    for j, b in enumerate(m.cells):
        if j not in keep:
            dropped[b.type] = dropped.get(b.type, 0) + len(b.data)
    blocks = [np.asarray(m.cells[j].data, dtype=np.int64) for j in keep]
    I = np.concatenate([b.ravel() for b in blocks]) if blocks else np.zeros(0, dtype=np.int64)
    sizes = np.concatenate([np.full(len(b), b.shape[1]) for b in blocks]) if blocks else np.zeros(0, np.int64)
    C = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    cell_data = {}
    for name, per_block in m.cell_data.items():
        parts = [np.asarray(per_block[j]) for j in keep]
        parts = [p[:, 0] if p.ndim == 2 and p.shape[1] == 1 else p for p in parts]
        if parts and all(p.dtype.kind in "fiub" for p in parts):
            cell_data[str(name)] = np.concatenate(parts)
    messages = []
    if dropped:
        messages.append("ignored cells that are not polygons: "
                        + ", ".join(f"{n} {k}" for k, n in dropped.items()))
    if len({m.cells[j].type for j in keep}) > 1:
        messages.append("meshio groups cells by type: the faces are in that order, not the file's")
    P = np.asarray(m.points, dtype=np.float64)
    if P.ndim == 2 and P.shape[1] == 2:                     # planar meshes: z = 0
        P = np.column_stack([P, np.zeros(len(P))])
    return PolygonMesh(P, I, C, point_data=_arrays(m.point_data), cell_data=cell_data,
                       reader=f"meshio {meshio.__version__}", messages=messages)
