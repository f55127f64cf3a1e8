"""Tiled curvature: the drop-in on meshes larger than one machine's memory, on Dask.

The mesh is cut into spatial tiles of about ``tile_faces`` faces
(:mod:`~igl_hhj.tiled.partition`), each tile is grown by vertex rings
(:mod:`~igl_hhj.tiled.rings`) as far as the computation reaches
(:mod:`~igl_hhj.tiled.reach`: the HHJ solve's decay and the vertex stage's smoothing
scale), the drop-in runs on the grown tile (:mod:`~igl_hhj.tiled.tile`) and the values
of the vertices the tile owns are kept.  Inputs are read by rows
(:mod:`~igl_hhj.tiled.source`; binary PLY memory-mapped in place,
:mod:`~igl_hhj.tiled.ply`), outputs written per tile into ``.npy`` files
(:mod:`~igl_hhj.tiled.store`), tiles run as Dask tasks
(:mod:`~igl_hhj.tiled.runner`).  When and how: ``igl_hhj/docs/tiled.md``.
"""
from __future__ import annotations

import shutil
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .reach import DEFAULT_TOLERANCE, overlap_rings, radius_bound
from .store import read_result

__all__ = ["principal_curvature", "curvature_file", "TiledResult", "overlap_rings", "radius_bound",
           "read_result", "DEFAULT_TILE_FACES"]

DEFAULT_TILE_FACES = 1_000_000
"""Faces per tile by default: on a 20M-face jittered torus (116 rings of overlap) the grown
tiles had 2.1× their cores' faces and each worker peaked at 1.4 GB (``igl_hhj/docs/tiled.md``)."""


def _check_options(radius, tile_faces, overlap, eps, rtol, solver, boundary, workers):
    from ..constants import BOUNDARY_TREATMENTS
    from ..pipeline import check_principal_curvature_args, check_rtol
    check_principal_curvature_args(radius, True)
    check_rtol(rtol)
    for name, x, lo in (("tile_faces", tile_faces, 1), ("overlap", overlap, 0), ("workers", workers, 0)):
        if x is None and name != "tile_faces":
            continue
        if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, np.integer)):
            raise TypeError(f"{name} must be an int, got {type(x).__name__}")
        if x < lo:
            raise ValueError(f"{name} must be ≥ {lo}, got {x}")
    if isinstance(eps, (bool, np.bool_)) or not isinstance(eps, (int, float, np.floating)) or not 0 < eps < 1:
        raise ValueError(f"eps must be a number in (0, 1), got {eps!r}")
    if not isinstance(solver, str) or solver not in ("auto", "cg", "direct"):
        raise ValueError(f"solver must be 'auto', 'cg' or 'direct', got {solver!r}")
    if not isinstance(boundary, str) or boundary not in BOUNDARY_TREATMENTS:
        raise ValueError(f"boundary must be one of {BOUNDARY_TREATMENTS}, got {boundary!r}")


def _params(radius, rtol, solver, boundary, eps, overlap):
    return dict(radius=float(radius), rtol=float(rtol), solver=solver, boundary=boundary,
                eps=float(eps), overlap=None if overlap is None else int(overlap))


def _warn_repairs(stats):
    """One :class:`~igl_hhj.mesh.MeshWarning` for the tiles' warnings (repairs)."""
    from ..mesh import MeshWarning
    msgs = [(t, m) for t, s in sorted(stats.items()) for m in s.get("warnings", ())]
    if msgs:
        tiles = sorted({t for t, _ in msgs})
        shown = " | ".join(dict.fromkeys(m for _, m in msgs[:3]))
        warnings.warn(f"{len(tiles)} of {len(stats)} tiles warned (tiles {tiles[:10]}"
                      f"{' ...' if len(tiles) > 10 else ''}): {shown}", MeshWarning, stacklevel=3)


@dataclass
class TiledResult:
    """What :func:`curvature_file` did: the output directory (read it with
    :func:`read_result`), the tiles' stats (also ``OUT/tiles.csv``), the mesh's size, the
    number of bad vertices, how the input was read, whether an earlier run was continued,
    the seconds, the tiles computed by this call."""

    out: Path
    stats: dict = field(default_factory=dict)
    n_vertices: int = 0
    n_faces: int = 0
    n_bad: int = 0
    read: str = ""
    resumed: bool = False
    seconds: float = 0.0
    computed: list = field(default_factory=list)
    """The tiles this call computed (the others were finished by an earlier run)."""

    @property
    def faces_computed(self) -> int:
        """Faces of all grown tiles (the overlap's cost: ``faces_computed / n_faces``)."""
        return int(sum(s["faces"] for s in self.stats.values()))


def curvature_file(mesh_path, out_path, *, radius: float = 5, tile_faces: int = DEFAULT_TILE_FACES,
                   overlap: int | None = None, eps: float = DEFAULT_TOLERANCE, client: Any = None,
                   scheduler: str | None = None, workers: int | None = None, rtol: float = 1e-6,
                   solver: str = "auto", boundary: str = "estimate", retries: int = 2,
                   resume: bool = True, progress: bool | None = None) -> TiledResult:
    """The drop-in's per-vertex curvature of a mesh file, out of core, file to directory.

    Parameters
    ----------
    mesh_path : str or os.PathLike
        A mesh file: binary PLY (memory-mapped in place), ascii PLY or OFF (converted in a
        streaming pass), or any other format :func:`igl_hhj.mesh_io.read_mesh` reads (read
        whole).
    out_path : str or os.PathLike
        Output directory (created): ``PD1.npy PD2.npy PV1.npy PV2.npy bad_vertices.npy``
        (as :func:`igl_hhj.principal_curvature` returns them), ``tiles.csv``, ``meta.json``
        (:mod:`igl_hhj.tiled.store`).
    radius, rtol, solver, boundary
        As :func:`igl_hhj.principal_curvature`.
    tile_faces : int
        Faces per tile (the memory of a worker grows with it, the overlap's share shrinks).
    overlap : int, optional
        Rings of overlap; default: the rule of :mod:`igl_hhj.tiled.reach` at ``eps``, from
        the radius the vertex stage chose on each tile.
    eps : float
        Tolerance of the rule: the cut changes a value by at most ``eps`` × max(abs(κ)).
    client, scheduler, workers
        A ``distributed.Client``, a scheduler address (``tcp://host:port``; workers must
        see ``mesh_path`` and ``out_path``), or the number of worker processes of the
        embedded ``LocalCluster`` (default: the cores; 0: in this process).
    retries : int
        Times a tile may fail (or lose its worker) before the run fails.
    resume : bool
        Continue an earlier run with the same input and options: finished tiles (a marker
        each) are not recomputed.
    progress : bool, optional
        Progress bar on stderr (default: when it is a terminal).

    Returns
    -------
    TiledResult
    """
    from .partition import Plan, plan_tiles
    from .runner import open_client, run_tiles, source_key
    from .source import open_mesh_file
    from .store import FileStore
    _check_options(radius, tile_faces, overlap, eps, rtol, solver, boundary, workers)
    t0 = time.perf_counter()
    store = FileStore(out_path)
    source, how = open_mesh_file(mesh_path, store.work / "input")
    params = _params(radius, rtol, solver, boundary, eps, overlap)
    from .. import __version__
    key = dict(input=source_key(mesh_path), tile_faces=int(tile_faces), version=__version__, **params)
    resumed = store.start(key, source.n_vertices, resume)
    plan = Plan.load(store.work) if resumed else plan_tiles(source, store.work, tile_faces)
    owned = []
    try:
        cl = None
        if client is not None or scheduler is not None or (workers != 0 and plan.n_tiles > 1):
            cl, owned = open_client(client, scheduler, workers, retries, plan.n_tiles)
        stats, computed = run_tiles(source, plan, store, params, client=cl, retries=retries, progress=progress)
    finally:
        for obj in owned:
            obj.close()
    bad = store.finish(stats)
    _warn_repairs(stats)
    return TiledResult(Path(out_path), stats, source.n_vertices, source.n_faces, int(len(bad)), how,
                       resumed, time.perf_counter() - t0, computed)


def principal_curvature(V: Any, F: Any = None, radius: float = 5, useKring: bool = True, *,
                        tile_faces: int = DEFAULT_TILE_FACES, overlap: int | None = None,
                        eps: float = DEFAULT_TOLERANCE, client: Any = None, scheduler: str | None = None,
                        workers: int | None = None, rtol: float = 1e-6, solver: str = "auto",
                        boundary: str = "estimate", retries: int = 2, progress: bool | None = False,
                        workdir: str | None = None, info: dict | None = None):
    """:func:`igl_hhj.principal_curvature` computed tile by tile (same call, same returns).

    Every vertex's values equal the whole-mesh call's to ``eps`` × max(abs(κ)) plus the
    solvers' tolerances (``rtol``; ``igl_hhj/docs/tiled.md``), the same ``bad_vertices``,
    the same repairs (one :class:`igl_hhj.mesh.MeshWarning` for the tiles that needed one).

    Parameters
    ----------
    V, F, radius, useKring, rtol, solver, boundary
        As :func:`igl_hhj.principal_curvature` (``useKring`` is accepted and changes
        nothing, as there).
    tile_faces, overlap, eps, client, scheduler, workers, retries, progress
        As :func:`curvature_file`.  Without ``client``/``scheduler`` and with one tile or
        ``workers=0`` the tiles run in this process.
    workdir : str, optional
        Directory for the arrays the workers read (default: a temporary directory; with a
        remote ``scheduler`` one that the workers see).
    info : dict, optional
        Receives ``tiles``: {tile: stats} (faces computed, rings, the radius the vertex
        stage chose, seconds, peak memory, ...; the columns of ``tiles.csv``).

    Returns
    -------
    PD1, PD2 : (#V, 3), PV1, PV2 : (#V,) float64, bad_vertices : list of int

    Examples
    --------
    >>> import igl_hhj, igl_hhj.tiled
    >>> from igl_hhj.surfaces import icosphere
    >>> V, F = icosphere(5)
    >>> PD1, PD2, PV1, PV2, bad = igl_hhj.tiled.principal_curvature(V, F, tile_faces=5000, workers=0)
    >>> W = igl_hhj.principal_curvature(V, F)
    >>> bool(abs(PV1 - W[2]).max() < 1e-6), bad
    (True, [])
    """
    from ..mesh import validate_faces, validate_vertices
    from ..repair import caller_arrays
    from .partition import plan_tiles
    from .runner import open_client, run_tiles
    from .source import ArraySource, NpySource
    from .store import ArrayStore, FileStore
    from ..pipeline import check_principal_curvature_args
    check_principal_curvature_args(radius, useKring)
    _check_options(radius, tile_faces, overlap, eps, rtol, solver, boundary, workers)
    V, F = caller_arrays(V, F)
    V = validate_vertices(V)
    F = validate_faces(F, len(V), repeated_ok=True)
    params = _params(radius, rtol, solver, boundary, eps, overlap)
    tmp = Path(tempfile.mkdtemp(prefix="igl_hhj_tiled_", dir=workdir))
    owned = []
    try:
        plan = plan_tiles(ArraySource(V, F), tmp / "plan", tile_faces)
        local = client is None and scheduler is None and (workers == 0 or plan.n_tiles == 1)
        if local:
            arrays = ArrayStore(len(V))
            stats, computed = run_tiles(ArraySource(V, F), plan, arrays, params, progress=progress)
            PD1, PD2, PV1, PV2 = (arrays.arrays[k] for k in ("PD1", "PD2", "PV1", "PV2"))
        else:
            np.save(tmp / "V.npy", V)
            np.save(tmp / "F.npy", F)
            source = NpySource.open(tmp / "V.npy", tmp / "F.npy")
            store = FileStore(tmp / "out")
            store.start({}, len(V), resume=False)
            cl, owned = open_client(client, scheduler, workers, retries, plan.n_tiles)
            stats, computed = run_tiles(source, plan, store, params, client=cl, retries=retries, progress=progress)
            PD1, PD2, PV1, PV2 = (np.load(store.path(k)) for k in ("PD1", "PD2", "PV1", "PV2"))
    finally:
        for obj in owned:
            obj.close()
        shutil.rmtree(tmp, ignore_errors=True)
    bad = ~(np.isfinite(PD1).all(axis=1) & np.isfinite(PD2).all(axis=1) & np.isfinite(PV1) & np.isfinite(PV2))
    if info is not None:
        info["tiles"] = stats
    _warn_repairs(stats)
    return (np.ascontiguousarray(PD1), np.ascontiguousarray(PD2), np.ascontiguousarray(PV1),
            np.ascontiguousarray(PV2), np.flatnonzero(bad).tolist())
