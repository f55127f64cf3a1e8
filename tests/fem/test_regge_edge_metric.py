"""Degree-0 Regge metrics (squared edge lengths) on embedded and intrinsic meshes."""
import numpy as np
import pytest

igl = pytest.importorskip("igl")

from igl_hhj.regge import (angle_defect, gauss_curvature, gauss_curvature_intrinsic,
                           intrinsic_angles, intrinsic_areas, intrinsic_mass_matrix,
                           squared_edge_lengths)
from igl_hhj.surfaces.exact import Sphere, WalkerSaddle
from igl_hhj.surfaces.meshing import (graph_coarse, icosphere, jitter_tangentially, mesh_sequence,
                                      torus_coarse)


def _sphere(sub=2, seed=0):
    V, F = icosphere(sub)
    return jitter_tangentially(V, F, Sphere(), amount=0.25, seed=seed), F


def _total(V, F, K):
    return float(np.ones(len(V)) @ (igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_FULL) @ K))


def test_gauss_bonnet_closed_meshes():
    V, F = _sphere()
    assert _total(V, F, gauss_curvature(V, F)) == pytest.approx(4 * np.pi, abs=1e-11)
    V, F = torus_coarse()
    K = gauss_curvature(V, F)
    assert abs(_total(V, F, K)) < 1e-11
    assert K.max() > 0.1 and K.min() < -0.1           # a torus has both signs


def test_gauss_bonnet_with_boundary_conventions():
    V, F = graph_coarse(WalkerSaddle(), n=6, seed=1)
    lsq, uE = squared_edge_lengths(V, F)
    bv = np.zeros(len(V), bool)
    bv[igl.boundary_loop(F)] = True
    Kd = gauss_curvature(V, F, boundary="defect")
    Kg = gauss_curvature(V, F, boundary="geodesic")
    Kn = gauss_curvature(V, F)
    igl_defect = igl.gaussian_curvature(V, F)
    # "defect" = eq. (2.5) without Neumann data = libigl's angle defect
    assert _total(V, F, Kd) == pytest.approx(igl_defect.sum(), abs=1e-11)
    # geodesic boundary (κ̄ = 0, ā = π): disc, χ = 1 -> 2π
    assert _total(V, F, Kg) == pytest.approx(2 * np.pi, abs=1e-11)
    # natural: interior sources only = 2πχ - ∮ κ_g (discrete boundary turning)
    theta = np.bincount(F.ravel(), weights=intrinsic_angles(igl.edge_lengths(V, F) ** 2).ravel())
    turning = (np.pi - theta[bv]).sum()
    assert _total(V, F, Kn) == pytest.approx(2 * np.pi - turning, abs=1e-11)
    assert abs(turning) > 0.1


def test_agreement_with_libigl():
    V, F = _sphere(2, seed=3)
    # load vector = igl.gaussian_curvature, mass matrix = igl.massmatrix FULL
    lsq, _ = squared_edge_lengths(V, F)
    np.testing.assert_allclose(angle_defect(lsq, F), igl.gaussian_curvature(V, F), atol=1e-13)
    K = gauss_curvature(V, F)
    np.testing.assert_allclose(igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_FULL) @ K,
                               igl.gaussian_curvature(V, F), atol=1e-13)
    # lumped = igl.gaussian_curvature / barycentric area (the classic discrete K)
    Kl = gauss_curvature(V, F, mass="lumped", boundary="defect")
    Mb = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    np.testing.assert_allclose(Kl, igl.gaussian_curvature(V, F) / Mb, rtol=1e-12)
    # intrinsic areas and angles agree with the embedded ones
    np.testing.assert_allclose(intrinsic_areas(igl.edge_lengths(V, F) ** 2), igl.doublearea(V, F) / 2,
                               rtol=1e-12)
    M = intrinsic_mass_matrix(igl.edge_lengths(V, F) ** 2, F, len(V))
    assert abs(M - igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_FULL)).max() < 1e-15


def test_rigid_motion_invariance():
    V, F = torus_coarse(seed=2)
    rng = np.random.default_rng(7)
    Q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    if np.linalg.det(Q) < 0:
        Q[:, 0] *= -1
    W = V @ Q.T + rng.standard_normal(3) * 10
    np.testing.assert_allclose(gauss_curvature(W, F), gauss_curvature(V, F), atol=1e-10)
    # a reflection (orientation reversing) too, once F is flipped to stay consistent
    np.testing.assert_allclose(gauss_curvature(V * [1, 1, -1], F[:, ::-1]), gauss_curvature(V, F),
                               atol=1e-10)


def test_from_edge_lengths_alone():
    V, F = _sphere(1, seed=5)
    lsq, uE = squared_edge_lengths(V, F)
    K = gauss_curvature(V, F)
    np.testing.assert_allclose(gauss_curvature_intrinsic(lsq, F), K, atol=1e-13)     # per edge
    np.testing.assert_allclose(gauss_curvature_intrinsic(igl.edge_lengths(V, F) ** 2, F), K,
                               atol=1e-13)                                             # per corner
    # an intrinsic mesh with no coordinates: the flat torus (periodic 4×4 grid,
    # unit legs, diagonals √2) has K_h ≡ 0 and total curvature 0 = 2πχ
    n = 4
    idx = lambda i, j: (i % n) * n + (j % n)  # noqa: E731
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a, b = i.ravel(), j.ravel()
    F = np.concatenate([np.stack([idx(a, b), idx(a + 1, b), idx(a + 1, b + 1)], 1),
                        np.stack([idx(a, b), idx(a + 1, b + 1), idx(a, b + 1)], 1)])
    lsq = np.tile([1.0, 2.0, 1.0], (len(F), 1))      # opposite corners 0, 1, 2
    lsq[len(F) // 2:] = [1.0, 1.0, 2.0]
    Kt = gauss_curvature_intrinsic(lsq, F)
    assert Kt.shape == (n * n,)
    np.testing.assert_allclose(Kt, 0.0, atol=1e-12)
    # and a cone: 5 unit equilateral triangles around a vertex (defect 2π - 5π/3)
    Fc = np.array([[0, k + 1, (k + 1) % 5 + 1] for k in range(5)])
    Kc = gauss_curvature_intrinsic(np.ones((5, 3)), Fc, boundary="defect", mass="lumped")
    assert Kc[0] == pytest.approx((2 * np.pi - 5 * np.pi / 3) / (5 * np.sqrt(3) / 4 / 3))


def test_weak_convergence_on_jittered_sphere():
    """∫ K_h u dA → ∫ K u dA = 4π/3 for u = z² + x on the unit sphere.

    Measured: EOC 2.37, 2.09, 2.02, 2.01 (L2 error of K_h itself decays like h
    on these uniformly refined meshes, but is not expected to converge in general)."""
    V0, F0 = _sphere(1, seed=0)
    errs, hs = [], []
    for V, F in mesh_sequence(V0, F0, Sphere(), 4):
        M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_FULL)
        u = V[:, 2] ** 2 + V[:, 0]
        errs.append(abs(u @ (M @ gauss_curvature(V, F)) - 4 * np.pi / 3))
        hs.append(igl.edge_lengths(V, F).max())
    e = np.log(np.array(errs[:-1]) / errs[1:]) / np.log(np.array(hs[:-1]) / hs[1:])
    assert e[-2:].min() >= 1.8, e
    assert errs[-1] < 5e-4


def test_bad_input():
    V, F = _sphere(0)
    lsq = igl.edge_lengths(V, F) ** 2
    with pytest.raises(ValueError, match="l_sq must have shape"):
        gauss_curvature_intrinsic(lsq[:, :2], F)
    with pytest.raises(ValueError, match="finite and positive"):
        gauss_curvature_intrinsic(-lsq, F)
    bad = lsq.copy()
    bad[3] = [1.0, 1.0, 9.0]
    with pytest.raises(ValueError, match="triangle inequality"):
        gauss_curvature_intrinsic(bad, F)
    bad = lsq.copy()
    bad[3, 0] *= 1.01
    with pytest.raises(ValueError, match="not a Regge metric"):
        gauss_curvature_intrinsic(bad, F)
    with pytest.raises(TypeError, match="real numbers"):
        gauss_curvature_intrinsic(lsq.astype(str), F)
    with pytest.raises(TypeError, match="integer vertex indices"):
        gauss_curvature_intrinsic(lsq, F.astype(float))
    with pytest.raises(ValueError, match="boundary must be one of"):
        gauss_curvature(V, F, boundary="dirichlet")
    with pytest.raises(ValueError, match="mass must be one of"):
        gauss_curvature(V, F, mass="voronoi")
    Fn = np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]])
    with pytest.raises(ValueError, match="non-manifold"):
        gauss_curvature_intrinsic(np.ones((3, 3)), Fn)
    with pytest.raises(ValueError, match="shape"):
        gauss_curvature(V[:, :2], F)


def test_unreferenced_vertices_are_nan():
    V, F = _sphere(0)
    K = gauss_curvature(np.vstack([V, [[5.0, 5, 5]]]), F)
    assert np.isnan(K[-1]) and np.isfinite(K[:-1]).all()


@pytest.mark.parametrize("name", ["bunny.off", "fertility.off", "camelhead.off"])
def test_gauss_bonnet_on_real_meshes(name):
    import os
    path = os.path.join("/work/shared/data/meshes", name)
    if not os.path.exists(path):
        pytest.skip(f"{path} not available")
    V, F = igl.read_triangle_mesh(path)
    K = gauss_curvature(V, F, boundary="geodesic")
    nE = igl.edges(F).shape[0]
    chi = len(np.unique(F)) - nE + len(F)
    assert np.nansum(igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_FULL) @ np.nan_to_num(K)) == \
        pytest.approx(2 * np.pi * chi, abs=1e-9)
