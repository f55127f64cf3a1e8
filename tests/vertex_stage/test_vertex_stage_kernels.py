"""The compiled vertex-stage kernels (recovery, smoothing, 2×2 eigen) equal their numpy
references and give the same bits for any thread count."""

import numpy as np
import pytest

import igl_hhj
from igl_hhj import kernels
from igl_hhj.curvature import _shape_operator, principal_from_shape_operator
from igl_hhj.mesh import TriangleMesh
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially
from reference_intrinsic import principal_from_shape_operator_reference, recover, roughness
from kernel_cases import RTOL, bumpy, closed, kernel_meshes, on_one_and_two_threads, rel, sliver_mesh  # noqa: F401 (closed, saddle: pytest fixtures)


def test_eigen_equals_reference(closed):
    from igl_hhj import recovery as rc
    S = _shape_operator(closed, None, None, None, "direct")
    Sv, N = rc.recover_vertex_tensors(closed, S, method="lumped")     # tangential vertex tensors
    PD1, PD2, PV1, PV2 = principal_from_shape_operator(Sv, N)
    rPD1, rPD2, rPV1, rPV2 = principal_from_shape_operator_reference(Sv, N)
    assert rel(PV1, rPV1) <= RTOL and rel(PV2, rPV2) <= RTOL
    gap = (rPV1 - rPV2) > 1e-6 * np.abs(rPV1).max()
    assert gap.mean() > 0.9
    # directions agree up to sign where κ1 ≠ κ2
    np.testing.assert_allclose(np.abs(np.einsum("na,na->n", PD1, rPD1))[gap], 1.0, atol=1e-8)
    np.testing.assert_allclose(np.einsum("na,na->n", np.cross(N, PD1), PD2), 1.0, atol=1e-12)


def _vertex_stage_meshes():
    out = kernel_meshes()
    V, F = bumpy()
    out["unreferenced"] = (np.vstack([V, [[5.0, 5.0, 5.0]]]), F)    # a vertex no face uses
    return out


def test_recovery_kernels_equal_reference(closed):
    from igl_hhj import recovery as rc
    m = TriangleMesh(*sliver_mesh())
    for mesh in (closed, m):
        w = kernels.recovery_weights(mesh, rc.QUALITY_FLOOR)
        assert rel(w, rc.recovery_weights(mesh)) <= 1e-13
    cross, dbl, l2max = kernels.face_metrics(closed.V, closed.F)
    ev = closed._edge_vectors
    np.testing.assert_allclose(cross, np.cross(ev[:, 2], -ev[:, 1]), rtol=0, atol=1e-15)
    np.testing.assert_allclose(dbl, np.linalg.norm(cross, axis=1), rtol=1e-15)
    np.testing.assert_allclose(l2max, (ev ** 2).sum(axis=2).max(axis=1), rtol=1e-15)


def test_patch_fit_of_vertices_whose_faces_all_weigh_zero(closed):
    """The compiled patch fit gathers each vertex's corners; a vertex whose corners all weigh 0
    falls back to the plain average of its faces (weight 1 each) there too: the compiled
    recovery equals the numpy reference on a mesh with such vertices."""
    from igl_hhj import recovery as rc
    S = _shape_operator(closed, None, None, None, "direct")
    N = closed.vertex_normals
    w = kernels.recovery_weights(closed, rc.QUALITY_FLOOR)
    lost = np.arange(0, closed.n_vertices, 37)
    w[np.isin(closed.F, lost).any(axis=1)] = 0.0
    assert (np.bincount(closed.F.ravel(), np.repeat(w, 3), closed.n_vertices)[lost] == 0).all()
    Xi, rough = kernels.intrinsic_patch_recovery(closed, S, N, w)
    assert rel(Xi, recover(closed, S, N, w)) <= 1e-13
    assert rel(rough, roughness(closed, S, N, Xi, w)) <= 1e-13
    assert np.isfinite(Xi).all() and np.abs(Xi[lost]).max() > 0


def test_gathered_vertex_kernels_bit_identical_across_thread_counts():
    """The recovery and the adaptive radius gather every vertex's corners in face order, in
    parallel over vertices: one and two threads give the same bits (>= 20k vertices, where
    the kernels take two)."""
    from igl_hhj import recovery as rc
    m = TriangleMesh(*icosphere(6))
    S = _shape_operator(m, None, None, None, "cg", 1e-10)
    N = m.vertex_normals
    w = kernels.recovery_weights(m, rc.QUALITY_FLOOR)
    P = np.random.default_rng(1).normal(size=(m.n_vertices, 3))

    def kernels_once():
        Xi, rough = kernels.intrinsic_patch_recovery(m, S, N, w)
        return Xi, rough, kernels.adaptive_radius(m, P, rough, 5.0, 0.3, 0.25, 0.2, 5.0)
    for a, b in zip(*on_one_and_two_threads(kernels_once)):
        assert np.array_equal(a, b)


def test_smoothing_with_edges_out_of_lexicographic_order(closed):
    """The compiled smoothing sums each diagonal row by row when the edges are listed in
    lexicographic order (TriangleMesh.edges); any other order takes the serial scatter,
    which must give the same smoothing (to round-off: the rows list their entries in
    another order)."""
    import types
    from igl_hhj import intrinsic
    from igl_hhj import recovery as rc
    S = _shape_operator(closed, None, None, None, "direct")
    N = closed.vertex_normals
    w = kernels.recovery_weights(closed, rc.QUALITY_FLOOR)
    X0, rough = kernels.intrinsic_patch_recovery(closed, S, N, w)
    C0, mass = rc.smoothing_coefficients(closed, w)
    phase = kernels.transport_phases(closed, N)
    perm = np.random.default_rng(3).permutation(closed.n_edges)
    shuffled = types.SimpleNamespace(
        V=closed.V, F=closed.F, n_vertices=closed.n_vertices, n_faces=closed.n_faces, n_edges=closed.n_edges,
        edges=closed.edges[perm], edge_faces=closed.edge_faces[perm],
        edge_local_index=closed.edge_local_index[perm])
    out = []
    for mesh, ph in ((closed, phase), (shuffled, phase[perm])):
        X = X0.copy()
        status, its, _, r = intrinsic.adaptive_smoothing(mesh, X, C0, mass, ph, rough, 5, 1e-12)
        assert status == 0 and its > 0
        out.append((X, r))
    assert rel(out[1][0], out[0][0]) <= 1e-9 and rel(out[1][1], out[0][1]) <= 1e-12


def test_smoothing_falls_back_to_the_reference_when_a_solve_stalls(closed, monkeypatch):
    """A compiled smoothing solve that stalls (status != 0) sends the vertex stage to the
    sparse-LU smoothing (intrinsic_numpy.smooth_reference) from the recovered components:
    the same values to the smoothing's tolerance."""
    from igl_hhj import intrinsic
    S = _shape_operator(closed, None, None, None, "direct")
    good, _ = intrinsic.vertex_stage(closed, S, 5, rtol=1e-12)
    monkeypatch.setattr(kernels, "intrinsic_smoothing", lambda *a, **k: (1, 500, 1, np.zeros(closed.n_faces)))
    fallback, _ = intrinsic.vertex_stage(closed, S, 5, rtol=1e-12)
    assert rel(fallback, good) <= 1e-5


def test_stalled_smoothing_kernel_leaves_its_input_unchanged(closed):
    """The compiled smoothing returns a non-zero status without touching X when a solve
    does not converge, so the fallback restarts from the recovered components (the drop-in
    has freed the face tensors by then)."""
    from igl_hhj import intrinsic
    from igl_hhj import recovery as rc
    S = _shape_operator(closed, None, None, None, "direct")
    X, rough, N, w = intrinsic.vertex_recovery(closed, S)
    X0 = X.copy()
    C0, m = rc.smoothing_coefficients(closed, w)
    phase = kernels.transport_phases(closed, N)
    status, *_ = intrinsic.adaptive_smoothing(closed, X, C0, m, phase, rough, 5, 1e-6, 2, solve_rtol=1e-14)
    assert status != 0 and np.array_equal(X, X0)
    status, *_ = intrinsic.adaptive_smoothing(closed, X, C0, m, phase, rough, 5, 1e-6)
    assert status == 0 and not np.array_equal(X, X0)


def test_vertex_stage_bit_identical_across_thread_counts():
    from igl_hhj import intrinsic
    m = TriangleMesh(*bumpy(5))
    S = _shape_operator(m, None, None, None, "cg", 1e-10)
    nt = kernels.max_threads()
    adapt, kernels.ADAPT_TO_LOAD = kernels.ADAPT_TO_LOAD, False
    try:
        kernels.set_num_threads(1)
        one, _ = intrinsic.vertex_stage(m, S, 5)
        kernels.set_num_threads(max(2, nt))
        two, _ = intrinsic.vertex_stage(m, S, 5)
    finally:
        kernels.set_num_threads(nt)
        kernels.ADAPT_TO_LOAD = adapt
    assert np.array_equal(one, two)


def _vertex_stage_on_one_and_two_threads(m):
    """intrinsic.vertex_stage at radius 5 on one thread, then on two: [(X, info)] * 2."""
    from igl_hhj.intrinsic import vertex_stage
    S = _shape_operator(m, None, None, None, "cg", 1e-10)

    def stage():
        X, _ = vertex_stage(m, S, 5, info=(info := {}))
        return X, info
    return on_one_and_two_threads(stage)


@pytest.mark.parametrize("parts", [1, 2])
def test_smoothing_tasks_bit_identical_to_one_pcg(parts):
    """Below the two-thread sweep size (2k-20k vertices) the smoothing runs the h and z parts
    of each solve as two tasks on two threads; on one thread one PCG solves both.  The bits
    and the iteration count must agree (one and several parts)."""
    V0, F0 = bumpy(4)
    V, F = V0, F0
    if parts == 2:
        V = np.vstack([V0, 0.5 * V0 + 3.0])
        F = np.vstack([F0, F0 + len(V0)])
    m = TriangleMesh(V, F)
    assert 2000 <= m.n_vertices < 20000
    (one, i1), (two, i2) = _vertex_stage_on_one_and_two_threads(m)
    assert i1["components"] == i2["components"] == parts
    assert i1["smoothing_iterations"] == i2["smoothing_iterations"] > 0
    assert np.array_equal(one, two)


def test_smoothing_of_several_parts_bit_identical_across_thread_counts():
    """The intrinsic smoothing of a mesh with several parts (per-part CG scalars) runs its
    reductions in parallel chunks: the same bits on one and two threads (>= 20k vertices,
    where the kernel takes two)."""
    from igl_hhj.surfaces import icosphere
    V0, F0 = icosphere(5)
    V = np.vstack([V0, 0.5 * V0 * [1.0, 0.8, 0.6] + 3.0])
    F = np.vstack([F0, F0 + len(V0)])
    m = TriangleMesh(V, F)
    assert m.n_vertices >= 20000
    (one, i1), (two, i2) = _vertex_stage_on_one_and_two_threads(m)
    assert i1["components"] == i2["components"] == 2
    assert np.array_equal(one, two)


def test_vertex_kernels_reject_bad_arrays(closed):
    S = np.zeros((closed.n_faces, 3, 3))
    with pytest.raises(ValueError, match="intrinsic_patch_recovery"):
        kernels.intrinsic_patch_recovery(closed, S[:-1], closed.vertex_normals, closed.face_areas)
    X = np.zeros((closed.n_vertices, 5))
    with pytest.raises(ValueError, match="intrinsic_smoothing"):
        kernels.intrinsic_smoothing(closed, X, np.zeros((closed.n_faces, 3)), np.ones(closed.n_vertices),
                                    np.zeros((closed.n_edges, 2)), np.zeros(closed.n_vertices), 5,
                                    per_radius=0.2, pilot_radius=5, pilot_rtol=1e-3, gain=0.3, power=0.25,
                                    bounds=(0.2, 5.0), steps=2, coefficients=[2, -1], rtol=1e-3, maxiter=10)


def test_dropin_frees_the_face_tensors_before_its_memory_peak(monkeypatch):
    """The drop-in frees the (#F, 3, 3) face tensors after the recovery, before the
    smoothing (its memory peak), and gives the same values as the public composition."""
    import weakref

    from igl_hhj import curvature, pipeline
    V, F = icosphere(4)
    V = jitter_tangentially(V, F, Sphere(), 0.3, seed=1)
    alive = {}
    real_S, real_smooth = pipeline.face_shape_operator, kernels.intrinsic_smoothing

    def shape_operator(*a, **k):
        S = real_S(*a, **k)
        alive["S"] = weakref.ref(S)
        return S

    def smooth(*a, **k):
        alive["at smoothing"] = alive["S"]() is not None
        return real_smooth(*a, **k)
    monkeypatch.setattr(pipeline, "face_shape_operator", shape_operator)
    monkeypatch.setattr(kernels, "intrinsic_smoothing", smooth)
    out = igl_hhj.principal_curvature(V, F)
    assert alive["at smoothing"] is False
    monkeypatch.undo()
    m = TriangleMesh(V, F)
    ref = curvature.dropin_vertex_values(m, igl_hhj.shape_operator(m), 5)
    for a, b in zip(ref, out):
        np.testing.assert_array_equal(a, b)
