"""A tile's core grown by vertex rings, inside the faces loaded around it.

``F_0`` is the core; ``F_j`` adds every face that shares a vertex with ``F_{j-1}``.
Every vertex within ``j - 1`` edges of the core is then a vertex of ``F_{j-1}`` with
its whole fan in ``F_j``, so the cut of ``F_k`` (its boundary edges that are not
boundary edges of the mesh) is at least ``k`` edges from every core vertex: the
distance the overlap rule (:mod:`igl_hhj.tiled.reach`) counts.  Only the faces loaded
around the tile are needed (:mod:`igl_hhj.tiled.partition` loads a box that contains
the ``k + 2`` rings), not the mesh's adjacency.

A ring's outer edge can pinch: a vertex whose faces in ``F_k`` form two fans, which
the drop-in would refuse (a non-manifold vertex) and repair.  :func:`grow` closes
such vertices by adding their whole fan, so a tile needs a repair only where the
mesh does.
"""
from __future__ import annotations

import numpy as np

__all__ = ["VertexFaces", "grow", "boundary_edge_faces"]


class VertexFaces:
    """Vertex → incident faces of a face array (CSR), with local vertex numbers.

    Parameters
    ----------
    F : (m, 3) int array of (global) vertex indices.

    Attributes
    ----------
    vertices : (n,) int64, the sorted global indices of F's vertices.
    local : (m, 3) int64, F in local numbers (``vertices[local] == F``).
    """

    def __init__(self, F):
        F = np.asarray(F, dtype=np.int64)
        self.vertices, inverse = np.unique(F.ravel(), return_inverse=True)
        self.local = inverse.reshape(F.shape)
        n = len(self.vertices)
        flat = self.local.ravel()
        order = np.argsort(flat, kind="stable")
        self.face_of = order // 3
        self.start = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(np.bincount(flat, minlength=n), out=self.start[1:])

    def faces_of(self, verts):
        """Faces incident to the local vertices ``verts`` (with repeats)."""
        verts = np.asarray(verts, dtype=np.int64)
        counts = self.start[verts + 1] - self.start[verts]
        total = int(counts.sum())
        if total == 0:
            return np.zeros(0, dtype=np.int64)
        first = np.repeat(self.start[verts] - np.cumsum(counts) + counts, counts)
        return self.face_of[first + np.arange(total)]


def boundary_edge_faces(local, faces):
    """Boundary edges of the face subset ``faces`` of ``local`` (m, 3): ``(i, j)`` local
    vertex pairs (k, 2) and the face of each (k,)."""
    sub = local[faces]
    E = np.concatenate([sub[:, [1, 2]], sub[:, [2, 0]], sub[:, [0, 1]]])
    owner = np.tile(faces, 3)
    lo, hi = E.min(axis=1), E.max(axis=1)
    key = lo * (int(local.max(initial=0)) + 1) + hi
    _, inv, counts = np.unique(key, return_inverse=True, return_counts=True)
    once = counts[inv] == 1
    return E[once], owner[once]


def grow(vf: VertexFaces, core, k, *, close_pinches=True, max_closing=4):
    """Grow the faces ``core`` (bool mask or indices over ``vf.local``) by ``k`` vertex rings.

    Returns
    -------
    ring : (m,) int64, the ring of each face (0: core, 1..k: overlap, k + 1: added to
        close a pinched vertex of the outer edge), -1 for faces not in the tile.
    """
    m = len(vf.local)
    ring = np.full(m, -1, dtype=np.int64)
    core = np.asarray(core)
    ring[np.flatnonzero(core) if core.dtype == bool else core] = 0
    seen = np.zeros(len(vf.vertices), dtype=bool)
    front = np.unique(vf.local[ring == 0].ravel())
    seen[front] = True
    for j in range(1, int(k) + 1):
        cand = vf.faces_of(front)
        new = np.unique(cand[ring[cand] < 0])
        if new.size == 0:
            break
        ring[new] = j
        verts = vf.local[new].ravel()
        front = np.unique(verts[~seen[verts]])
        seen[front] = True
    if close_pinches:
        # a pinched vertex has all its tile faces in the last ring (a vertex of an inner
        # ring has its whole fan inside); faces sharing an edge differ by at most one ring,
        # so the boundary edges of the last ring are those of the faces of rings ≥ k - 1
        for _ in range(max_closing):
            outer = np.flatnonzero(ring >= max(int(k) - 1, 0))
            E, _ = boundary_edge_faces(vf.local, outer)
            deg = np.bincount(E.ravel(), minlength=len(vf.vertices))
            last = np.zeros(len(vf.vertices), dtype=bool)
            last[vf.local[ring >= int(k)].ravel()] = True
            pinched = np.flatnonzero((deg > 2) & last)
            cand = vf.faces_of(pinched)
            new = np.unique(cand[ring[cand] < 0])
            if new.size == 0:
                break
            ring[new] = int(k) + 1
    return ring
