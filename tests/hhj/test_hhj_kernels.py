"""The compiled HHJ kernels (assembly, face-Schwarz, S_h, Hessian, boundary-normal fits)
equal the numpy references of igl_hhj.hhj and igl_hhj.boundary_estimation."""

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import sequence

import igl_hhj
from igl_hhj import kernels
from igl_hhj.curvature import _shape_operator
from igl_hhj.errors import SolverError
from igl_hhj.hhj import HHJProjection, face_schwarz_preconditioner, face_tensors, jump_matrix, mass_matrix
from igl_hhj.mesh import DEGENERATE_AREA_RTOL, TriangleMesh, as_mesh
from igl_hhj.surfaces import icosphere
from igl_hhj.surfaces.boundary_data import exact_boundary_normals, exact_boundary_shape_operator
from reference_shape_operator import shape_operator_reference
from kernel_cases import RTOL, bumpy, closed, kernel_meshes, rel, saddle, sliver_mesh  # noqa: F401 (closed, saddle: pytest fixtures)


@pytest.mark.parametrize("name", ["closed", "open", "sliver"])
def test_assembly_and_schwarz_equal_reference(name):
    m = TriangleMesh(*kernel_meshes()[name])
    cols, A, M, _, sin_min = kernels.hhj_system(m)
    n = m.n_edges
    rows = np.repeat(np.arange(n), 5)
    Ac = sp.csr_matrix((A.ravel(), (rows, cols.ravel())), shape=(n, n))
    Mc = sp.csr_matrix((M.ravel(), (rows, cols.ravel())), shape=(n, n))
    Aref = mass_matrix(m)
    assert abs(Ac - Aref).max() <= RTOL * abs(Aref).max()
    Mref = face_schwarz_preconditioner(m, Aref)
    assert abs(Mc - Mref).max() <= RTOL * abs(Mref).max()
    l = m.edge_lengths
    assert rel(sin_min, m.face_double_areas * l.min(axis=1) / l.prod(axis=1)) <= 1e-12
    W = np.random.default_rng(1).normal(size=(m.n_vertices, 3))
    Bw = kernels.jump_apply(m, W)
    assert rel(Bw, jump_matrix(m) @ W) <= RTOL


def test_face_tensors_and_shape_operator_faces(closed):
    s = np.random.default_rng(2).normal(size=(closed.n_edges, 3))
    ref = face_tensors(closed, s)                         # (#F, 3, 3, 3)
    assert rel(kernels.face_tensors(closed, s), ref) <= RTOL
    S_ref = -np.einsum("fkab,fk->fab", ref, closed.face_normals)
    assert rel(kernels.shape_operator_faces(closed, s), S_ref) <= RTOL


def _boundary_cases(surface, m):
    V = m.V
    N = exact_boundary_normals(V, m.F, surface)
    S = exact_boundary_shape_operator(V, m.F, surface)
    ss = V[:, 0] > 0
    return {
        "plain": {},
        "clamped": {"boundary_normals": N},
        "simply_supported": {"boundary_shape_operator": S},
        "mixed": {"boundary_normals": N, "boundary_shape_operator": S, "simply_supported": ss},
    }


@pytest.mark.parametrize("case", ["plain", "clamped", "simply_supported", "mixed"])
@pytest.mark.parametrize("solver", ["direct", "cg"])
def test_shape_operator_equals_reference_with_boundary_data(saddle, case, solver):
    surface, m = saddle
    kw = _boundary_cases(surface, m)[case]
    S = _shape_operator(m, kw.get("boundary_normals"), kw.get("boundary_shape_operator"),
                        kw.get("simply_supported"), solver, rtol=1e-13)
    R = shape_operator_reference(m, **kw)
    assert rel(S, R) <= RTOL


@pytest.mark.parametrize("name", ["closed", "open", "sliver"])
@pytest.mark.parametrize("solver", ["direct", "cg", "auto"])
def test_shape_operator_equals_reference(name, solver):
    m = TriangleMesh(*kernel_meshes()[name])
    S = _shape_operator(m, None, None, None, solver, rtol=1e-13)
    R = shape_operator_reference(m)
    assert np.isfinite(S).all()
    assert rel(S, R) <= RTOL


def test_surface_hessian_equals_reference(saddle):
    _, m = saddle
    W = np.column_stack([np.sin(m.V[:, 0]) * m.V[:, 1], np.exp(m.V[:, 2])])
    H = igl_hhj.surface_hessian(m, None, W, solver="cg", rtol=1e-13)
    proj = HHJProjection(m, solver="direct")
    ref = face_tensors(m, proj.solve(W), proj.phi)
    assert rel(H, ref) <= RTOL
    G = np.random.default_rng(3).normal(size=(m.n_vertices, 2, 3))
    H = igl_hhj.surface_hessian(m, None, W, boundary_gradient=G, solver="direct")
    from igl_hhj.hhj import clamped_load
    load = proj.plain_boundary_load(W)
    bnd = m.boundary_edges
    load[bnd] = clamped_load(m, bnd, G)[bnd]
    ref = face_tensors(m, proj.solve(W, load=load), proj.phi)
    assert rel(H, ref) <= RTOL


def test_sliver_face_schwarz_never_raises():
    """A face of relative area 1e-9 used to make the Schwarz setup raise LinAlgError; validation
    now stops at DEGENERATE_AREA_RTOL, and a face just above it must not either."""
    V, F = sliver_mesh(3 * DEGENERATE_AREA_RTOL)
    m = TriangleMesh(V, F)
    M = face_schwarz_preconditioner(m, mass_matrix(m))
    assert np.isfinite(M.data).all()
    cols, A, Mk, n_jacobi, _ = kernels.hhj_system(m)
    assert n_jacobi >= 1 and np.isfinite(Mk).all()
    for solver in ("direct", "auto"):
        S = igl_hhj.shape_operator(V, F, solver=solver)
        assert np.isfinite(S).all()
    # PCG in floating point cannot solve this (cond(A) ~ 1e20); it must say so promptly
    try:
        S = igl_hhj.shape_operator(V, F, solver="cg")
    except SolverError as exc:
        assert "did not converge" in str(exc)
    else:
        assert np.isfinite(S).all()


def _open_meshes_for_boundary_normals():
    """Open meshes whose boundary normal fits take every branch: a jittered saddle, a
    jittered cap cut from a sphere, a flat 6×6 grid (its corners' 1-rings have < 10
    vertices: one ring more), a strip too small for a fit (fewer than 6 neighbours), and
    a fan whose vertices all lie on two lines (xy ≡ 0: a singular Gram matrix, decided by
    the eigenvalue test, not the cheap condition bound)."""
    surface, seq = sequence("saddle", 3)
    out = {"saddle": seq[-1]}
    V, F = bumpy(2)
    keep = V[F].mean(axis=1)[:, 2] < 0.2
    out["cap"] = (V, F[keep])
    n = 6
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    Vg = np.c_[x.ravel(), y.ravel(), np.zeros(n * n)]
    q = np.arange(n * n).reshape(n, n)[:-1, :-1].ravel()
    Fg = np.r_[np.c_[q, q + 1, q + n + 1], np.c_[q, q + n + 1, q + n]]
    out["flat grid"] = (Vg, Fg)
    out["strip"] = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.1], [0, 2, 0.3]], float),
                    np.array([[0, 1, 2], [1, 3, 2], [2, 3, 4]]))
    Va = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [0, 2, 0], [-1, 0, 0], [-2, 0, 0]], float)
    out["axes"] = (Va, np.array([[0, 1, 3], [1, 2, 3], [3, 2, 4], [0, 3, 5], [5, 3, 4], [5, 4, 6]]))
    return out


@pytest.mark.parametrize("name", ["saddle", "cap", "flat grid", "strip", "axes"])
@pytest.mark.parametrize("rings", [1, 3])
def test_boundary_normal_fits_equal_reference(name, rings):
    """The compiled quadric fits of estimate_boundary_normals equal the numpy reference."""
    from igl_hhj.boundary_estimation import boundary_normal_fits_reference, estimate_boundary_normals
    V, F = _open_meshes_for_boundary_normals()[name]
    m = TriangleMesh(V, F)
    verts = np.flatnonzero(m.boundary_vertices)
    N0 = m.vertex_normals[verts]
    got = kernels.boundary_normal_fits(m, verts, rings, N0)
    ref = boundary_normal_fits_reference(m, verts, rings, N0)
    assert got.shape == (len(verts), 3)
    assert np.allclose(got, ref, rtol=0, atol=1e-12)
    a = estimate_boundary_normals(m, rings)
    b = estimate_boundary_normals(m, rings, reference=True)
    assert np.array_equal(np.isnan(a), np.isnan(b))
    assert np.allclose(a[~np.isnan(b)], b[~np.isnan(b)], rtol=0, atol=1e-12)


def test_boundary_normal_fits_reject_bad_arrays():
    V, F = _open_meshes_for_boundary_normals()["saddle"]
    m = TriangleMesh(V, F)
    verts = np.flatnonzero(m.boundary_vertices)
    N0 = m.vertex_normals[verts]
    with pytest.raises(ValueError, match="boundary_normal_fits"):
        kernels.boundary_normal_fits(m, verts, 3, N0[:-1])
    with pytest.raises(ValueError, match="rings"):
        kernels.boundary_normal_fits(m, verts, 0, N0)
    with pytest.raises(ValueError, match="out of range"):
        kernels.boundary_normal_fits(m, np.r_[verts[:-1], m.n_vertices], 3, N0)


def test_tiny_meshes_take_the_envelope_solve_and_match_the_reference(monkeypatch):
    """A drop-in call on a tiny mesh uses the compiled envelope solve, never scipy's
    sparse factorisation, and its shape operator is the numpy reference's."""
    from igl_hhj import curvature, solvers
    V, F = icosphere(1)
    called = []
    monkeypatch.setattr(solvers, "cholesky_solve", lambda *a, **k: called.append(1))
    S = curvature.shape_operator(V, F)
    assert not called
    monkeypatch.undo()
    ref = shape_operator_reference(as_mesh(V, F))
    assert np.abs(S - ref).max() <= 1e-10 * np.abs(ref).max()
