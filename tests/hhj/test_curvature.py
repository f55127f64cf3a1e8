"""Walker's HHJ shape operator and surface Hessian: rates on non-uniform meshes,
exactness properties, boundary data, invariances."""
import numpy as np
import pytest
from conftest import sequence

import igl_hhj
from igl_hhj.convergence import eoc, l2_error_p1_vs_p0, shape_operator_errors, vertex_errors
from igl_hhj.mesh import TriangleMesh


def _rates(name, levels, boundary="estimate", **kw_fn):
    surface, seq = sequence(name, levels)
    errs = []
    for V, F in seq:
        kw = {k: f(surface, V) for k, f in kw_fn.items()}
        kw["boundary"] = boundary
        errs.append(shape_operator_errors(V, F, igl_hhj.shape_operator(V, F, **kw), surface))
    hs = [e["h"] for e in errs]
    return errs, {k: eoc([e[k] for e in errs], hs) for k in ("S", "kappa_a", "kappa_g", "S_inf", "nu")}


def _exact_l2_norm(surface, V, F):
    m = TriangleMesh(V, F)
    S = surface.shape_operator(m.V)
    return l2_error_p1_vs_p0(m, S, np.zeros((m.n_faces, 3, 3)))


@pytest.mark.parametrize("name,levels", [("ellipsoid", 5), ("torus", 5)])
def test_closed_surface_rates(name, levels):
    """EOC ≥ 0.9 for ‖S‖, ‖κ^a‖, ‖κ^g‖ on the last refinement of a perturbed,
    uniformly refined sequence (Walker Theorem 5.2), and the finest relative
    error is small (a wrong constant cannot hide behind a slope)."""
    errs, rates = _rates(name, levels)
    for key in ("S", "kappa_a", "kappa_g", "nu"):
        assert rates[key][-1] >= 0.9, f"{name} {key}: observed EOCs {np.round(rates[key], 3)}"
        assert rates[key][-2] >= 0.75, f"{name} {key}: observed EOCs {np.round(rates[key], 3)}"
    surface, seq = sequence(name, levels)
    rel = errs[-1]["S"] / _exact_l2_norm(surface, *seq[-1])
    assert rel < 0.08, f"relative L2 error of S_h at the finest level: {rel:.3f}"


def test_saddle_clamped_rates_and_plain_assembly_degrades():
    """Clamped saddle with exact boundary normals converges at O(h) (Walker Table 2);
    without boundary data (plain assembly) the boundary layer costs the rate:
    L2 about h^(1/2)…h^(2/3), max error does not converge at all."""
    errs, rates = _rates("saddle", 5, boundary_normals=lambda s, V: s.normal(V))
    for key in ("S", "kappa_a", "kappa_g", "S_inf"):
        assert rates[key][-1] >= 0.9, f"clamped {key}: EOCs {np.round(rates[key], 3)}"
    plain, prates = _rates("saddle", 5, boundary="plain")
    assert prates["S"][-1] < 0.8, f"plain: EOCs {np.round(prates['S'], 3)}"
    assert prates["S_inf"][-1] < 0.3, f"plain L∞: EOCs {np.round(prates['S_inf'], 3)}"
    assert plain[-1]["S"] > 2 * errs[-1]["S"]


def test_saddle_simply_supported_rates():
    errs, rates = _rates("saddle", 5, boundary_shape_operator=lambda s, V: s.shape_operator(V))
    for key in ("S", "kappa_a", "kappa_g"):
        assert rates[key][-1] >= 0.9, f"simply supported {key}: EOCs {np.round(rates[key], 3)}"


def test_mixed_boundary_partition():
    surface, seq = sequence("saddle", 4)
    V, F = seq[-1]
    ss = V[:, 0] < 0.5
    S_mixed = igl_hhj.shape_operator(V, F, boundary_normals=surface.normal(V),
                                     boundary_shape_operator=surface.shape_operator(V),
                                     simply_supported=ss)
    e_mixed = shape_operator_errors(V, F, S_mixed, surface)["S"]
    e_plain = shape_operator_errors(V, F, igl_hhj.shape_operator(V, F, boundary="plain"), surface)["S"]
    e_clamp = shape_operator_errors(V, F, igl_hhj.shape_operator(
        V, F, boundary_normals=surface.normal(V)), surface)["S"]
    assert e_mixed < 0.7 * e_plain
    assert e_mixed < 1.2 * e_clamp


def test_vertex_recovery_rates():
    """The drop-in's recovered per-vertex curvatures at its smallest smoothing scale
    (radius=1) converge at least at O(h), also in max norm (tests/vertex_stage/test_recovery.py
    checks the default radius against libigl)."""
    surface, seq = sequence("ellipsoid", 5)
    errs = []
    for V, F in seq:
        _, _, PV1, PV2, bad = igl_hhj.principal_curvature(V, F, 1)
        assert bad == []
        errs.append(vertex_errors(V, F, PV1, PV2, surface))
    hs = [e["h"] for e in errs]
    for key in ("k1", "k2", "H", "K", "k_inf"):
        r = eoc([e[key] for e in errs], hs)
        assert r[-1] >= 0.9, f"vertex {key}: EOCs {np.round(r, 3)}"
    assert errs[-1]["k_inf"] < 0.1


def test_sphere_tangential_symmetric_and_sign():
    surface, seq = sequence("sphere", 3)
    V, F = seq[-1]
    m = TriangleMesh(V, F)
    S = igl_hhj.shape_operator(V, F)
    np.testing.assert_allclose(S, np.swapaxes(S, 1, 2), atol=1e-12)
    np.testing.assert_allclose(np.einsum("fab,fb->fa", S, m.face_normals), 0.0, atol=1e-12)
    H = igl_hhj.face_mean_curvature(V, F)
    K = igl_hhj.face_gaussian_curvature(V, F)
    assert abs(np.median(H) - 1.0) < 0.02 and abs(np.median(K) - 1.0) < 0.05
    # reversing the orientation flips the sign (F's order carries the normal)
    H_rev = igl_hhj.face_mean_curvature(V, F[:, ::-1])
    np.testing.assert_allclose(H_rev, -H, atol=1e-10)


def test_face_principal_curvature_consistent():
    surface, seq = sequence("ellipsoid", 3)
    V, F = seq[-1]
    PD1, PD2, PV1, PV2 = igl_hhj.face_principal_curvature(V, F)
    S = igl_hhj.shape_operator(V, F)
    m = TriangleMesh(V, F)
    assert np.all(PV1 >= PV2)
    np.testing.assert_allclose(np.einsum("fa,fab,fb->f", PD1, S, PD1), PV1, atol=1e-10)
    np.testing.assert_allclose(np.einsum("fa,fab,fb->f", PD2, S, PD2), PV2, atol=1e-10)
    np.testing.assert_allclose(np.einsum("fa,fa->f", PD1, PD2), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.einsum("fa,fa->f", PD1, m.face_normals), 0.0, atol=1e-12)
    np.testing.assert_allclose(PV1 + PV2, np.trace(S, axis1=1, axis2=2), atol=1e-10)


def test_rigid_motion_and_scaling():
    surface, seq = sequence("torus", 2)
    V, F = seq[-1]
    S = igl_hhj.shape_operator(V, F)
    rng = np.random.default_rng(5)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(Q) < 0:
        Q[:, 0] *= -1
    t = rng.normal(size=3)
    S_rot = igl_hhj.shape_operator(V @ Q.T + t, F)
    np.testing.assert_allclose(S_rot, Q @ S @ Q.T, atol=1e-9)
    S_scaled = igl_hhj.shape_operator(3.0 * V, F)
    np.testing.assert_allclose(S_scaled, S / 3.0, atol=1e-9)


# ---------------------------------------------------------------- surface Hessian
def _hessian_rates(name, levels, exact):
    surface, seq = sequence(name, levels)
    errs, hs = [], []
    for V, F in seq:
        m = TriangleMesh(V, F)
        H_ex, w = exact(surface, m.V)
        errs.append(l2_error_p1_vs_p0(m, H_ex, igl_hhj.surface_hessian(V, F, w)))
        hs.append(m.max_edge_length)
    return np.array(errs), eoc(errs, hs)


def _sphere_z(surface, X):
    P = np.eye(3) - X[:, :, None] * X[:, None, :]
    return -X[:, 2, None, None] * P, X[:, 2]


def _exp_sin(surface, X):
    """w = exp(x) sin(y): ∇_Γ∇_Γ w = P ∇²w P - (ν·∇w) ∇_Γν (checked by finite differences below)."""
    ex, s, c = np.exp(X[:, 0]), np.sin(X[:, 1]), np.cos(X[:, 1])
    g = np.stack([ex * s, ex * c, 0 * ex], axis=1)
    H = np.zeros((len(X), 3, 3))
    H[:, 0, 0], H[:, 0, 1], H[:, 1, 0], H[:, 1, 1] = ex * s, ex * c, ex * c, -ex * s
    nu = surface.normal(X)
    P = np.eye(3) - nu[:, :, None] * nu[:, None, :]
    return P @ H @ P - np.einsum("ij,ij->i", g, nu)[:, None, None] * surface.shape_operator(X), ex * s


def test_exp_sin_exact_hessian_by_finite_differences():
    """Check the closed form: along a geodesic-free test, d²/dt² w(γ(t)) at t=0 for a
    surface curve γ with γ'(0) = d equals dᵀ(∇_Γ∇_Γ w)d + ∇w·γ''(0) tangential part;
    for γ(t) = project(x + t d) the normal part of γ'' carries the -(ν·∇w)S term."""
    from igl_hhj.surfaces import Ellipsoid
    s = Ellipsoid()
    rng = np.random.default_rng(6)
    X = s.project(rng.normal(size=(20, 3)))
    Hex, _ = _exp_sin(s, X)
    nu = s.normal(X)
    d = rng.normal(size=(20, 3))
    d -= np.einsum("ij,ij->i", d, nu)[:, None] * nu
    d /= np.linalg.norm(d, axis=1, keepdims=True)

    def w(P):
        return np.exp(P[:, 0]) * np.sin(P[:, 1])

    def gamma(t):
        return s.project(X + t * d)

    eps = 1e-4
    g0, gp, gm = gamma(0.0), gamma(eps), gamma(-eps)
    second = (w(gp) - 2 * w(g0) + w(gm)) / eps ** 2
    acc = (gp - 2 * g0 + gm) / eps ** 2                    # γ''(0)
    grad = np.stack([np.exp(X[:, 0]) * np.sin(X[:, 1]), np.exp(X[:, 0]) * np.cos(X[:, 1]), 0 * X[:, 0]], 1)
    P = np.eye(3) - nu[:, :, None] * nu[:, None, :]
    tang_acc = np.einsum("nab,nb->na", P, acc)
    # d²/dt² w(γ) = dᵀ ∇²w d + ∇w·γ'' ; the surface Hessian removes the tangential
    # acceleration and keeps the normal one: dᵀ ∇_Γ∇_Γ w d = second - ∇_Γ w · γ''_tan
    lhs = np.einsum("na,nab,nb->n", d, Hex, d)
    rhs = second - np.einsum("na,na->n", np.einsum("nab,nb->na", P, grad), tang_acc)
    np.testing.assert_allclose(lhs, rhs, atol=2e-5)


@pytest.mark.parametrize("name,exact,levels", [("sphere", _sphere_z, 4), ("ellipsoid", _exp_sin, 5)])
def test_surface_hessian_rates(name, exact, levels):
    errs, rates = _hessian_rates(name, levels, exact)
    assert rates[-1] >= 0.9, f"{name}: EOCs {np.round(rates, 3)}"
    assert rates[-2] >= 0.8, f"{name}: EOCs {np.round(rates, 3)}"
    assert errs[-1] < errs[0] / 6


def test_surface_hessian_multiple_columns_and_boundary_gradient():
    surface, seq = sequence("saddle", 4)
    V, F = seq[-1]
    W = np.column_stack([V[:, 0] ** 2, V[:, 1]])
    H2 = igl_hhj.surface_hessian(V, F, W)
    assert H2.shape == (len(F), 2, 3, 3)
    np.testing.assert_allclose(H2[:, 0], igl_hhj.surface_hessian(V, F, W[:, 0]), atol=1e-12)
    # clamped data = exact surface gradient of the coordinate z beats the plain assembly
    nu = surface.normal(V)
    grad_z = np.eye(3)[2] - nu[:, 2, None] * nu
    m = TriangleMesh(V, F)
    nu_f = m.face_normals
    S_ex = surface.shape_operator(m.V)
    H_ex = -nu[:, 2, None, None] * S_ex
    e_data = l2_error_p1_vs_p0(m, H_ex, igl_hhj.surface_hessian(V, F, V[:, 2], boundary_gradient=grad_z))
    e_plain = l2_error_p1_vs_p0(m, H_ex, igl_hhj.surface_hessian(V, F, V[:, 2]))
    assert e_data < 0.7 * e_plain
    del nu_f


# ---------------------------------------------------------------- argument checks
def _open_patch():
    surface, seq = sequence("saddle", 2)
    return surface, seq[-1]


def test_boundary_argument_errors():
    s, (V, F) = _open_patch()
    N = s.normal(V)
    Sx = s.shape_operator(V)
    with pytest.raises(ValueError, match="boundary_normals must have shape"):
        igl_hhj.shape_operator(V, F, boundary_normals=N[:-1])
    with pytest.raises(ValueError, match="points away from the normal"):
        igl_hhj.shape_operator(V, F, boundary_normals=-N)
    Nn = N.copy()
    Nn[0] = np.nan   # vertex 0 = corner (0, 0) of the square is on the boundary
    with pytest.raises(ValueError, match="NaN or inf at boundary vertex 0"):
        igl_hhj.shape_operator(V, F, boundary_normals=Nn)
    with pytest.raises(ValueError, match="pass simply_supported"):
        igl_hhj.shape_operator(V, F, boundary_normals=N, boundary_shape_operator=Sx)
    with pytest.raises(ValueError, match="simply_supported needs boundary_shape_operator"):
        igl_hhj.shape_operator(V, F, boundary_normals=N, simply_supported=np.ones(len(V), bool))
    with pytest.raises(TypeError, match="boolean"):
        igl_hhj.shape_operator(V, F, boundary_normals=N, boundary_shape_operator=Sx,
                               simply_supported=np.ones(len(V)))
    with pytest.raises(ValueError, match=r"boundary_shape_operator must have shape \(\d+, 3, 3\)"):
        igl_hhj.shape_operator(V, F, boundary_shape_operator=Sx[:, :2])
    with pytest.raises(ValueError, match="w must have shape"):
        igl_hhj.surface_hessian(V, F, np.zeros(len(V) + 1))
    w = V[:, 0].copy()
    w[3] = np.inf
    with pytest.raises(ValueError, match="w has NaN or inf at vertex 3"):
        igl_hhj.surface_hessian(V, F, w)
    with pytest.raises(ValueError, match="unknown solver"):
        igl_hhj.shape_operator(V, F, solver="magic")
    with pytest.raises(TypeError, match="boundary_normal"):
        igl_hhj.face_principal_curvature(V, F, boundary_normal=N)   # misspelled keyword


def test_interior_data_rows_may_be_nan():
    """Only boundary rows of boundary data are read."""
    s, (V, F) = _open_patch()
    m = TriangleMesh(V, F)
    N = s.normal(V)
    N[~m.boundary_vertices] = np.nan
    S = igl_hhj.shape_operator(V, F, boundary_normals=N)
    assert np.isfinite(S).all()


def test_huge_radius_is_one_value_error():
    """radius=10**300 used to raise OverflowError (smoothing: TypeError from np.isfinite)."""
    from igl_hhj.surfaces import icosphere
    V, F = icosphere(1)
    for big in (10**300, 10**6 + 1):
        with pytest.raises(ValueError, match=r"radius must be <= 10\*\*6"):
            igl_hhj.principal_curvature(V, F, radius=big)
        with pytest.raises(ValueError, match=r"smoothing must be .*<= 10\*\*6"):
            igl_hhj.face_principal_curvature(V, F, smoothing=big)
    with pytest.raises(ValueError, match="smoothing must be"):
        igl_hhj.face_principal_curvature(V, F, smoothing=float("nan"))


def test_non_symmetric_boundary_shape_operator_names_the_vertex():
    s, (V, F) = _open_patch()
    Sx = s.shape_operator(V).copy()
    Sx[0, 0, 1] += 0.5                      # vertex 0 is on the boundary (corner of the square)
    with pytest.raises(ValueError, match="not symmetric at boundary vertex 0"):
        igl_hhj.shape_operator(V, F, boundary_shape_operator=Sx)
    igl_hhj.shape_operator(V, F, boundary_shape_operator=s.shape_operator(V))   # symmetric: fine


def test_message_hints():
    from igl_hhj.mesh import TriangleMesh
    from igl_hhj.surfaces import icosphere
    V, F = icosphere(1)
    with pytest.raises(TypeError, match="V is a TriangleMesh; pass the mesh object alone"):
        igl_hhj.principal_curvature(TriangleMesh(V, F), F)
    with pytest.raises(ValueError, match="w is required"):
        igl_hhj.surface_hessian(V, F, None)
    Vm = np.ma.masked_array(V, mask=np.zeros(V.shape, bool))
    Vm[3, 1] = np.ma.masked
    with pytest.raises(ValueError, match="V is a masked array with 1 masked entries"):
        igl_hhj.principal_curvature(Vm, F)
    Fm = np.ma.masked_array(F)
    Fm[0, 0] = np.ma.masked
    with pytest.raises(ValueError, match="F is a masked array"):
        igl_hhj.face_mean_curvature(V, Fm)
    igl_hhj.face_mean_curvature(np.ma.masked_array(V), F)          # nothing masked: accepted


def test_masked_data_arrays_are_refused_not_unmasked():
    """A masked w, boundary_gradient or simply_supported is refused (np.asarray would use
    the values under the mask)."""
    import numpy as np
    import pytest

    import igl_hhj
    from igl_hhj.surfaces import icosphere
    V, F = icosphere(2)
    w = np.ma.masked_array(V[:, 0], mask=np.zeros(len(V), bool))
    w.mask[3] = True
    with pytest.raises(ValueError, match="w is a masked array"):
        igl_hhj.surface_hessian(V, F, w)
    keep = V[:, 2] < 0.5
    Fo = F[keep[F].all(axis=1)]
    G = np.ma.masked_array(np.zeros((len(V), 3)), mask=np.zeros((len(V), 3), bool))
    G.mask[0, 0] = True
    with pytest.raises(ValueError, match="boundary_gradient is a masked array"):
        igl_hhj.surface_hessian(V, Fo, V[:, 0], boundary_gradient=G)
    S = np.broadcast_to(np.eye(3), (len(V), 3, 3)).copy()
    flag = np.ma.masked_array(np.ones(len(V), bool), mask=np.zeros(len(V), bool))
    flag.mask[1] = True
    with pytest.raises(ValueError, match="simply_supported is a masked array"):
        igl_hhj.shape_operator(V, Fo, boundary_shape_operator=S, boundary_normals=V, simply_supported=flag)
