"""The compiled mesh kernels (topology) equal their references and refuse sizes beyond
their index types."""
"""The compiled mesh kernels (topology) equal their references, and refuse sizes beyond their index types."""

import numpy as np
import pytest

from igl_hhj import kernels
from igl_hhj.mesh import TriangleMesh
from reference_topology import topology_reference
from kernel_cases import kernel_meshes


@pytest.mark.parametrize("name", ["closed", "open", "permuted", "sliver"])
def test_topology_equals_libigl_reference(name):
    V, F = kernel_meshes()[name]
    m = TriangleMesh(V, F)
    for got, want in zip(m._topology, topology_reference(F)):
        assert got.dtype == want.dtype
        np.testing.assert_array_equal(got, want)


def test_topology_refuses_sizes_beyond_its_32_bit_keys():
    """The topology kernel packs (vertex, half-edge) into 64-bit keys: more than 2**32 - 1
    vertices (or 1.43e9 faces) is a ValueError, not a wrong answer."""
    with pytest.raises(ValueError, match="at most"):
        kernels.topology(np.array([[0, 1, 2]]), 2 ** 32)


def test_topology_refuses_sizes_beyond_its_int32_maps():
    """The maps hold int32 indices: 2**31 vertices or faces are a ValueError before any
    work (the face array is a broadcast view: no 2**31 x 3 array is made)."""
    with pytest.raises(ValueError, match="at most 2\\*\\*31 - 1 vertices, faces"):
        kernels.topology(np.array([[0, 1, 2]]), 2 ** 31)
    with pytest.raises(ValueError, match="at most 2\\*\\*31 - 1 vertices, faces"):
        kernels.topology(np.broadcast_to(np.array([[0, 1, 2]]), (2 ** 31, 3)), 3)
    with pytest.raises(ValueError, match="2\\*\\*31 - 1 vertices"):     # the binding's own check
        kernels._core.topology(np.array([[0, 1, 2]]), 2 ** 31)


def test_topology_count_saturates_and_the_error_names_the_true_count():
    """edge_face_count is int8, saturated at 127: an edge of 200 faces stays non-manifold
    (not 200 mod 256 = 72 -> 'fine'), and the error counts the faces exactly."""
    k = 200
    a = np.linspace(0, 2 * np.pi, k, endpoint=False)
    V = np.r_[[[0.0, 0, 0], [0, 0, 1]], np.c_[np.cos(a), np.sin(a), np.full(k, 0.5)]]
    F = np.c_[np.zeros(k, int), np.ones(k, int), 2 + np.arange(k)]
    count = kernels.topology(F, len(V))[2]
    assert count.dtype == np.int8 and count.max() == 127
    assert np.array_equal(count, topology_reference(F)[2])
    with pytest.raises(ValueError, match=f"non-manifold.*with {k} faces"):
        TriangleMesh(V, F)
