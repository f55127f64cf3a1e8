"""Connected components: solve each one on its own, so that no component's result
depends on another's.

The HHJ system of a mesh with several connected components is block diagonal, but
an iterative solve of all blocks together shares its CG scalars and its stopping
test (and ``solver="auto"`` picks one method for the whole mesh), so adding a far
away part changed a component's S_h at the level of the solver tolerance.
:func:`solve_groups` splits the faces into independent solves instead: every
component with more than :data:`igl_hhj.solvers.AUTO_DIRECT_MAX` edges alone, with
the caller's solver (as if it were the only component), and all the small ones
together with the direct solver (which ``"auto"`` uses for each of them alone, and
whose factor of a block diagonal matrix is block diagonal).  The vertex stage needs
no split: its PCG keeps separate scalars per component
(:func:`igl_hhj.kernels.intrinsic_smoothing`).
"""
from __future__ import annotations

import warnings

import numpy as np

from .constants import AUTO_DIRECT_MAX
from .mesh import TriangleMesh

__all__ = ["solve_groups", "submesh", "split_parts"]


def solve_groups(mesh: TriangleMesh, solver):
    """Face groups to solve separately, or None when one solve of the whole mesh is exact.

    Returns
    -------
    None, or a list of ``(faces, solver)``: ``faces`` (m,) int64 face indices in
    ascending order, ``solver`` the solver for that group.
    """
    if solver == "direct" or mesh.n_faces == 0:
        return None
    from . import kernels
    labels, n = kernels.vertex_components(mesh)
    if n <= 1:
        return None
    face_label = labels[mesh.F[:, 0]]
    edge_count = np.bincount(labels[mesh.edges[:, 0]], minlength=n)
    small = edge_count <= AUTO_DIRECT_MAX if solver == "auto" else np.zeros(n, dtype=bool)
    big = np.flatnonzero(~small)
    if len(big) == 1 and not small.any():
        return None                # a single component
    if len(big) == 0:              # all small: one direct solve (auto could pick CG for the total)
        return [(np.arange(mesh.n_faces), "direct")]
    order = np.argsort(face_label, kind="stable")
    starts = np.searchsorted(face_label[order], np.arange(n + 1))
    groups = [(np.sort(order[starts[c]:starts[c + 1]]), solver) for c in big]
    if small.any():
        groups.append((np.flatnonzero(small[face_label]), "direct"))
    return groups


def submesh(mesh: TriangleMesh, faces):
    """The sub-mesh of ``faces`` (ascending) with its own vertex numbering.

    Returns ``(sub, vertices)``: a :class:`TriangleMesh` (validation warnings are
    not repeated: the whole mesh gave them) and the (k,) int64 indices of its vertices in
    ``mesh`` (ascending, so relative orders are kept)."""
    F = mesh.F[faces]
    used = np.zeros(mesh.n_vertices, dtype=bool)
    used[F.ravel()] = True
    vertices = np.flatnonzero(used)
    local = np.cumsum(used) - 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sub = TriangleMesh(mesh.V[vertices], local[F])
    return sub, vertices



def split_parts(mesh: TriangleMesh, labels, n):
    """The mesh reordered part by part, for the vertex labels ``labels`` (#V,) int
    (0..n-1, each a connected component or a union of components), with the topology
    sliced from ``mesh`` instead of recomputed.

    Vertices, faces and edges keep their relative order within a part (the local
    numbering is monotone), so a part's ``edges`` are still lexicographic and its
    ``edge_faces`` and ``edge_local_index`` are those of ``mesh`` renumbered: each part
    is the mesh :func:`submesh` would build, without its validation and topology pass.

    Returns
    -------
    order : ``(vertices, faces, edges)``, (#V,), (#F,), (#E,) int64 permutations of
        ``mesh``'s indices, part after part (ascending within a part).
    parts : list of ``(sub, vs, fs, es)``, one per label: ``sub`` a :class:`TriangleMesh`
        and the slices of its rows in the three permutations (the rows of a per-vertex
        array ``A`` of the part are ``A[order[0]][vs]``).
    """
    # a stable sort keeps each part ascending; small labels sort by radix
    labels = np.asarray(labels, dtype=np.int16 if n < 2 ** 15 else np.int64)
    take = np.take                    # np.take: several times faster than fancy indexing of rows
    perms = []
    for lab in (labels, take(labels, mesh.F[:, 0]), take(labels, mesh.edges[:, 0])):
        order = np.argsort(lab, kind="stable")
        starts = np.searchsorted(take(lab, order), np.arange(n + 1))
        perms.append((order, starts))
    (vo, vs), (fo, fs), (eo, es) = perms
    # local index of every vertex and face in its part; the faces' with a last entry -1
    # for the edges' missing faces (edge_faces -1)
    vloc = np.empty(len(vo), dtype=np.int64)
    vloc[vo] = np.arange(len(vo)) - np.repeat(vs[:-1], np.diff(vs))
    floc = np.empty(len(fo) + 1, dtype=np.int64)
    floc[fo] = np.arange(len(fo)) - np.repeat(fs[:-1], np.diff(fs))
    floc[-1] = -1
    V = take(mesh.V, vo, axis=0)
    F = take(vloc, take(mesh.F, fo, axis=0))
    E = take(vloc, take(mesh.edges, eo, axis=0))
    EF = take(floc, take(mesh.edge_faces, eo, axis=0))
    ELI = take(mesh.edge_local_index, eo, axis=0)
    parts = []
    for c in range(n):
        v, f, e = slice(vs[c], vs[c + 1]), slice(fs[c], fs[c + 1]), slice(es[c], es[c + 1])
        parts.append((TriangleMesh._with_topology(V[v], F[f], E[e], EF[e], ELI[e]), v, f, e))
    return (vo, fo, eo), parts
