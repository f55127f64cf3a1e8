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

HEADROOM = 1.25
"""A tile is given (and regrown to) the rings of ``HEADROOM`` × the radius that sets its
overlap, at most those of the largest radius the stage can choose: a larger overlap
band may hold a slightly larger radius (measured: 13.26 → 13.72 between tiles of a
jittered torus), and a regrowth costs a whole recomputation, a few more rings little."""


def rings_for(radius, params):
    """The rings a tile is given for a measured ``radius``: the rule's, with
    :data:`HEADROOM` up to ``params["rings_bound"]``."""
    need = reach.overlap_rings(radius, params["eps"])
    return max(need, min(reach.overlap_rings(HEADROOM * radius, params["eps"]), params["rings_bound"]))


@dataclass
class GrownTile:
    """A tile's core grown by ``rings`` vertex rings.

    ``faces`` (m,) global face indices (ascending), ``F`` (m, 3) local, ``vertices`` (n,)
    global vertex indices of ``V`` (n, 3), ``ring`` (m,) each face's ring (0: core),
    ``real_boundary`` (n,) bool: the vertex is on a boundary edge of the mesh (not only
    on the cut), ``band_boundary``: a face of rings 1 .. rings - 1 has a boundary edge of
    the mesh, ``complete``: the growth ran out of faces (no cut: whole components)."""

    faces: np.ndarray
    F: np.ndarray
    vertices: np.ndarray
    V: np.ndarray
    ring: np.ndarray
    rings: int
    complete: bool
    real_boundary: np.ndarray
    band_boundary: bool


def _real_boundary(vf, ring, rings):
    """Boundary edges of the tile ``ring >= 0`` that are boundary edges of the mesh: no face
    outside the tile (all of them are loaded around the cut) shares them.  Returns the
    (superset-local) vertices on such edges and whether a face of rings 1 .. rings - 1 has one."""
    E, owner = boundary_edge_faces(vf.local, np.flatnonzero(ring >= 0))
    if len(E) == 0:
        return np.zeros(0, dtype=np.int64), False
    n = len(vf.vertices)
    cand = vf.faces_of(np.unique(E))
    out = vf.local[np.unique(cand[ring[cand] < 0])]
    OE = np.concatenate([out[:, [1, 2]], out[:, [2, 0]], out[:, [0, 1]]])
    real = ~np.isin(E.min(axis=1) * n + E.max(axis=1), OE.min(axis=1) * n + OE.max(axis=1))
    band = bool((real & (ring[owner] >= 1) & (ring[owner] < rings)).any())
    return np.unique(E[real]), band


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
    real, band = _real_boundary(vf, ring, rings)
    vertices = vf.vertices[used]
    return GrownTile(faces[sel], local.reshape(-1, 3), vertices, source.vertices(vertices), ring[sel],
                     int(rings), bool(complete), np.isin(used, real), band)


def _peak_rss():
    """Peak resident memory of this process in bytes (Linux ``VmHWM``; 0 when unknown)."""
    from ..batch.jobs import _proc_status_bytes
    return _proc_status_bytes("VmHWM") or 0


def compute_tile(source, plan, t, params):
    """Compute tile ``t``: the drop-in on the grown tile, regrown until the overlap covers
    the radius the vertex stage chose on the overlap's faces (:func:`reach.overlap_rings`).

    ``params``: those of :func:`igl_hhj.tiled._compute.tile_values` and ``eps``, ``rings``
    (the first overlap), ``rings_bound`` (:func:`rings_for`), ``fixed`` (True: keep
    ``rings`` whatever the stage chose).

    Returns
    -------
    rows : (k,) int64, the vertices tile t owns; values : dict of their rows
    (``PD1, PD2, PV1, PV2``); stats : dict (``tile, core_faces, faces, rings, rounds,
    radius_max`` (on the overlap), ``radius_tile_max`` (on the grown tile), ``boundary,
    rings_needed, complete, vertices, seconds, peak_rss`` (of the process so far), ``warnings``).
    """
    t0 = time.perf_counter()
    rings = int(params["rings"])
    for rounds in range(1, MAX_ROUNDS + 1):
        tile = grown_tile(source, plan, t, rings)
        out = tile_values(tile.V, tile.F, params, real_boundary=tile.real_boundary)
        # the radius the stage chose, away from the cut: within the rule's k_S outermost
        # rings the cut perturbs S_h and hence the radius itself (icosphere(7): 1.3 in
        # the tile, 6.5 on the cut's ring), a perturbation the k_S rings already cover
        inner = tile.ring <= rings - reach.hhj_rings(params["eps"])
        band = inner & (tile.ring >= 1)
        rmax = float(out["radius"][band].max()) if band.any() else 0.0
        rall = float(out["radius"][inner].max()) if inner.any() else 0.0
        boundary = tile.band_boundary
        need = reach.overlap_rings(rmax, params["eps"], boundary=boundary)
        if not band.any():          # no face away from the cut: the radius was not seen yet
            need = max(need, reach.hhj_rings(params["eps"]) + 1)
        if params.get("fixed") or tile.complete or need <= rings:
            break
        rings = max(need, rings_for(rmax, params))
    own = plan.owners(tile.vertices) == t
    rows = tile.vertices[own]
    values = {k: np.ascontiguousarray(out[k][own]) for k in ("PD1", "PD2", "PV1", "PV2")}
    stats = dict(tile=int(t), core_faces=plan.tile_size(t), faces=int(len(tile.faces)), rings=rings,
                 rounds=rounds, radius_max=rmax, radius_tile_max=rall, boundary=boundary, rings_needed=need,
                 complete=tile.complete, vertices=int(len(rows)),
                 seconds=time.perf_counter() - t0, peak_rss=_peak_rss(), warnings=out["warnings"])
    return rows, values, stats
