"""The readable numpy reference of the compiled topology pass (igl_hhj.kernels.topology,
:attr:`igl_hhj.mesh.TriangleMesh._topology`), from ``igl.unique_edge_map``; only the tests
use it (tests/mesh/test_mesh_kernels.py compares the two)."""
import igl
import numpy as np


def topology_reference(F):
    """The readable reference of :attr:`TriangleMesh._topology` (tests compare the two).

    From ``igl.unique_edge_map``: ``EMAP[f + c*#F]`` is the edge opposite corner
    ``c`` of face ``f``; edges are re-oriented as ``(min, max)``.

    Returns ``(edges, face_edges, count, edge_faces, edge_local_index, face_edge_sign)``
    as :func:`igl_hhj.kernels.topology` (int32 indices, int8 counts, local indices and
    signs; libigl's int64 outputs are converted once here).
    """
    import igl
    F = np.ascontiguousarray(F, dtype=np.int64)
    nF = F.shape[0]
    _, uE, EMAP, uEC, _ = igl.unique_edge_map(F)
    edges = np.sort(np.asarray(uE, dtype=np.int64), axis=1)
    face_edges = np.ascontiguousarray(np.asarray(EMAP).reshape(3, nF).T)
    count = np.minimum(np.diff(uEC), 127).astype(np.int8)
    src = F[:, [1, 2, 0]]
    sign = np.where(edges[face_edges, 0] == src, 1, -1).astype(np.int8)
    nE = edges.shape[0]
    ef = -np.ones((nE, 2), dtype=np.int32)
    li = -np.ones((nE, 2), dtype=np.int8)
    col = (sign.ravel() < 0).astype(np.int64)
    ef[face_edges.ravel(), col] = np.repeat(np.arange(nF), 3)
    li[face_edges.ravel(), col] = np.tile(np.arange(3), nF)
    return edges.astype(np.int32), face_edges.astype(np.int32), count, ef, li, sign
