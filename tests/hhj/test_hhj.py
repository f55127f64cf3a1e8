"""The HHJ edge-DOF layer: nodality, nn-continuity, tangentiality, A and B, solvers."""
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from igl_hhj.hhj import (
    HHJProjection, SolverDidNotConverge, face_schwarz_preconditioner, face_tensors,
    jump_matrix, local_basis, mass_matrix, nn_moments, solve_spd,
)
from igl_hhj.mesh import TriangleMesh
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially


@pytest.fixture(scope="module")
def mesh():
    V, F = icosphere(2)
    V = jitter_tangentially(V, F, Sphere(), 0.3, seed=3)
    V = V * np.array([1.0, 0.7, 1.3])  # bent, non-uniform, no longer a sphere
    return TriangleMesh(V, F)


def test_nodality(mesh):
    """n_iᵀ φ_j n_i = δ_ij on every face (DOF functionals applied to the basis)."""
    phi = local_basis(mesh)
    D = np.einsum("fia,fjab,fib->fij", mesh.conormals, phi, mesh.conormals)
    np.testing.assert_allclose(D, np.broadcast_to(np.eye(3), D.shape), atol=1e-10)


def test_basis_symmetric_tangential(mesh):
    phi = local_basis(mesh)
    np.testing.assert_allclose(phi, np.swapaxes(phi, -1, -2), atol=1e-14)
    np.testing.assert_allclose(np.einsum("fjab,fb->fja", phi, mesh.face_normals), 0.0, atol=1e-10)


def test_nn_continuity_across_edges(mesh):
    """A random HHJ function has the same nᵀσn seen from both faces of every edge,
    each face using its own conormal (n_a ≠ -n_b on a bent surface)."""
    s = np.random.default_rng(1).normal(size=mesh.n_edges)
    nn = nn_moments(mesh, face_tensors(mesh, s))
    f, i = mesh.edge_faces, mesh.edge_local_index
    np.testing.assert_allclose(nn[f[:, 0], i[:, 0]], s, atol=1e-10)
    np.testing.assert_allclose(nn[f[:, 1], i[:, 1]], s, atol=1e-10)
    # conormals of the two sides really differ from antiparallel here
    na, nb = mesh.conormals[f[:, 0], i[:, 0]], mesh.conormals[f[:, 1], i[:, 1]]
    assert np.max(np.linalg.norm(na + nb, axis=1)) > 1e-2


def test_mass_matrix_spd_and_matches_l2_norm(mesh):
    A = mass_matrix(mesh)
    assert abs(A - A.T).max() < 1e-12
    s = np.random.default_rng(2).normal(size=mesh.n_edges)
    sig = face_tensors(mesh, s)
    l2 = np.sum(mesh.face_areas * np.einsum("fab,fab->f", sig, sig))
    np.testing.assert_allclose(s @ A @ s, l2, rtol=1e-12)
    assert spla.eigsh(A, k=1, which="SA", return_eigenvectors=False)[0] > 0
    assert A.getnnz(axis=1).max() <= 5


def test_jump_matrix_kills_constants_and_is_conormal_jump(mesh):
    B = jump_matrix(mesh)
    np.testing.assert_allclose(B @ np.ones(mesh.n_vertices), 0.0, atol=1e-12)
    w = np.random.default_rng(3).normal(size=mesh.n_vertices)
    grad = np.einsum("fi,fia->fa", w[mesh.F], mesh.barycentric_gradients)
    f, i = mesh.edge_faces, mesh.edge_local_index
    jump = (np.einsum("ea,ea->e", mesh.conormals[f[:, 0], i[:, 0]], grad[f[:, 0]])
            + np.einsum("ea,ea->e", mesh.conormals[f[:, 1], i[:, 1]], grad[f[:, 1]]))
    np.testing.assert_allclose(B @ w, mesh.unique_edge_lengths * jump, atol=1e-10)


def test_flat_mesh_linear_function_has_zero_hessian():
    rng = np.random.default_rng(4)
    P = rng.uniform(size=(60, 2))
    import scipy.spatial
    F = scipy.spatial.Delaunay(P).simplices
    V = np.column_stack([P, np.zeros(len(P))])
    m = TriangleMesh(V, F)
    s = HHJProjection(m).solve((V @ [0.3, -1.2, 0.0] + 2.0)[:, None])
    np.testing.assert_allclose(s, 0.0, atol=1e-10)


def test_cg_matches_direct_and_preconditioner_spd(mesh):
    proj = HHJProjection(mesh)
    R = -(proj.B @ mesh.V)
    X_direct = solve_spd(proj.A, R, method="direct")
    M = face_schwarz_preconditioner(mesh, proj.A, proj.phi)
    X_cg = solve_spd(proj.A, R, method="cg", preconditioner=M)
    np.testing.assert_allclose(X_cg, X_direct, atol=1e-7 * np.abs(X_direct).max())
    X_jac = solve_spd(proj.A, R, method="cg")
    np.testing.assert_allclose(X_jac, X_direct, atol=1e-7 * np.abs(X_direct).max())
    assert abs(M - M.T).max() < 1e-10
    assert spla.eigsh(M, k=1, which="SA", return_eigenvectors=False)[0] > 0


def test_cg_failure_is_a_clear_error(mesh):
    proj = HHJProjection(mesh)
    R = -(proj.B @ mesh.V)
    with pytest.raises(SolverDidNotConverge, match="did not converge in 2 iterations"):
        solve_spd(proj.A, R, method="cg", maxiter=2)
    # "auto" falls back to the direct solver instead
    X = solve_spd(proj.A, R, method="direct")
    with pytest.raises(ValueError, match="unknown solver method"):
        solve_spd(proj.A, R, method="qr")
    assert np.isfinite(X).all()


def test_fixed_dofs_are_kept():
    V, F = icosphere(2)
    keep = V[F].mean(axis=1)[:, 2] < 0.4
    m = TriangleMesh(V, F[keep])
    fixed = m.boundary_edges
    vals = np.zeros((m.n_edges, 1))
    vals[fixed, 0] = 0.7
    for solver in ("direct", "cg"):
        s = HHJProjection(m, fixed_edges=fixed, solver=solver).solve(V[:, :1], fixed_values=vals)
        np.testing.assert_allclose(s[fixed, 0], 0.7)
    with pytest.raises(ValueError, match="fixed_values"):
        HHJProjection(m, fixed_edges=fixed).solve(V[:, :1])
