"""A mesh read by rows: vertex and face arrays in memory, in ``.npy`` files or in a
binary PLY, of which a caller holds only the rows it asks for.

Every read opens the memory map and drops it afterwards, so the pages it touched stop
counting in the process's resident memory when the call returns (a map kept open
accumulates them: the whole file, after a pass over it).  Sources are small picklable
objects (paths and layouts), sent to the Dask workers, which read the rows themselves.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .ply import PlyLayout, convert_text_mesh, ply_layout

__all__ = ["MeshSource", "ArraySource", "NpySource", "PlySource", "open_mesh_file", "CHUNK"]

CHUNK = 1 << 20
"""Rows per block of the streaming passes."""


class MeshSource:
    """Rows of ``V`` (float64) and ``F`` (int64, triangles) of a mesh."""

    n_vertices: int
    n_faces: int

    def vertices(self, rows) -> np.ndarray:
        """(m, 3) float64 rows of V (``rows``: a slice or an int array)."""
        raise NotImplementedError

    def faces(self, rows) -> np.ndarray:
        """(m, 3) int64 rows of F."""
        raise NotImplementedError

    def vertex_blocks(self, block=CHUNK):
        """Yield ``(start, V[start:start + block])`` over the vertices."""
        for a in range(0, self.n_vertices, block):
            yield a, self.vertices(slice(a, min(a + block, self.n_vertices)))

    def face_blocks(self, block=CHUNK):
        """Yield ``(start, F[start:start + block])`` over the faces."""
        for a in range(0, self.n_faces, block):
            yield a, self.faces(slice(a, min(a + block, self.n_faces)))


@dataclass
class ArraySource(MeshSource):
    """In-memory arrays (``V`` (#V, 3) float64, ``F`` (#F, 3) int64, validated by the caller)."""

    V: np.ndarray
    F: np.ndarray

    @property
    def n_vertices(self):
        return len(self.V)

    @property
    def n_faces(self):
        return len(self.F)

    def vertices(self, rows):
        return np.asarray(self.V[rows], dtype=np.float64)

    def faces(self, rows):
        return np.asarray(self.F[rows], dtype=np.int64)


@dataclass(frozen=True)
class NpySource(MeshSource):
    """``.npy`` files of V (#V, 3) and F (#F, 3) (any real / integer dtype), memory-mapped per read."""

    v_path: str
    f_path: str
    n_vertices: int
    n_faces: int

    @classmethod
    def open(cls, v_path, f_path):
        V = np.load(v_path, mmap_mode="r")
        F = np.load(f_path, mmap_mode="r")
        if V.ndim != 2 or V.shape[1] != 3:
            raise ValueError(f"{v_path}: V must have shape (#V, 3), got {V.shape}")
        if F.ndim != 2 or F.shape[1] != 3:
            raise ValueError(f"{f_path}: F must have shape (#F, 3) (triangles), got {F.shape}")
        return cls(str(v_path), str(f_path), int(V.shape[0]), int(F.shape[0]))

    def vertices(self, rows):
        V = np.load(self.v_path, mmap_mode="r")
        return np.array(V[rows], dtype=np.float64)

    def faces(self, rows):
        F = np.load(self.f_path, mmap_mode="r")
        return np.array(F[rows], dtype=np.int64)


@dataclass(frozen=True)
class PlySource(MeshSource):
    """The vertex and face records of a binary PLY, memory-mapped where they lie
    (:func:`igl_hhj.tiled.ply.ply_layout`); k-gons read as the fans of their first corner."""

    layout: PlyLayout

    @property
    def n_vertices(self):
        return self.layout.n_vertices

    @property
    def n_faces(self):
        return self.layout.n_faces

    def _records(self, offset, dtype, n):
        return np.memmap(self.layout.path, dtype=dtype, mode="r", offset=offset, shape=(n,))

    def vertices(self, rows):
        L = self.layout
        rec = self._records(L.vertex_offset, L.vertex_dtype, L.n_vertices)[rows]
        return np.stack([rec["x"], rec["y"], rec["z"]], axis=-1).astype(np.float64)

    def faces(self, rows):
        L = self.layout
        rec = self._records(L.face_offset, L.face_dtype, L.n_polygons)
        k = L.corners
        if k == 3:
            return np.array(rec[rows]["idx"], dtype=np.int64)
        t = np.arange(L.n_faces)[rows] if isinstance(rows, slice) else np.asarray(rows, dtype=np.int64)
        p, j = np.divmod(t, k - 2)
        idx = rec[p]["idx"]
        r = np.arange(len(t))
        return np.stack([idx[:, 0], idx[r, j + 1], idx[r, j + 2]], axis=1).astype(np.int64)


def open_mesh_file(path, workdir) -> tuple[MeshSource, str]:
    """A :class:`MeshSource` for a mesh file, and how it is read.

    Binary PLY: in place (``"memory-mapped"``); ascii PLY and OFF: converted in one
    streaming pass to ``.npy`` files in ``workdir`` (``"converted"``); other formats:
    read whole by :func:`igl_hhj.mesh_io.read_mesh` and written to ``workdir``
    (``"read whole"``).
    """
    from ..errors import MeshFileError
    from ..mesh_io import read_mesh
    path = str(path)
    if not os.path.isfile(path):
        raise MeshFileError(f"{path}: no such file")
    ext = Path(path).suffix.lower()
    if ext == ".ply":
        layout = ply_layout(path)
        if layout is not None:
            return PlySource(layout), "memory-mapped"
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    v_out, f_out = str(workdir / "input_V.npy"), str(workdir / "input_F.npy")
    if ext in (".ply", ".off") and convert_text_mesh(path, v_out, f_out) is not None:
        return NpySource.open(v_out, f_out), "converted"
    V, F, _ = read_mesh(path)
    if F.ndim != 2 or F.shape[1] != 3:
        raise MeshFileError(f"{path}: not a triangle mesh (faces of shape {F.shape})")
    np.save(v_out, np.asarray(V, dtype=np.float64))
    np.save(f_out, np.asarray(F, dtype=np.int64))
    return NpySource.open(v_out, f_out), "read whole"
