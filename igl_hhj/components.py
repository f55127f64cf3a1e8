"""Connected components: solve each one on its own, so that no component's result
depends on another's (issue 23, "locality").

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

from .mesh import TriangleMesh

__all__ = ["solve_groups", "submesh"]


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
    from .solvers import AUTO_DIRECT_MAX
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
