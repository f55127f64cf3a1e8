"""Walker's HHJ surface Hessian of a general function on curved surfaces
(igl_hhj.curved.surface_hessian; paper 000, eq. 4.9, Theorem 4.1: O(h^{r+1}) for m ≥ r + 1)."""
from __future__ import annotations

import functools

import numpy as np
import pytest

from conftest import sequence
from igl_hhj.benchmarks import walker_hessian as wh
from igl_hhj.convergence import eoc
from igl_hhj.curved import CurvedHHJ, LagrangeSurface, modified_interpolant, shape_operator, surface_hessian
from igl_hhj.curved.hessian import conormal_load


_w, _grad_w, _node_images = wh.w, wh.grad_w, wh.node_images


@functools.cache
def _rates(name, order, degree, levels, boundary="none", data="walker"):
    """(errors, EOCs) of walker_hessian.errors on the test sequences (tests/conftest.py's)."""
    errs, hs = wh.errors(name, order, degree, levels, boundary, data)
    return errs, eoc(errs, hs)


@pytest.mark.slow
@pytest.mark.parametrize("name,order,degree", [
    ("torus", 2, 1), ("ellipsoid", 2, 1), ("torus", 3, 2), ("ellipsoid", 3, 2), ("torus", 3, 1)])
def test_theorem_4_1_rate_closed(name, order, degree):
    """‖σ − σ̂_h‖_L2 = O(h^{r+1}) on non-uniform sequences of closed surfaces (m ≥ r + 1)."""
    errs, rates = _rates(name, order, degree, 3)
    assert rates[-1] >= degree + 0.8, (errs, rates)
    assert errs[-1] < errs[0] / 2 ** (2 * degree + 1), errs


@pytest.mark.slow
@pytest.mark.parametrize("order", [2, 3])
def test_theorem_4_1_rate_clamped_saddle(order):
    """With clamped data ξ̃ = I_h^m ∇_Γ w (eq. 4.9's Σ_c term) the full rate r + 1 holds on a surface
    with boundary.  The plain assembly (discrete gradient as data) is bounded by h^{m-1/2} (its data
    error n̂·(∇ŵ_h - ∇w) = O(h^m) on Σ, times the inverse estimate h^{-1/2}); measured it stays at
    the full rate on these three levels (1.88 vs 1.93 at m = 2, 2.90 vs 2.91 at m = 3).  Zero data
    (a wrong slope) must destroy the convergence: the data enters."""
    errs, rates = _rates("saddle", order, order - 1, 3, "clamped")
    assert rates[-1] >= order - 1 + 0.8, (errs, rates)
    errs_p, rates_p = _rates("saddle", order, order - 1, 3, "none")
    assert rates_p[-1] >= order - 0.5, (errs_p, rates_p)
    errs_0, rates_0 = _rates("saddle", order, order - 1, 3, "zero")
    assert rates_0[-1] < 1.0 and errs_0[-1] > 10 * errs[-1], (errs_0, rates_0)


@pytest.mark.slow
def test_nodal_data_lose_an_order_at_m3():
    """Remark 4.2's interpolant must be Walker's moment interpolant 𝓘_h^{1,m} (Fortin property 4.6):
    nodal values w(Ψ^m(x_a)) on the same surface converge one order slower (measured 2.0 vs 3.0)."""
    _, walker = _rates("torus", 3, 2, 3)
    _, nodal = _rates("torus", 3, 2, 3, data="nodal")
    assert walker[-1] >= 2.8 and nodal[-1] <= 2.3, (walker, nodal)


def test_an_r0_space_on_quadratic_geometry_converges_at_first_order_only():
    """r = 0 on m = 2: Theorem 4.1 gives h^{r+1} = h, not h² (the rate is the HHJ degree's)."""
    errs, rates = _rates("torus", 2, 0, 3)
    assert 0.8 <= rates[-1] <= 1.3, (errs, rates)


@pytest.mark.parametrize("name", ["torus", "saddle"])
def test_coordinate_functions_reproduce_the_shape_operator(name):
    """w = id^k: -Σ ν̂^k σ̂_h^k is shape_operator's S_h (eq. 5.12), closed and plain boundary."""
    s, seq = sequence(name, 1)
    V, F = seq[0]
    surf = LagrangeSurface.from_projection(V, F, 2, s.project)
    H = surface_hessian(surf, surf.nodes)
    S = shape_operator(surf)
    np.testing.assert_allclose(H.coefficients, S.coefficients, atol=1e-10)
    faces, bary, _ = surf.quadrature(4)
    nu = surf.normals(faces, bary)
    np.testing.assert_allclose(-np.einsum("nk,nkij->nij", nu, H(faces, bary)), S(faces, bary), atol=1e-9)


def test_plain_load_cancels_the_one_sided_boundary_term():
    """conormal_load with w = id^k equals CurvedHHJ.boundary_edge_terms without data (both are
    ∫_E φ^nn n̂^k ds) — two independent codings of the same integral."""
    s, seq = sequence("saddle", 1)
    V, F = seq[0]
    surf = LagrangeSurface.from_projection(V, F, 3, s.project)
    space = CurvedHHJ(surf)
    bnd = np.flatnonzero(surf.mesh.boundary_edges)
    np.testing.assert_allclose(conormal_load(space, bnd, w=surf.nodes), space.boundary_edge_terms(bnd), atol=1e-12)


def test_single_and_multiple_columns_agree_and_the_field_is_tangential():
    s, seq = sequence("torus", 1)
    V, F = seq[0]
    surf = LagrangeSurface.from_projection(V, F, 2, s.project)
    Y = _node_images(V, F, surf, s.project)
    W = np.column_stack([_w(Y), Y[:, 2] ** 2])
    H2 = surface_hessian(surf, W)
    H1 = surface_hessian(surf, W[:, 0])
    faces, bary, _ = surf.quadrature(4)
    T2, T1 = H2(faces, bary), H1(faces, bary)
    assert T2.shape == (len(faces), 2, 3, 3) and T1.shape == (len(faces), 3, 3)
    np.testing.assert_allclose(T2[:, 0], T1, atol=1e-10)
    nu = surf.normals(faces, bary)
    assert np.abs(np.einsum("nkij,nj->nki", T2, nu)).max() < 1e-10
    np.testing.assert_allclose(T2, np.swapaxes(T2, -1, -2), atol=1e-12)


def test_bad_input_raises():
    s, seq = sequence("saddle", 1)
    V, F = seq[0]
    surf = LagrangeSurface.from_projection(V, F, 2, s.project)
    with pytest.raises(TypeError, match="LagrangeSurface"):
        surface_hessian((V, F), V[:, 0])
    with pytest.raises(ValueError, match="one row per node"):
        surface_hessian(surf, np.zeros(surf.n_nodes + 1))
    w = np.zeros(surf.n_nodes)
    w[3] = np.nan
    with pytest.raises(ValueError, match="NaN or inf at node 3"):
        surface_hessian(surf, w)
    with pytest.raises(ValueError, match="m >= r \\+ 1"):
        surface_hessian(surf, np.zeros(surf.n_nodes), degree=2)
    with pytest.raises(ValueError, match="boundary_gradient must have shape"):
        surface_hessian(surf, np.zeros(surf.n_nodes), boundary_gradient=np.zeros((surf.n_nodes, 2)))
    G = np.zeros((surf.n_nodes, 3))
    G[np.flatnonzero(surf.boundary_nodes)[0]] = np.inf
    with pytest.raises(ValueError, match="NaN or inf at a boundary node"):
        surface_hessian(surf, np.zeros(surf.n_nodes), boundary_gradient=G)


def test_modified_interpolant_of_the_coordinates_is_the_node_placement():
    """𝓘_h^{1,m}(id ∘ F_T) are the nodes of Γ^m (the same eq. 4.2 rule); more than 3 columns work."""
    s, seq = sequence("torus", 1)
    V, F = seq[0]
    for order in (1, 2, 3):
        surf = LagrangeSurface.from_projection(V, F, order, s.project)
        X = modified_interpolant(V, F, order, lambda P: np.column_stack([P, P[:, 0] * P[:, 1]]), project=s.project)
        np.testing.assert_allclose(X[:, :3], surf.nodes, atol=1e-13)
        assert X.shape == (surf.n_nodes, 4)
    with pytest.raises(TypeError, match="exactly one"):
        modified_interpolant(V, F, 2, _w)
    with pytest.raises(TypeError, match="callable"):
        modified_interpolant(V, F, 2, np.zeros(3), project=s.project)


def test_benchmark_sequences_are_the_test_sequences():
    for name in ("torus", "ellipsoid", "saddle"):
        _, a = sequence(name, 2)
        _, b = wh.sequence(name, 2)
        for (Va, Fa), (Vb, Fb) in zip(a, b):
            np.testing.assert_array_equal(Fa, Fb)
            np.testing.assert_allclose(Va, Vb, atol=0)


def test_exact_hessian_by_finite_differences_on_the_torus():
    """dᵀ(∇_Γ∇_Γ w)d = d²/dt² w(γ(t)) − ∇_Γ w·γ''(0) for γ(t) = π(x + t d), d tangent."""
    from igl_hhj.surfaces import WalkerTorus
    s = WalkerTorus()
    rng = np.random.default_rng(3)
    X = s.project(rng.normal(size=(20, 3)))
    nu = s.normal(X)
    d = rng.normal(size=(20, 3))
    d -= np.einsum("ij,ij->i", d, nu)[:, None] * nu
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    eps = 1e-4
    g0, gp, gm = X, s.project(X + eps * d), s.project(X - eps * d)
    second = (_w(gp) - 2 * _w(g0) + _w(gm)) / eps ** 2
    acc = (gp - 2 * g0 + gm) / eps ** 2
    P = np.eye(3) - nu[:, :, None] * nu[:, None, :]
    rhs = second - np.einsum("na,na->n", np.einsum("nab,nb->na", P, _grad_w(X)), np.einsum("nab,nb->na", P, acc))
    np.testing.assert_allclose(np.einsum("na,nab,nb->n", d, wh.exact_hessian(s, X), d), rhs, atol=2e-5)
