"""Mesh families of the robustness benchmark (igl_hhj.benchmarks.robustness) are valid."""
import numpy as np
from conftest import sequence

from igl_hhj.benchmarks import robustness as rb
from igl_hhj.mesh import TriangleMesh


def test_flipped_meshes_are_valid_and_flipped():
    surface, seq = sequence("ellipsoid", 3)
    V, F = seq[-1]
    G, frac = rb.flip_edges(V, F, rb.FLIP_FRACTION, seed=1)
    m = TriangleMesh(V, G)                       # validation: manifold, consistently oriented
    assert m.n_faces == len(F) and m.n_edges == TriangleMesh(V, F).n_edges
    assert 0.05 < frac < 0.3
    assert (np.sort(G, axis=1) != np.sort(F, axis=1)).any(axis=1).mean() > 0.1
    assert not rb._folded_faces(V, G, surface).any()


def test_families_are_fold_free_and_open_boundaries_stay():
    surface, seq = sequence("saddle", 3)
    fam = rb.families(surface, seq, len(seq))
    assert set(fam) >= {"clean", "flips", "slivers", "jitter 0.45", "noise 0.1"}
    V0, F0 = seq[-1]
    b = TriangleMesh(V0, F0).boundary_vertices
    for name, rows in fam.items():
        V, F, X = rows[-1]
        TriangleMesh(V, F)
        if name.startswith("jitter"):
            assert not rb._folded_faces(V, F, surface).any()
            np.testing.assert_array_equal(V[b], V0[b])


def test_errors_are_zero_for_exact_values():
    surface, seq = sequence("saddle", 2)
    V, F = seq[-1]
    k1, k2 = surface.principal_curvatures(V)
    d1 = surface.principal_directions(V)[0]
    e = rb.errors(surface, V, F, V, "vertex", k1, k2, d1)
    for region in ("interior", "band"):
        assert e[region]["H"] < 1e-12 and e[region]["K_max"] < 1e-12 and e[region]["angle"] < 1e-5
