"""One tile from its plan: load the faces around it, grow the core, compute, and regrow
when the scale the vertex stage used needs more overlap than the tile was given."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from . import reach
from ._compute import tile_values
from .rings import VertexFaces, boundary_edge_faces, grow

__all__ = ["GrownTile", "grown_tile", "compute_tile", "MAX_ROUNDS"]

MAX_ROUNDS = 4
"""A tile is regrown at most this many times (the rule's radius is bounded, so one
regrowth suffices unless the stage's radius grows with the overlap)."""


@dataclass
class GrownTile:
    """A tile's core grown by ``rings`` vertex rings.

    ``faces`` (m,) global face indices (ascending), ``F`` (m, 3) local, ``vertices`` (n,)
    global vertex indices of ``V`` (n, 3), ``ring`` (m,) each face's ring (0: core),
    ``complete``: the growth ran out of faces (no cut: the tile holds whole components)."""

    faces: np.ndarray
    F: np.ndarray
    vertices: np.ndarray
    V: np.ndarray
    ring: np.ndarray
    rings: int
    complete: bool

    def band_has_boundary(self) -> bool:
        """True when a face of rings 1 .. rings - 1 has a boundary edge (a real one: all
        faces around such a face's vertices are in the tile)."""
        band = np.flatnonzero((self.ring >= 1) & (self.ring < self.rings))
        if band.size == 0:
            return False
        _, owner = boundary_edge_faces(self.F, np.arange(len(self.F)))
        return bool(np.isin(owner, band).any())


def _margin_cells(plan, t, rings):
    """Cells around tile t that hold its ``rings + 2`` rings: the box grown by
    ``(rings + 2) × (longest edge in the box)``, enlarged until that edge stops growing."""
    cells = np.arange(plan.tile_start[t], plan.tile_start[t + 1])
    m = -1
    while True:
        h = float(plan.hmax[cells].max())
        need = math.ceil((rings + 2) * h / plan.cell)
        if need <= m:
            return cells
        m = need
        cells = plan.box_cells(t, m)


def grown_tile(source, plan, t, rings) -> GrownTile:
    """Tile ``t`` of ``plan`` grown by ``rings`` rings (:func:`igl_hhj.tiled.rings.grow`)."""
    core = plan.tile_faces(t)
    faces = plan.cells_faces(_margin_cells(plan, t, rings))
    vf = VertexFaces(source.faces(faces))
    is_core = np.zeros(len(faces), dtype=bool)
    is_core[np.searchsorted(faces, core)] = True
    ring = grow(vf, is_core, rings)
    sel = np.flatnonzero(ring >= 0)
    complete = not (ring[sel] >= rings).any() if rings > 0 else False
    used, local = np.unique(vf.local[sel], return_inverse=True)
    vertices = vf.vertices[used]
    return GrownTile(faces[sel], local.reshape(-1, 3), vertices, source.vertices(vertices), ring[sel],
                     int(rings), bool(complete))


def compute_tile(source, plan, t, params):
    """Compute tile ``t``: the drop-in on the grown tile, regrown until the overlap covers
    the radius the vertex stage chose on the overlap's faces (:func:`reach.overlap_rings`).

    ``params``: those of :func:`igl_hhj.tiled._compute.tile_values` and ``eps``, ``rings``
    (the first overlap), ``fixed`` (True: keep ``rings`` whatever the stage chose).

    Returns
    -------
    rows : (k,) int64, the vertices tile t owns; values : dict of their rows
    (``PD1, PD2, PV1, PV2``); stats : dict (``tile, core_faces, faces, rings, rounds,
    radius_max`` (on the overlap), ``radius_tile_max`` (on the grown tile), ``boundary,
    rings_needed, complete, vertices, seconds, warnings``).
    """
    t0 = time.perf_counter()
    rings = int(params["rings"])
    for rounds in range(1, MAX_ROUNDS + 1):
        tile = grown_tile(source, plan, t, rings)
        out = tile_values(tile.V, tile.F, params)
        band = tile.ring >= 1
        rmax = float(out["radius"][band].max()) if band.any() else 0.0
        rall = float(out["radius"].max()) if len(out["radius"]) else 0.0
        boundary = tile.band_has_boundary()
        need = reach.overlap_rings(rmax, params["eps"], boundary=boundary)
        if params.get("fixed") or tile.complete or need <= rings:
            break
        rings = need
    own = plan.owners(tile.vertices) == t
    rows = tile.vertices[own]
    values = {k: np.ascontiguousarray(out[k][own]) for k in ("PD1", "PD2", "PV1", "PV2")}
    stats = dict(tile=int(t), core_faces=plan.tile_size(t), faces=int(len(tile.faces)), rings=rings,
                 rounds=rounds, radius_max=rmax, radius_tile_max=rall, boundary=boundary, rings_needed=need,
                 complete=tile.complete, vertices=int(len(rows)),
                 seconds=time.perf_counter() - t0, warnings=out["warnings"])
    return rows, values, stats
