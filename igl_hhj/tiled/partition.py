"""Spatial partition of a mesh into tiles, in streaming passes over its rows.

The faces are bucketed by their centroid into the cells of a uniform grid (about
:data:`CELLS_PER_TILE` cells per tile), the occupied cells are split by a weighted
k-d tree into boxes of at most ``tile_faces`` faces (a box of one cell may hold
more), and a counting sort writes the face indices tile by tile and cell by cell
(``order.npy``).  Each vertex is *owned* by the lowest-numbered tile among its faces'
(``owner.npy``): the one tile that writes its values.  Memory: the cell tables (a few
numbers per occupied cell) and one block of rows; the per-face and per-vertex arrays
live in memory-mapped files.

A graph partition (METIS and the like) would need the mesh's adjacency in memory;
the grid needs only coordinates, and a tile's neighbourhood is a box of cells
(:meth:`Plan.box_cells`), so a worker loads the faces around its tile without any
global structure.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .source import CHUNK, MeshSource

__all__ = ["Plan", "plan_tiles", "CELLS_PER_TILE", "kd_split"]

CELLS_PER_TILE = 256
"""Target number of grid cells per tile (granularity of the tiles and of their neighbourhoods)."""

MAX_GRID = 1 << 20
"""Largest number of cells along an axis."""


@dataclass
class Plan:
    """Tiles of a mesh (see module docstring), stored in ``directory``.

    Attributes
    ----------
    lo : (3,) grid origin; cell : float, the cells' edge length.
    ijk : (#C, 3) int64 integer coordinates of the occupied cells, in tile order.
    start : (#C + 1,) int64, cell c holds the faces ``order[start[c]:start[c + 1]]``.
    hmax : (#C,) float64, the longest edge of the cell's faces.
    tile_start : (#T + 1,) int64, tile t holds the cells ``tile_start[t]:tile_start[t + 1]``.
    box_lo, box_hi : (#T, 3) int64, the box of the tile's cells (inclusive).
    n_vertices, n_faces : ints of the mesh.
    """

    directory: str
    lo: np.ndarray
    cell: float
    ijk: np.ndarray
    start: np.ndarray
    hmax: np.ndarray
    tile_start: np.ndarray
    box_lo: np.ndarray
    box_hi: np.ndarray
    n_vertices: int
    n_faces: int

    @property
    def n_tiles(self) -> int:
        return len(self.tile_start) - 1

    @property
    def order_path(self) -> str:
        return os.path.join(self.directory, "order.npy")

    @property
    def owner_path(self) -> str:
        return os.path.join(self.directory, "owner.npy")

    def tile_faces(self, t) -> np.ndarray:
        """The face indices of tile t's core (ascending)."""
        a, b = self.start[self.tile_start[t]], self.start[self.tile_start[t + 1]]
        return np.sort(np.load(self.order_path, mmap_mode="r")[a:b])

    def tile_size(self, t) -> int:
        return int(self.start[self.tile_start[t + 1]] - self.start[self.tile_start[t]])

    def box_cells(self, t, margin) -> np.ndarray:
        """Indices of the cells within ``margin`` cells of tile t's box."""
        lo, hi = self.box_lo[t] - margin, self.box_hi[t] + margin
        return np.flatnonzero(((self.ijk >= lo) & (self.ijk <= hi)).all(axis=1))

    def cells_faces(self, cells) -> np.ndarray:
        """The face indices of the given cells (ascending)."""
        order = np.load(self.order_path, mmap_mode="r")
        parts = [order[self.start[c]:self.start[c + 1]] for c in cells]
        return np.sort(np.concatenate(parts)) if parts else np.zeros(0, dtype=np.int64)

    def owners(self, vertices) -> np.ndarray:
        """The owning tile of each of the given vertices (-1: no face)."""
        return np.array(np.load(self.owner_path, mmap_mode="r")[vertices])

    def save(self):
        np.savez(os.path.join(self.directory, "plan.npz"), lo=self.lo, cell=self.cell, ijk=self.ijk,
                 start=self.start, hmax=self.hmax, tile_start=self.tile_start, box_lo=self.box_lo,
                 box_hi=self.box_hi, sizes=[self.n_vertices, self.n_faces])

    @classmethod
    def load(cls, directory):
        with np.load(os.path.join(directory, "plan.npz")) as z:
            nv, nf = (int(x) for x in z["sizes"])
            return cls(str(directory), z["lo"], float(z["cell"]), z["ijk"], z["start"], z["hmax"],
                       z["tile_start"], z["box_lo"], z["box_hi"], nv, nf)


def kd_split(ijk, weight, limit):
    """Split weighted cells into boxes of total weight ≤ ``limit`` (a single cell may exceed it).

    A box of weight W > limit is cut across its longest axis at the coordinate that
    gives its lower part ``⌊n/2⌋/n`` of W, n = ⌈W / limit⌉ (so the leaves are about
    equally full).  Returns (#C,) int64 leaf numbers in depth-first order."""
    leaf = np.zeros(len(ijk), dtype=np.int64)
    stack = [np.arange(len(ijk))]
    count = 0
    out = []
    while stack:
        idx = stack.pop()
        W = float(weight[idx].sum())
        ext = ijk[idx].max(axis=0) - ijk[idx].min(axis=0)
        if W <= limit or not ext.any():
            out.append(idx)
            continue
        n = math.ceil(W / limit)
        target = W * (n // 2) / n
        for axis in np.argsort(-ext, kind="stable"):
            if ext[axis] == 0:
                continue
            x = ijk[idx, axis]
            vals, inv = np.unique(x, return_inverse=True)
            cum = np.cumsum(np.bincount(inv, weights=weight[idx]))[:-1]     # weight below each cut
            cut = int(np.argmin(np.abs(cum - target)))
            left = x <= vals[cut]
            stack.append(idx[~left])
            stack.append(idx[left])
            break
    for idx in out:
        leaf[idx] = count
        count += 1
    return leaf


def _check_vertices(source, lo, hi):
    """Streaming pass: finite coordinates below COORDINATE_MAX; returns the bounding box."""
    from ..mesh import COORDINATE_MAX
    for a, V in source.vertex_blocks():
        bad = ~np.isfinite(V).all(axis=1) | (np.abs(V) > COORDINATE_MAX).any(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            what = "NaN or inf coordinates" if not np.isfinite(V[i]).all() else \
                f"coordinates beyond {COORDINATE_MAX:g}"
            raise ValueError(f"V has {what}; first at vertex {a + i}: {V[i]}")
        np.minimum(lo, V.min(axis=0), out=lo)
        np.maximum(hi, V.max(axis=0), out=hi)
    return lo, hi


def _check_faces(F, a, nV):
    if F.min(initial=0) < 0:
        i = int(np.flatnonzero((F < 0).any(axis=1))[0])
        raise ValueError(f"F has negative vertex indices; first at face {a + i}: {F[i]} "
                         f"(indices are 0-based positions in V)")
    if F.max(initial=0) >= nV:
        i = int(np.flatnonzero((F >= nV).any(axis=1))[0])
        raise ValueError(f"F has out-of-range vertex indices (#V = {nV}); first at face {a + i}: {F[i]}")


def _face_geometry(source, F):
    """Centroids (m, 3) and longest edges (m,) of the faces F, from the rows they use."""
    u, inv = np.unique(F.ravel(), return_inverse=True)
    X = source.vertices(u)[inv.reshape(F.shape)]
    L = np.sqrt(np.maximum.reduce([((X[:, i] - X[:, (i + 1) % 3]) ** 2).sum(axis=1) for i in range(3)]))
    return X.mean(axis=1), L


def plan_tiles(source: MeshSource, directory, tile_faces, *, progress=None) -> Plan:
    """Partition ``source`` into tiles of about ``tile_faces`` faces (module docstring).

    Raises ``ValueError`` for an empty mesh, non-finite or too large coordinates and
    negative or out-of-range face indices, naming the first offending row."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    nV, nF = source.n_vertices, source.n_faces
    if nV == 0:
        raise ValueError("V is empty: the mesh has no vertices")
    if nF == 0:
        raise ValueError("F is empty: the mesh has no faces")
    lo, hi = _check_vertices(source, np.full(3, np.inf), np.full(3, -np.inf))
    # mean edge length from up to 2^17 faces spread over the file: sets the cell size
    sample = np.unique(np.linspace(0, nF - 1, min(nF, 1 << 17)).astype(np.int64))
    Fs = source.faces(sample)
    _check_faces(Fs, 0, nV)
    u, inv = np.unique(Fs.ravel(), return_inverse=True)
    X = source.vertices(u)[inv.reshape(Fs.shape)]
    h = float(np.mean([np.linalg.norm(X[:, i] - X[:, (i + 1) % 3], axis=1).mean() for i in range(3)]))
    per_cell = max(float(tile_faces) / CELLS_PER_TILE, 16.0)
    extent = float((hi - lo).max())
    cell = max(h * math.sqrt(per_cell / 2.3), extent / (MAX_GRID - 1), 1e-300)
    G = np.minimum(np.floor((hi - lo) / cell).astype(np.int64) + 1, MAX_GRID)
    key_path = directory / "face_key.npy"
    key = np.lib.format.open_memmap(key_path, mode="w+", dtype=np.int64, shape=(nF,))
    keys, counts, hmaxes = [], [], []
    for a, F in source.face_blocks():
        _check_faces(F, a, nV)
        C, L = _face_geometry(source, F)
        q = np.clip(np.floor((C - lo) / cell).astype(np.int64), 0, G - 1)
        k = (q[:, 0] * G[1] + q[:, 1]) * G[2] + q[:, 2]
        key[a:a + len(F)] = k
        uk, ui = np.unique(k, return_inverse=True)
        keys.append(uk)
        counts.append(np.bincount(ui, minlength=len(uk)))
        hm = np.zeros(len(uk))
        np.maximum.at(hm, ui, L)
        hmaxes.append(hm)
        if progress:
            progress("partition", a + len(F), 2 * nF)
    key.flush()
    del key
    uk, ui = np.unique(np.concatenate(keys), return_inverse=True)
    cnt = np.bincount(ui, weights=np.concatenate(counts)).astype(np.int64)
    hmax = np.zeros(len(uk))
    np.maximum.at(hmax, ui, np.concatenate(hmaxes))
    ijk = np.stack([uk // (G[1] * G[2]), (uk // G[2]) % G[1], uk % G[2]], axis=1)
    tile = kd_split(ijk, cnt, tile_faces)
    rank = np.lexsort((uk, tile))                       # cells in tile order, by key inside a tile
    pos_of = np.empty(len(uk), dtype=np.int64)          # key index -> position in tile order
    pos_of[rank] = np.arange(len(uk))
    start = np.zeros(len(uk) + 1, dtype=np.int64)
    np.cumsum(cnt[rank], out=start[1:])
    fill = start[:-1].copy()
    tile_of_pos = tile[rank]
    order = np.lib.format.open_memmap(directory / "order.npy", mode="w+", dtype=np.int64, shape=(nF,))
    owner = np.lib.format.open_memmap(directory / "owner.npy", mode="w+", dtype=np.int32, shape=(nV,))
    owner[:] = np.iinfo(np.int32).max
    for a, F in source.face_blocks():
        k = np.load(key_path, mmap_mode="r")[a:a + len(F)]
        p = pos_of[np.searchsorted(uk, k)]
        s = np.argsort(p, kind="stable")                # faces of a cell in ascending order
        ps = p[s]
        first = np.r_[True, ps[1:] != ps[:-1]]
        run = np.maximum.accumulate(np.where(first, np.arange(len(ps)), 0))
        order[fill[ps] + np.arange(len(ps)) - run] = a + s
        cells, n = np.unique(ps, return_counts=True)
        fill[cells] += n
        np.minimum.at(owner, F.ravel(), np.repeat(tile_of_pos[p], 3).astype(np.int32))
        if progress:
            progress("partition", nF + a + len(F), 2 * nF)
    owner[owner == np.iinfo(np.int32).max] = -1
    order.flush()
    owner.flush()
    del order, owner
    os.remove(key_path)
    ntile = int(tile.max()) + 1
    tile_start = np.searchsorted(tile_of_pos, np.arange(ntile + 1))
    ijk_t = ijk[rank]
    box_lo = np.array([ijk_t[tile_start[t]:tile_start[t + 1]].min(axis=0) for t in range(ntile)])
    box_hi = np.array([ijk_t[tile_start[t]:tile_start[t + 1]].max(axis=0) for t in range(ntile)])
    plan = Plan(str(directory), lo, cell, ijk_t, start, hmax[rank], tile_start, box_lo, box_hi, nV, nF)
    plan.save()
    return plan
