"""Where the tiles' values go: ``.npy`` files written in place, one marker per finished tile.

Layout of an output directory::

    OUT/PD1.npy  PD2.npy      (#V, 3) float64   as igl_hhj.principal_curvature returns them
    OUT/PV1.npy  PV2.npy      (#V,)   float64   (NaN rows: bad vertices)
    OUT/bad_vertices.npy      (k,)    int64     written when every tile is done
    OUT/tiles.csv             one row per tile: faces, overlap, radius, seconds, ...
    OUT/meta.json             the options, the input, the state ("running" / "done")
    OUT/.work/                the plan (order.npy, owner.npy, plan.npz) and tiles/<t>.json markers

Why ``.npy``: every tool that reads numpy reads them, ``np.load(path, mmap_mode="r")``
reads any rows without loading the rest, and a tile writes its rows where they belong
(``mmap_mode="r+"``) without a merge step; ``.npy`` needs no package (Zarr would add
chunk compression and object stores but a dependency and a chunk grid that tiles'
scattered vertex rows do not follow; Parquet files are written whole, row group by row
group, so rows cannot be updated in place).  Each vertex is written by one tile only
(its owner), so workers never write the same bytes.  A tile's marker is written after
its rows are flushed: a run that stops (killed, interrupted) resumes with the tiles
that have no marker.  Writes through a shared memory map are coherent on a local
disk and on cluster file systems that keep mmap writes coherent (Lustre, GPFS,
CephFS); NFS clients write whole pages back, so there use one machine's workers.
"""
from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import numpy as np

__all__ = ["ARRAYS", "FileStore", "ArrayStore", "read_result"]

ARRAYS = {"PD1": (3,), "PD2": (3,), "PV1": (), "PV2": ()}
"""The per-vertex outputs and their row shapes."""

STAT_COLUMNS = ("tile", "core_faces", "faces", "vertices", "rings", "rounds", "radius_max", "boundary",
                "rings_needed", "complete", "seconds", "peak_rss", "warnings")


def _atomic_json(path, obj):
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w") as fh:
        json.dump(obj, fh)
    os.replace(tmp, path)


class ArrayStore:
    """In-memory outputs (the in-process path of :func:`igl_hhj.tiled.principal_curvature`)."""

    def __init__(self, n_vertices):
        self.arrays = {k: np.full((n_vertices,) + s, np.nan) for k, s in ARRAYS.items()}
        self.stats = {}

    def write(self, rows, values, stats):
        for k, a in self.arrays.items():
            a[rows] = values[k]
        self.stats[stats["tile"]] = stats

    def done(self, t):
        return self.stats.get(t)


class FileStore:
    """An output directory (module docstring)."""

    def __init__(self, directory):
        self.directory = Path(directory)
        self.work = self.directory / ".work"
        self.markers = self.work / "tiles"

    def path(self, name):
        return self.directory / f"{name}.npy"

    # --------------------------------------------------------------- set-up and resume
    def meta(self):
        try:
            with open(self.directory / "meta.json") as fh:
                return json.load(fh)
        except (OSError, ValueError):
            return None

    def start(self, key, n_vertices, resume=True):
        """Prepare the directory for a run with options ``key`` (a dict).  Returns True when a
        previous run with the same key is continued (its markers and plan kept)."""
        self.directory.mkdir(parents=True, exist_ok=True)
        old = self.meta()
        same = resume and old is not None and old.get("key") == key and \
            all(self.path(k).is_file() for k in ARRAYS) and (self.work / "plan.npz").is_file()
        if not same:
            for p in self.markers.glob("*.json") if self.markers.is_dir() else ():
                p.unlink()
            for f in ("plan.npz", "order.npy", "owner.npy"):
                if (self.work / f).exists():
                    (self.work / f).unlink()
            for name, shape in ARRAYS.items():
                a = np.lib.format.open_memmap(self.path(name), mode="w+", dtype=np.float64,
                                              shape=(n_vertices,) + shape)
                for s in range(0, n_vertices, 1 << 20):
                    a[s:s + (1 << 20)] = np.nan
                a.flush()
                del a
            for f in ("bad_vertices.npy", "tiles.csv"):
                if (self.directory / f).exists():
                    (self.directory / f).unlink()
        self.markers.mkdir(parents=True, exist_ok=True)
        _atomic_json(self.directory / "meta.json", {"key": key, "state": "running",
                                                    "n_vertices": int(n_vertices)})
        return same

    # --------------------------------------------------------------- tiles
    def write(self, rows, values, stats):
        """Write a tile's rows in place, flush, then its marker."""
        for name in ARRAYS:
            a = np.load(self.path(name), mmap_mode="r+")
            a[rows] = values[name]
            a.flush()
            del a
        _atomic_json(self.markers / f"{stats['tile']}.json", stats)

    def done(self, t):
        """The stats of tile t if it is finished, else None."""
        try:
            with open(self.markers / f"{t}.json") as fh:
                return json.load(fh)
        except (OSError, ValueError):
            return None

    # --------------------------------------------------------------- end
    def finish(self, stats, block=1 << 20):
        """bad_vertices.npy (the NaN rows, in streaming blocks), tiles.csv, state "done"."""
        n = int(self.meta()["n_vertices"])
        bad = []
        for s in range(0, n, block):
            ok = np.ones(min(block, n - s), dtype=bool)
            for name in ARRAYS:
                a = np.load(self.path(name), mmap_mode="r")[s:s + block]
                ok &= np.isfinite(a.reshape(len(a), -1)).all(axis=1)
            bad.append(s + np.flatnonzero(~ok))
        bad = np.concatenate(bad) if bad else np.zeros(0, dtype=np.int64)
        np.save(self.directory / "bad_vertices.npy", bad.astype(np.int64))
        with open(self.directory / "tiles.csv", "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(STAT_COLUMNS)
            for t in sorted(stats):
                row = dict(stats[t], warnings=" | ".join(stats[t].get("warnings", ())))
                w.writerow([row.get(c, "") for c in STAT_COLUMNS])
        meta = self.meta()
        meta["state"] = "done"
        _atomic_json(self.directory / "meta.json", meta)
        return bad


def read_result(directory, mmap_mode="r"):
    """The arrays of a finished output directory: ``(PD1, PD2, PV1, PV2, bad_vertices)``,
    memory-mapped (``mmap_mode="r"``, the default) or loaded (``mmap_mode=None``)."""
    directory = Path(directory)
    meta = FileStore(directory).meta()
    if meta is None or meta.get("state") != "done":
        raise ValueError(f"{directory}: not a finished igl_hhj.tiled output (meta.json says "
                         f"{None if meta is None else meta.get('state')!r})")
    out = [np.load(directory / f"{k}.npy", mmap_mode=mmap_mode) for k in ARRAYS]
    return (*out, np.load(directory / "bad_vertices.npy"))
