"""Curved higher-order surfaces (igl_hhj.curved): Walker's HHJ shape operator on
Lagrange triangles of order m = 2, 3 (HHJ degree r = m - 1), geometry, validation."""
from __future__ import annotations

import functools

import numpy as np
import pytest

from conftest import sequence
from igl_hhj import surfaces as su
from igl_hhj.convergence import eoc
from igl_hhj.curved import CurvedHHJ, LagrangeSurface, shape_operator
from igl_hhj.curved.errors import shape_operator_errors


def _sphere_levels(n):
    return sequence("sphere", n)


@functools.cache
def _rates(name, order, levels, boundary="none", interpolant="walker"):
    s, seq = sequence(name, levels)
    errs, hs = [], []
    for V, F in seq:
        surf = LagrangeSurface.from_projection(V, F, order, s.project, interpolant=interpolant)
        kw = {}
        if boundary == "clamped":
            kw["boundary_normals"] = s.normal(surf.nodes)
        elif boundary == "simply_supported":
            kw["boundary_shape_operator"] = s.shape_operator(surf.nodes)
        e = shape_operator_errors(shape_operator(surf, **kw), s)
        errs.append(e["S"])
        hs.append(e["h"])
    return np.array(errs), eoc(errs, hs)


# ----------------------------------------------------------------------------- rates
@pytest.mark.slow
@pytest.mark.parametrize("name,levels,boundary", [
    ("sphere", 3, "none"), ("torus", 3, "none"), ("saddle", 3, "clamped")])
def test_eoc_m2(name, levels, boundary):
    errs, rates = _rates(name, 2, levels, boundary)
    assert rates[-1] >= 1.8, (errs, rates)


@pytest.mark.slow
@pytest.mark.parametrize("name,levels,boundary", [
    ("sphere", 3, "none"), ("torus", 3, "none"), ("saddle", 3, "clamped")])
def test_eoc_m3(name, levels, boundary):
    errs, rates = _rates(name, 3, levels, boundary)
    assert rates[-1] >= 2.7, (errs, rates)


@pytest.mark.slow
def test_eoc_simply_supported_saddle():
    for m, lo in ((2, 1.8), (3, 2.7)):
        errs, rates = _rates("saddle", m, 3, "simply_supported")
        assert rates[-1] >= lo, (m, errs, rates)


@pytest.mark.slow
def test_modified_interpolant_is_needed_for_m3():
    """Walker §4.5: for m = r + 1 the modified interpolant (4.14) is necessary; the
    standard nodal one loses an order at m = 3 (measured: EOC 2.1 vs 3.1 on the sphere)."""
    _, walker = _rates("sphere", 3, 3)
    _, nodal = _rates("sphere", 3, 3, interpolant="nodal")
    assert walker[-1] >= 2.7 and nodal[-1] <= 2.4, (walker, nodal)


def test_m1_reproduces_the_flat_matrices():
    from igl_hhj.hhj import jump_matrix, mass_matrix
    from igl_hhj.mesh import as_mesh
    s, seq = _sphere_levels(1)
    V, F = seq[0]
    A, B = CurvedHHJ(LagrangeSurface.from_projection(V, F, 1, s.project)).matrices
    mesh = as_mesh(V, F)
    assert abs(A - mass_matrix(mesh)).max() < 1e-12
    assert abs(B - jump_matrix(mesh)).max() < 1e-12


# ----------------------------------------------------------------------------- geometry
@pytest.mark.parametrize("order", [1, 2, 3])
def test_sphere_area_converges_like_h_2m(order):
    s, seq = _sphere_levels(3)
    errs, hs = [], []
    for V, F in seq:
        surf = LagrangeSurface.from_projection(V, F, order, s.project)
        errs.append(abs(surf.area() - 4 * np.pi))
        hs.append(surf.h)
    rates = eoc(errs, hs)
    assert rates[-1] >= 2 * order - 0.3, (errs, rates)


@pytest.mark.parametrize("order", [2, 3])
def test_points_and_normals_converge_to_the_sphere(order):
    """max distance to Γ = O(h^{m+1}), normal error = O(h^m) at random points."""
    s, seq = _sphere_levels(3)
    rng = np.random.default_rng(0)
    dist, nerr, hs = [], [], []
    for V, F in seq:
        surf = LagrangeSurface.from_projection(V, F, order, s.project)
        b = rng.dirichlet(np.ones(3), 400)
        f = rng.integers(0, surf.n_faces, 400)
        X = surf.points(f, b)
        N = surf.normals(f, b)
        dist.append(np.abs(np.linalg.norm(X, axis=1) - 1).max())
        nerr.append(np.linalg.norm(N - X / np.linalg.norm(X, axis=1, keepdims=True), axis=1).max())
        hs.append(surf.h)
    assert eoc(dist, hs)[-1] >= order + 1 - 0.4, dist
    assert eoc(nerr, hs)[-1] >= order - 0.3, nerr
    # corners of the curved triangles are the mesh vertices
    corner = surf.points(np.arange(surf.n_faces), np.tile([1.0, 0, 0], (surf.n_faces, 1)))
    assert np.allclose(corner, surf.nodes[surf.elements[:, 0]])


# ----------------------------------------------------------------------------- HHJ space
@pytest.mark.parametrize("order", [2, 3])
def test_nn_continuity_across_curved_edges(order):
    s, seq = sequence("torus", 1)
    V, F = seq[0]
    surf = LagrangeSurface.from_projection(V, F, order, s.project)
    space = CurvedHHJ(surf)
    c = np.random.default_rng(1).standard_normal((space.n_dofs, 1))
    mesh = surf.mesh
    e = np.flatnonzero((mesh.edge_faces >= 0).all(1))
    t = np.array([0.0, 0.21, 0.5, 0.77, 1.0])
    for tk in t:
        fa, ja = mesh.edge_faces[e, 0], mesh.edge_local_index[e, 0]
        fb, jb = mesh.edge_faces[e, 1], mesh.edge_local_index[e, 1]
        a = space.nn_trace(c, fa, ja, np.full(len(e), tk))
        b = space.nn_trace(c, fb, jb, np.full(len(e), 1 - tk))   # opposite direction
        scale = np.abs(a).max()
        assert np.abs(a - b).max() <= 1e-10 * scale
        # the tangent-tangent part is not continuous (a bent surface): the test can fail
    sig = space.tensors(c, np.array([0]), np.array([[0.2, 0.3, 0.5]]))[0, 0]
    nu = surf.normals(np.array([0]), np.array([[0.2, 0.3, 0.5]]))[0]
    assert np.abs(sig - sig.T).max() < 1e-12 and np.abs(sig @ nu).max() < 1e-10 * np.abs(sig).max()


def test_field_is_symmetric_tangential_and_curvatures():
    s, seq = _sphere_levels(2)
    V, F = seq[1]
    surf = LagrangeSurface.from_projection(V, F, 2, s.project)
    fld = shape_operator(surf)
    f, b, _ = surf.quadrature()
    S = fld(f, b)
    nu = surf.normals(f, b)
    assert np.abs(S - np.swapaxes(S, 1, 2)).max() < 1e-12
    assert np.abs(np.einsum("nij,nj->ni", S, nu)).max() < 1e-10
    k1, k2, d1, d2 = fld.principal(f, b)
    assert np.all(k1 >= k2)
    assert abs(np.median(k1) - 1) < 0.05 and abs(np.median(k2) - 1) < 0.05
    assert np.abs(np.einsum("ni,ni->n", d1, nu)).max() < 1e-8
    assert abs(np.median(fld.gaussian_curvature(f, b)) - 1) < 0.05
    nv = fld.node_values()
    assert nv["H"].shape == (surf.n_nodes,) and abs(np.median(nv["H"]) - 1) < 0.05


# ----------------------------------------------------------------------------- validation
def _square(n=3, amount=0.0):
    P, F = su.square_grid(n, amount=amount)
    return np.column_stack([P, np.zeros(len(P))]), F


def _quad_disk():
    V, F = _square()
    surf = LagrangeSurface.from_projection(V, F, 2, lambda X: X)
    return surf


def test_validation_errors():
    surf = _quad_disk()
    P, E = np.array(surf.nodes), np.array(surf.elements)
    with pytest.raises(ValueError, match="3, 6, 10 or 15 columns"):
        LagrangeSurface(P, E[:, :5])
    with pytest.raises(ValueError, match="out of range"):
        LagrangeSurface(P, np.where(E == E.max(), len(P), E))
    with pytest.raises(ValueError, match="NaN"):
        Q = P.copy()
        Q[3, 1] = np.nan
        LagrangeSurface(Q, E)
    with pytest.raises(ValueError, match=r"shape \(#N, 3\)"):
        LagrangeSurface(P[:, :2], E)
    with pytest.raises(TypeError):
        LagrangeSurface(P, E.astype(float) + 0.5)
    with pytest.raises(TypeError):
        LagrangeSurface(np.array([["a", "b", "c"]]), E)
    with pytest.raises(ValueError, match="repeats"):
        Er = E.copy()
        Er[0, 3] = Er[0, 0]
        LagrangeSurface(P, Er)
    # a neighbour with its own copy of the shared edge node: not conforming
    mesh = surf.mesh
    e = int(np.flatnonzero((mesh.edge_faces >= 0).all(1))[0])
    f, j = mesh.edge_faces[e, 1], mesh.edge_local_index[e, 1]
    from igl_hhj.curved.reference import edge_node_slots
    En = E.copy()
    slot = edge_node_slots(2)[j][0]
    P2 = np.vstack([P, P[E[f, slot]]])
    En[f, slot] = len(P)
    with pytest.raises(ValueError, match="not conforming"):
        LagrangeSurface(P2, En)
    # a folded element: its edge node pulled across the triangle
    Pf = P.copy()
    Pf[E[0, 3]] += 3.0 * (P[E[0, 2]] - P[E[0, 3]])
    with pytest.raises(ValueError, match="degenerate or folds"):
        LagrangeSurface(Pf, E)


def test_int32_float32_inputs():
    surf = _quad_disk()
    a = LagrangeSurface(surf.nodes.astype(np.float32), surf.elements.astype(np.int32))
    assert a.nodes.dtype == np.float64 and a.elements.dtype == np.int64
    V, F = _square()
    b = LagrangeSurface.from_projection(V.astype(np.float32), F.astype(np.int32), 3, lambda X: X)
    assert abs(b.area() - 1.0) < 1e-6
    assert b.points(np.array([0], dtype=np.int32), np.array([[1, 0, 0]], dtype=np.float32)).shape == (1, 3)


def test_from_projection_and_shape_operator_errors():
    V, F = _square()
    with pytest.raises(ValueError, match="order"):
        LagrangeSurface.from_projection(V, F, 4, lambda X: X)
    with pytest.raises(TypeError, match="callable"):
        LagrangeSurface.from_projection(V, F, 2, None)
    with pytest.raises(ValueError, match="shape"):
        LagrangeSurface.from_projection(V, F, 2, lambda X: X[:, :2])
    with pytest.raises(ValueError, match="interpolant"):
        LagrangeSurface.from_projection(V, F, 2, lambda X: X, interpolant="spline")
    surf = LagrangeSurface.from_projection(V, F, 2, lambda X: X)
    with pytest.raises(TypeError):
        shape_operator((V, F))
    with pytest.raises(ValueError, match="one row per node"):
        shape_operator(surf, boundary_normals=np.ones((3, 3)))
    with pytest.raises(ValueError, match="needs boundary_shape_operator"):
        shape_operator(surf, simply_supported=np.ones(surf.n_nodes, bool))
    with pytest.raises(ValueError, match="point away"):
        shape_operator(surf, boundary_normals=np.tile([0, 0, -1.0], (surf.n_nodes, 1)))
    with pytest.raises(ValueError, match="NaN"):
        N = np.tile([0, 0, 1.0], (surf.n_nodes, 1))
        N[surf.boundary_nodes.nonzero()[0][0]] = np.nan
        shape_operator(surf, boundary_normals=N)


def test_boundary_data_needed_only_on_the_boundary():
    s, seq = sequence("saddle", 1)
    V, F = seq[0]
    surf = LagrangeSurface.from_projection(V, F, 2, s.project)
    N = s.normal(surf.nodes)
    full = shape_operator(surf, boundary_normals=N)
    N[~surf.boundary_nodes] = np.nan
    part = shape_operator(surf, boundary_normals=N)
    assert np.allclose(full.coefficients, part.coefficients, rtol=0, atol=1e-12 * np.abs(full.coefficients).max())


def test_flat_square_has_zero_shape_operator():
    V, F = _square(4, 0.2)
    surf = LagrangeSurface.from_projection(V, F, 3, lambda X: X)
    fld = shape_operator(surf, boundary_normals=np.tile([0, 0, 1.0], (surf.n_nodes, 1)))
    f, b, _ = surf.quadrature()
    assert np.abs(fld(f, b)).max() < 1e-10


def test_meshio_round_trip(tmp_path):
    meshio = pytest.importorskip("meshio")
    s, seq = _sphere_levels(1)
    V, F = seq[0]
    surf = LagrangeSurface.from_projection(V, F, 3, s.project)
    m = surf.to_meshio()
    assert isinstance(m, meshio.Mesh)
    back = LagrangeSurface.from_meshio(m)
    assert back.order == 3 and np.array_equal(back.elements, surf.elements)
    path = tmp_path / "sphere3.msh"          # gmsh's own triangle10 order, through a file
    meshio.write(str(path), m, file_format="gmsh22", binary=False)
    again = LagrangeSurface.from_meshio(str(path))
    assert np.array_equal(again.elements, surf.elements) and np.allclose(again.nodes, surf.nodes)
    assert abs(again.area() - surf.area()) < 1e-12
    with pytest.raises(TypeError):
        LagrangeSurface.from_meshio(42)


# ----------------------------------------------------------------------------- Heine
def test_heine_degree1_equals_the_baseline():
    from igl_hhj.baselines import heine_weingarten_map
    from igl_hhj.curved import heine_weingarten
    from igl_hhj.surfaces.heine import heine_sequence
    seq, s = heine_sequence("5.1a", 2, jitter=0.3, seed=100)
    V, F = seq[1]
    fld = heine_weingarten(LagrangeSurface.from_projection(V, F, 1, s.project), 1)
    Pi, nu, Y = heine_weingarten_map(V, F)
    assert np.abs(fld.coefficients - Pi).max() < 1e-10 * np.abs(Pi).max()
    assert np.abs(fld.raw["nu"] - nu).max() < 1e-10
    assert np.abs(fld.raw["Y"] - Y).max() < 1e-10 * np.abs(Y).max()


@functools.cache
def _heine_rates(label, degree, levels=4):
    from igl_hhj.benchmarks.heine_curved import heine_errors
    from igl_hhj.curved import heine_weingarten
    from igl_hhj.surfaces.heine import heine_sequence
    seq, s = heine_sequence(label, levels, pre_refine=1, jitter=0.3, seed=100)
    rows = []
    for V, F in seq:
        surf = LagrangeSurface.from_projection(V, F, degree, s.project, interpolant="nodal")
        rows.append(heine_errors(heine_weingarten(surf, degree), s))
    hs = [r["h"] for r in rows]
    return {k: eoc([r[k] for r in rows], hs) for k in ("K2", "H2", "Y2", "Pi2")}


@pytest.mark.slow
def test_heine_degree2_converges_degree1_does_not():
    """Heine Tables 5.1–5.4: γ = 2 converges (EOC 1.1–2.4 there), γ = 1 does not
    (measured on the re-jittered ellipsoid sequence: γ = 2 EOC ≈ 1.3; γ = 1 ≈ 0)."""
    r2 = _heine_rates("5.1c", 2)
    r1 = _heine_rates("5.1c", 1)
    assert r2["K2"][-1] >= 1.0 and r2["H2"][-1] >= 1.0, r2
    assert r1["H2"][-1] <= 0.5, r1


@pytest.mark.slow
def test_order4_surface_nodal_interpolant():
    """Order m = 4 (gmsh triangle15, nodal interpolant of the projection): the sphere's area
    error falls at ≥ h^5 (measured EOC 8.9, 5.7); Walker's modified interpolant is m ≤ 3 only."""
    from igl_hhj.surfaces.heine import heine_sequence
    seq, s = heine_sequence("5.1d", 3, pre_refine=1, jitter=0.3, seed=100)
    err, hs = [], []
    for V, F in seq:
        surf = LagrangeSurface.from_projection(V, F, 4, s.project, interpolant="nodal")
        assert surf.order == 4 and surf.elements.shape[1] == 15
        err.append(abs(surf.area() - 4 * np.pi))
        hs.append(surf.h)
    assert eoc(err, hs).min() >= 4.5, (err, eoc(err, hs))
    assert err[-1] < 1e-8
    again = LagrangeSurface(surf.nodes, surf.elements)      # the generic constructor takes 15 columns
    assert abs(again.area() - surf.area()) < 1e-13
    with pytest.raises(ValueError, match="order m <= 3"):
        LagrangeSurface.from_projection(V, F, 4, s.project)
    with pytest.raises(ValueError, match="HHJ degree must be 0, 1 or 2"):
        shape_operator(surf)


@pytest.mark.slow
@pytest.mark.parametrize("degree, bound", [(3, 1.8), (4, 2.8)])
def test_heine_curvature_vector_and_weingarten_rates(degree, bound):
    """Heine Theorem 4.1: ‖Y − Y_h‖L2 and ‖Π − Π_h‖L2 = O(h^{γ−1}); on (5.1a), 4 re-jittered
    levels, measured EOC γ = 3: 2.03 / 2.07, γ = 4: 3.25 / 3.30 (and E_K,2, E_H,2 2.10 / 2.02,
    3.23 / 3.24: above γ − 1, as Heine observed)."""
    r = _heine_rates("5.1a", degree)
    for key in ("Y2", "Pi2", "K2", "H2"):
        assert r[key][-1] >= bound, (key, r)


def test_heine_adaptive_bisection_meshes():
    """Heine §5's mesh family: adaptive newest-vertex bisection of the icosahedron until the
    geometric L2 error of the degree-γ surface is below 0.005, then global double bisection.
    The meshes are conforming closed manifolds (no boundary edge, no duplicate vertex), stay
    shape regular, and the geometric error falls at ≥ h^{γ+1} (measured on (5.1a), γ = 2:
    0.0039, 0.00041, 4.6e-05, EOC 3.6, 3.2; min angle 10.5°)."""
    import igl
    from igl_hhj.mesh import as_mesh
    from igl_hhj.surfaces.heine import heine_adaptive_sequence
    seq, s, info = heine_adaptive_sequence("5.1a", 3, degree=2)
    geo = np.array(info["geometric_error"])
    assert info["adaptive_steps"] > 0 and geo[0] < 0.005
    hs = []
    for k, (V, F) in enumerate(seq):
        m = as_mesh(V, F)
        assert not m.boundary_edges.any() and igl.is_edge_manifold(F)[0]
        assert np.abs(s.value(V)).max() < 1e-10                      # vertices on the surface
        assert np.degrees(igl.internal_angles(V, F).min()) > 8.0
        if k:
            assert len(F) >= 4 * len(seq[k - 1][1])
        hs.append(m.max_edge_length)
    assert eoc(geo, hs).min() >= 2.8, (geo, hs)
    with pytest.raises(ValueError, match="unknown Heine surface"):
        heine_adaptive_sequence("5.1z", 2)
    with pytest.raises(ValueError, match="n_levels"):
        heine_adaptive_sequence("5.1a", 0)


# ----------------------------------------------------------------------------- viewer
def test_display_mesh_is_a_closed_manifold_with_values():
    from igl_hhj.curved.display import display_mesh
    from igl_hhj.mesh import as_mesh
    s, seq = sequence("torus", 1)
    V, F = seq[0]
    surf = LagrangeSurface.from_projection(V, F, 2, s.project)
    fld = shape_operator(surf)
    DV, DF, vals = display_mesh(surf, fld, subdivisions=3, exact=s)
    m = as_mesh(DV, DF)
    assert m.n_faces == 9 * surf.n_faces and not m.boundary_edges.any()
    assert set(vals) == {"H", "K", "k1", "k2", "|H error|"}
    assert all(v.shape == (len(DV),) and np.isfinite(v).all() for v in vals.values())
    # display vertices lie on the curved surface: on the torus to O(h^3)
    assert np.abs(s.value(DV)).max() < 0.05
    with pytest.raises(ValueError, match="subdivisions"):
        display_mesh(surf, fld, subdivisions=0)


@pytest.mark.slow
def test_curved_demo_headless(tmp_path):
    """demos/curved.py renders the three orders and prints errors falling with m."""
    import subprocess
    import sys
    from pathlib import Path
    from conftest import png_stats, require_egl
    require_egl()
    root = Path(__file__).resolve().parents[2]
    png = tmp_path / "curved.png"
    res = subprocess.run([sys.executable, "demos/curved.py", "--screenshot", str(png), "--size", "360", "160",
                          "--subdivisions", "1"], cwd=root, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    st = png_stats(png)
    assert (st["width"], st["height"]) == (360, 160) and st["std"] > 0.03 and st["foreground"] > 0.1
    rows = [line.split("|") for line in res.stdout.splitlines() if line.startswith("| m = ")]
    err = [float(r[3]) for r in rows]
    assert len(err) == 3 and err[0] > 3 * err[1] > 9 * err[2], res.stdout


@pytest.mark.parametrize("order,boundary", [(2, "none"), (3, "simply_supported")])
def test_static_condensation_gives_the_same_solution(order, boundary):
    name = "torus" if boundary == "none" else "saddle"
    s, seq = sequence(name, 1)
    V, F = seq[0]
    surf = LagrangeSurface.from_projection(V, F, order, s.project)
    kw = {"boundary_shape_operator": s.shape_operator(surf.nodes)} if boundary != "none" else {}
    a = shape_operator(surf, condense=False, **kw).coefficients
    b = shape_operator(surf, condense=True, **kw).coefficients
    assert np.abs(a - b).max() <= 1e-10 * np.abs(a).max()


def test_walker_tables_orders_cli(tmp_path, capsys):
    from igl_hhj.benchmarks.walker_curved import PAPER_CURVED
    from igl_hhj.benchmarks.walker_tables import main
    main(["--orders", "2", "--surfaces", "saddle", "--curved-levels", "2", "--curved-cond-levels", "1",
          "--out", str(tmp_path)])
    text = (tmp_path / "walker_tables_curved.md").read_text(encoding="utf-8")
    assert "## saddle, m = 2" in text and "| paper 1 |" in text and "κ(S^m) condensed" in text
    rows = [r for r in text.splitlines() if r.startswith("| 1 | 1792")]
    eoc_S = float(rows[0].split("|")[5].split("(")[1].rstrip(") "))
    assert eoc_S > 1.8
    assert set(PAPER_CURVED) == {"saddle", "dumbbell", "torus", "genus3"}
    assert all(len(PAPER_CURVED[n][m]) >= 4 for n in PAPER_CURVED for m in (2, 3))


@pytest.mark.slow
def test_walker_tables_append_min_level(tmp_path):
    """--min-level skips the coarse solves (rows carry their k; no EOC without the level
    before); --append adds a section with the command line and the ours/paper line."""
    from igl_hhj.benchmarks.walker_tables import main
    (tmp_path / "walker_tables_curved.md").write_text("# existing\n", encoding="utf-8")
    main(["--orders", "2", "--surfaces", "saddle", "--curved-levels", "3", "--min-level", "1",
          "--append", "--out", str(tmp_path)])
    text = (tmp_path / "walker_tables_curved.md").read_text(encoding="utf-8")
    assert text.startswith("# existing\n") and "## Further rows: `python -m igl_hhj.benchmarks.walker_tables" in text
    assert "### saddle, m = 2" in text and "peak memory" in text
    assert not any(r.startswith("| 0 | 448 |") for r in text.splitlines())
    row1 = next(r for r in text.splitlines() if r.startswith("| 1 | 1792"))
    row2 = next(r for r in text.splitlines() if r.startswith("| 2 | 7168"))
    assert "(" not in row1.split("|")[5] and float(row2.split("|")[5].split("(")[1].rstrip(") ")) > 1.8
    line = next(r for r in text.splitlines() if r.startswith("At k = 2, ours / paper:"))
    ratio = float(line.split("‖S‖L2 ")[1].split(",")[0])
    assert 0.3 < ratio < 3, line
