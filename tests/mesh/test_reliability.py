"""Issue 12 regression tests: one per root cause, through the API and the CLI.

No accepted input may crash, hang, exhaust memory or return silent NaN; every
rejected one gets a message naming the cause and the fix.
"""
from __future__ import annotations

import os
import re
import signal
import struct
import subprocess
import sys
import time
import warnings

import igl
import numpy as np
import pytest
from cli_driver import check_outcome, run_capped
from conftest import write_off

import igl_hhj
from igl_hhj import baselines, cli, mesh
from igl_hhj.errors import SolverError
from igl_hhj.mesh import DEGENERATE_AREA_RTOL, MeshWarning, TriangleMesh
from igl_hhj.surfaces import icosphere
from igl_hhj.surfaces.meshing import square_grid

LINUX = sys.platform.startswith("linux")


# --------------------------------------------------------------------------- helpers
def relative_area(V, F, f):
    X = V[F[f]]
    dbl = np.linalg.norm(np.cross(X[1] - X[0], X[2] - X[0]))
    return dbl / max(np.sum((X[[1, 2, 0]] - X) ** 2, axis=1))


def thin_face(V, F, f, rel):
    """Move corner 0 of face f towards the midpoint of the opposite edge until the
    relative area 2|T| / (longest edge)² is ``rel`` (a cap: one angle near 180°)."""
    V = np.array(V, dtype=np.float64)
    a, b, c = F[f]
    mid = 0.5 * (V[b] + V[c])
    lo, hi = 0.0, 1.0                       # bisection on the height (relative area is monotone)
    base = V[a] - mid
    for _ in range(200):
        t = 0.5 * (lo + hi)
        V[a] = mid + t * base
        lo, hi = (t, hi) if relative_area(V, F, f) < rel else (lo, t)
    V[a] = mid + hi * base
    return V


def wavy_grid(n):
    P, F = square_grid(n)
    return np.column_stack([P, 0.3 * np.sin(3 * P[:, 0]) * np.cos(2 * P[:, 1])]), F


def one_error_line(err):
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("igl-hhj: error: "), lines
    return lines[0]


@pytest.fixture(scope="module")
def large_grid():
    """> 50k edges: solver='auto' uses the face-Schwarz PCG path."""
    V, F = wavy_grid(135)
    assert TriangleMesh(V, F).n_edges > 50_000
    return V, F


# --------------------------------------------------------------------------- 1. thin triangles
def test_threshold_matches_libigl_precision():
    """The validation threshold is where libigl's edge-length formulas (cotmatrix,
    massmatrix: every solver but HHJ uses them) still resolve a sliver: at
    1.5 × DEGENERATE_AREA_RTOL the cotangent weight of the face is good to 2 %, a
    decade and a half below it is off by more than 50 % or NaN."""
    rng = np.random.default_rng(0)

    def worst_error(rel):
        worst = 0.0
        for _ in range(100):
            b, c = rng.normal(size=3), rng.normal(size=3)
            d = np.cross(c - b, rng.normal(size=3))
            d /= np.linalg.norm(d)
            L = np.linalg.norm(c - b)
            V = np.array([b + rng.uniform(0.05, 0.95) * (c - b) + d * rel * L, b, c])
            C = igl.cotmatrix(V, np.array([[0, 1, 2]])).toarray()
            u, v = V[1] - V[0], V[2] - V[0]
            exact = 0.5 * np.dot(u, v) / np.linalg.norm(np.cross(u, v))  # weight of edge 1-2
            err = abs(C[1, 2] - exact) / abs(exact) if np.isfinite(C).all() else np.inf
            worst = max(worst, err)
        return worst

    assert worst_error(1.5 * DEGENERATE_AREA_RTOL) < 2e-2
    assert worst_error(DEGENERATE_AREA_RTOL / 30) > 0.5


@pytest.mark.slow
def test_hhj_auto_on_large_mesh_with_thin_face(large_grid):
    """Issue: one face of relative area 1e-9 on > 50k edges crashed solver='auto'
    with LinAlgError.  Now: rejected by validation with the cause; just above the
    threshold the default solver returns the direct solver's answer."""
    V, F = large_grid
    f = len(F) // 2 + 7
    with pytest.raises(ValueError, match=r"near-degenerate \(sliver\) faces; first at face "
                                         rf"{f}.*relative area 1e-09.*collapse"):
        igl_hhj.shape_operator(thin_face(V, F, f, 1e-9), F)
    Vt = thin_face(V, F, f, 1.5 * DEGENERATE_AREA_RTOL)
    S = igl_hhj.shape_operator(Vt, F, solver="auto")
    S_direct = igl_hhj.shape_operator(Vt, F, solver="direct")
    assert np.isfinite(S).all()
    # PCG stops at relative residual 1e-10; the sliver raises A's condition number,
    # so the solution agrees to ~1e-5 relative: far below the O(h) = 1e-2 discretisation error.
    others = np.arange(len(F)) != f
    scale = np.abs(S_direct[others]).max()
    assert np.abs(S - S_direct)[others].max() < 1e-4 * scale


def test_cli_thin_face_is_one_line_and_info_agrees(tmp_path, capsys):
    V, F = wavy_grid(20)
    path = write_off(tmp_path / "thin.off", thin_face(V, F, 401, 1e-9), F)
    assert cli.main(["curvature", str(path), "--strict"]) == cli.EXIT_USAGE
    assert "near-degenerate" in one_error_line(capsys.readouterr().err)
    assert cli.main(["curvature", str(path)]) == 0           # repaired, as by the drop-in: one warning
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("igl-hhj: warning: ") and "sliver" in err[0]
    assert cli.main(["info", str(path)]) == cli.EXIT_REJECTED
    assert "rejected: F has near-degenerate" in capsys.readouterr().out


def test_biharmonic_thin_face():
    """Issue: 'Factor is exactly singular' on a grid with one 1e-9 face.  Just above
    the threshold the solution is finite and close to the unperturbed grid's (the
    face is tiny); below it the operators are refused with SolverError, never a
    bare RuntimeError, even when validation is bypassed."""
    P, F = square_grid(20)
    V = np.column_stack([P, np.zeros(len(P))])
    f = np.ones(len(V))
    u0 = np.asarray(igl_hhj.biharmonic_solve(V, F, f)[0])
    u = np.asarray(igl_hhj.biharmonic_solve(thin_face(V, F, 401, 1.5 * DEGENERATE_AREA_RTOL), F, f)[0])
    assert np.isfinite(u).all() and np.abs(u - u0).max() < 1e-2 * np.abs(u0).max()
    with pytest.raises(ValueError, match="near-degenerate"):
        igl_hhj.biharmonic_solve(thin_face(V, F, 401, 1e-9), F, f)


def test_libigl_operators_beyond_threshold_raise_solver_error(monkeypatch):
    monkeypatch.setattr(mesh, "DEGENERATE_AREA_RTOL", 1e-14)      # bypass validation
    P, F = square_grid(20)
    V = thin_face(np.column_stack([P, np.zeros(len(P))]), F, 401, 1e-10)
    with pytest.raises(SolverError, match="cannot represent those faces") as info:
        igl_hhj.biharmonic_solve(V, F, np.ones(len(V)))
    assert 401 in info.value.faces
    Vs, Fs = icosphere(3)
    with pytest.raises(SolverError):
        baselines.heine(thin_face(Vs, Fs, 5, 1e-10), Fs)


def test_heine_thin_face_is_not_silently_zero():
    """Issue: Heine returned H ≈ 1e-14 everywhere on a sphere with one thin face."""
    V, F = icosphere(3)
    H0 = baselines.heine(V, F).H
    H = baselines.heine(thin_face(V, F, 5, 1.5 * DEGENERATE_AREA_RTOL), F).H
    far = np.ones(len(V), bool)
    far[F[5]] = False
    assert abs(np.median(H[far]) - np.median(H0)) < 1e-3


def test_schwarz_preconditioner_singular_block_is_guarded():
    """A face block singular in float64 gets its Jacobi inverse (the preconditioner
    stays SPD instead of raising LinAlgError)."""
    from igl_hhj.hhj import _robust_block_inverse
    blk = np.array([np.diag([2.0, 3.0, 4.0]), np.ones((3, 3))])
    inv = _robust_block_inverse(blk)
    np.testing.assert_allclose(inv[0], np.diag([0.5, 1 / 3, 0.25]))
    np.testing.assert_allclose(inv[1], np.eye(3))
    assert np.isfinite(inv).all()


# --------------------------------------------------------------------------- 2. file guards
def _ply(body, header_extra=b""):
    return (b"ply\nformat ascii 1.0\n" + header_extra + b"element vertex 3\nproperty float x\n"
            b"property float y\nproperty float z\nelement face 1\nproperty list uchar int "
            b"vertex_indices\nend_header\n" + body)


FILES = {   # name: (content, exit code, message)
    "huge_corners.off": (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n", 3,
                         "claims more corners than it lists"),
    "nonnumeric.off": (b"OFF\n3 1 0\n0 0 0\n1 0 x\n0 1 0\n3 0 1 2\n", 3, "not three (or more) numbers"),
    "nonnumeric.ply": (_ply(b"0 0 0\n1 0 0\n0 1 0\n3 0 1 abc\n"), 3, "non-numeric value"),
    "long_header.ply": (_ply(b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                             b"".join(b"comment %06d padding the header beyond 64 KB\n" % i
                                      for i in range(2000))), 0, ""),
    "zero_based.obj": (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", 3, "the file is 0-based"),
    "nonnumeric.obj": (b"v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n", 3, "three (or more) numbers"),
    "truncated.stl": (b"\0" * 80 + struct.pack("<I", 10 ** 6) + b"\0" * 100, 3, "not an STL file"),
    "bad_count.ply": (b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                      b"property float y\nproperty float z\nelement face 1\nproperty list uchar int "
                      b"vertex_indices\nend_header\n" + np.eye(3, dtype="<f4").tobytes()
                      + b"\xff" + np.arange(3, dtype="<i4").tobytes(), 3, "declares 255 corners"),
    "huge_section.mesh": (b"MeshVersionFormatted 1\nDimension 3\nVertices\n2000000000\n0 0 0 0\n",
                          3, "declares 2000000000 records"),
    # libigl aborts (double free) when properties it reads together differ in type
    "mixed_types.ply": (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        b"property float z\nproperty double quality\nproperty float k\nelement face 1\n"
                        b"property list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 0 0\n"
                        b"0 1 0 0 0\n3 0 1 2\n", 3, "different types (quality double, k float)"),
    "mixed_colours.ply": (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          b"property float z\nproperty uchar red\nproperty float green\nproperty uchar blue\n"
                          b"element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                          b"0 0 0 1 1 1\n1 0 0 1 1 1\n0 1 0 1 1 1\n3 0 1 2\n", 3, "different types"),
    # an index from 2³¹ on overflows libigl's ascii PLY reader (abort); found by the fuzzer
    "huge_index.ply": (_ply(b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2147483648\n"), 3,
                       "vertex index of 10 or more digits"),
    # libigl aborts (double free) on a property or element declared twice, and on an ascii
    # face line that lacks the values of a second list property; found by the fuzzer
    "twice.ply": (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                  b"property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                  b"property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                  b"3 0 1 2 3 0 1 2\n", 3, "declares property 'vertex_indices' more than once"),
    "element_twice.ply": (_ply(b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n").replace(
        b"end_header", b"element face 1\nproperty list uchar int vertex_indices\nend_header"), 3,
        "element 'face' is declared twice"),
    "short_list.ply": (_ply(b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").replace(
        b"end_header", b"property list uchar float texcoord\nend_header"), 3,
        "each list its count and that many values"),
    # a second list property with its values reads fine: accepted
    "texcoord.ply": (_ply(b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2 6 0 0 1 0 0 1\n").replace(
        b"end_header", b"property list uchar float texcoord\nend_header"), 0, ""),
    # normals of mixed types read fine: accepted
    "mixed_normals.ply": (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          b"property float z\nproperty float nx\nproperty double ny\nproperty float nz\n"
                          b"element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                          b"0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n", 0, ""),
}


@pytest.mark.skipif(not LINUX, reason="RLIMIT_AS / /proc are Linux")
def test_file_guards_bound_memory_and_time(tmp_path):
    """Each file through igl-hhj info and curvature in a child capped at +300 MB:
    one error line (exit 3) or success, each in well under the alarm."""
    jobs, expect = [], []
    for name, (content, code, message) in FILES.items():
        (tmp_path / name).write_bytes(content)
        for command in ("info", "curvature"):
            jobs.append([command, tmp_path / name])
            expect.append((code, message))
    for rec, (code, message) in zip(run_capped(jobs, extra_mb=300, seconds=20), expect):
        assert check_outcome(rec, {code}) == code
        assert message in rec["err"] and rec["seconds"] < 10


@pytest.mark.parametrize("name", ["twice.ply", "element_twice.ply", "short_list.ply"])
def test_ply_headers_libigl_aborts_on_raise_in_process(tmp_path, name):
    """The PLYs on which libigl's reader aborts are refused by read_mesh itself (a
    MeshFileError, a ValueError, naming the problem), before libigl sees them."""
    from igl_hhj.mesh_io import MeshFileError, read_mesh
    content, _, message = FILES[name]
    (tmp_path / name).write_bytes(content)
    with pytest.raises(MeshFileError, match=re.escape(message)):
        read_mesh(tmp_path / name)
    (tmp_path / "ok.ply").write_bytes(FILES["texcoord.ply"][0])
    V, F = read_mesh(tmp_path / "ok.ply")[:2]
    assert F.shape == (1, 3)


def test_long_ply_header_reads():
    assert len(FILES["long_header.ply"][0]) > 1 << 16


_TRI = b"0 0 0\n1 0 0\n0 1 0\n"


@pytest.mark.parametrize("body", [b"3 0\n1 2\n", b"3\n0\n1\n2\n", b"3 0\n\n1 2 255 0 0 # c\n"])
def test_off_face_records_may_wrap_lines(tmp_path, body):
    """libigl reads OFF faces token by token; the guard does too (it used to reject these)."""
    from igl_hhj.mesh_io import read_mesh
    path = tmp_path / "w.off"
    path.write_bytes(b"OFF\n3 2 0\n" + _TRI + body + b"3 0 1 2\n")
    V, F, _ = read_mesh(path)
    assert V.shape == (3, 3) and F.tolist() == [[0, 1, 2], [0, 1, 2]]


@pytest.mark.parametrize("body, message", [
    (b"3 0\n1\n", "claims more corners than it lists"),
    (b"3 0\n1 x\n", "not a non-negative integer"),
    (b"3 0 # c\n1 2\n", "comment inside a face record"),
    (b"3 0\n# c\n1 2\n", "comment inside a face record"),
    (b"2000000000 0\n1 2\n" + b"4 5 6\n" * 50, "claims more corners than it lists"),
])
def test_off_wrapped_face_records_are_still_checked(tmp_path, body, message):
    from igl_hhj.mesh_io import MeshFileError, read_mesh
    path = tmp_path / "w.off"
    path.write_bytes(b"OFF\n3 1 0\n" + _TRI + body)
    with pytest.raises(MeshFileError, match=message):
        read_mesh(path)


_PLY_TRI = _ply(b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")


@pytest.mark.parametrize("name, content", [("b.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
                                           ("b.off", b"OFF\n3 1 0\n" + _TRI + b"3 0 1 2\n"),
                                           ("b.ply", _PLY_TRI)])
def test_utf8_bom_is_skipped(tmp_path, name, content):
    """A UTF-8 BOM used to cost an OBJ its first vertex (then a misleading index error)."""
    from igl_hhj.mesh_io import read_mesh
    path = tmp_path / name
    path.write_bytes(b"\xef\xbb\xbf" + content)
    V, F, _ = read_mesh(path)
    np.testing.assert_array_equal(V, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    assert F.tolist() == [[0, 1, 2]]


def test_utf8_bom_errors_name_the_original_file(tmp_path):
    from igl_hhj.mesh_io import MeshFileError, read_mesh
    path = tmp_path / "t.off"
    path.write_bytes(b"\xef\xbb\xbfOFF\n3 1 0\n0 0 0\n1 0 0\n")
    with pytest.raises(MeshFileError) as info:
        read_mesh(path)
    assert str(info.value).startswith(str(path)) and "igl_hhj_bom_" not in str(info.value)


# --------------------------------------------------------------------------- 3. regge index
@pytest.mark.skipif(not LINUX, reason="RLIMIT_AS is Linux")
def test_gauss_curvature_intrinsic_huge_index_in_capped_process():
    code = ("import resource, numpy as np; from igl_hhj import regge; "
            "resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))\n"
            "try:\n    regge.gauss_curvature_intrinsic(np.ones((1, 3)), np.array([[0, 1, 10**9]]))\n"
            "except ValueError as e:\n    print('ValueError', e)\n")
    t = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert out.stdout.startswith("ValueError F's largest vertex index is 1000000000"), out.stderr
    assert "np.unique(F, return_inverse=True)" in out.stdout and time.perf_counter() - t < 30


# --------------------------------------------------------------------------- 4. silent NaN
def _pillow(n=8):
    """A flat closed disc: two coincident fans glued along the rim."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    V = np.vstack([np.column_stack([np.cos(t), np.sin(t), 0 * t]), [[0, 0, 0], [0, 0, 0.0]]])
    F = [[i, (i + 1) % n, n] for i in range(n)] + [[(i + 1) % n, i, n + 1] for i in range(n)]
    return V, np.array(F)


FOLDED = {
    "two-sided": (np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2], [0, 2, 1]])),
    "folded": (np.array([[0.0, 0, 0], [1, 0, 0], [0.3, 1, 0], [0.3, 1, 0]]),
               np.array([[0, 1, 2], [1, 0, 3]])),
    "pillow": _pillow(),
    "bow-tie": (np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]]),
                np.array([[0, 1, 2], [0, 4, 3]])),
}


@pytest.mark.filterwarnings("ignore::igl_hhj.mesh.MeshWarning")
@pytest.mark.parametrize("name", sorted(FOLDED))
def test_folded_meshes_list_every_nan_vertex(name):
    V, F = FOLDED[name]
    PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(V, F)
    nan = ~np.isfinite(np.column_stack([PD1, PD2, PV1, PV2])).all(axis=1)
    assert np.flatnonzero(nan).tolist() == bad and bad
    assert set(bad) <= set(np.flatnonzero(TriangleMesh(V, F).folded_vertices)) | \
        set(np.flatnonzero(~TriangleMesh(V, F).referenced_vertices))
    assert np.isfinite(igl_hhj.shape_operator(V, F)).all()


@pytest.mark.filterwarnings("ignore::igl_hhj.mesh.MeshWarning")
def test_cli_names_folded_vertices_not_unreferenced(tmp_path, capsys):
    path = write_off(tmp_path / "pillow.off", *FOLDED["pillow"])
    assert cli.main(["curvature", str(path)]) == 0
    out = capsys.readouterr().out
    assert "without a tangent plane" in out and "unreferenced" not in out


def test_huge_coordinates_rejected_and_largest_accepted_work():
    V, F = icosphere(2)
    with pytest.raises(ValueError, match="beyond 1e.75.*Rescale"):
        igl_hhj.principal_curvature(V * 1e78, F, solver="cg")
    for s in (1e-50, 1e74):
        PV1 = igl_hhj.principal_curvature(V * s, F, solver="cg")[2]
        np.testing.assert_allclose(PV1 * s, igl_hhj.principal_curvature(V, F, solver="cg")[2],
                                   rtol=1e-6)
    with pytest.raises(ValueError, match="too small"):
        TriangleMesh(V * 1e-70, F)


def test_huge_boundary_shape_operator_rejected():
    V, F = icosphere(2)
    F = F[V[F].mean(axis=1)[:, 2] > 0]
    S = np.tile(np.eye(3) * 1e200, (len(V), 1, 1))
    with pytest.raises(ValueError, match="boundary_shape_operator has values beyond"):
        igl_hhj.principal_curvature(V, F, boundary_shape_operator=S, solver="cg")


def test_lift_gauss_curvature_rejects_nan_from_callables():
    from igl_hhj import regge
    from igl_hhj.regge.examples import graph_metric, structured_square
    P, F = structured_square(1)
    g = regge.interpolate(P, F, graph_metric, 1)
    with pytest.raises(ValueError, match="dirichlet_values returned NaN"):
        regge.lift_gauss_curvature(g, dirichlet=lambda m: np.ones(len(m), bool),
                                   dirichlet_values=lambda X: np.full(len(X), np.nan))
    with pytest.raises(ValueError, match="neumann_curvature returned NaN"):
        regge.lift_gauss_curvature(g, neumann_curvature=lambda X, t: np.full(len(X), np.inf))
    with pytest.raises(ValueError, match="metric returned NaN"):
        regge.interpolate(P, F, lambda X: np.full((len(X), 2, 2), np.nan), 1)


def test_triangle_mesh_arrays_are_read_only_copies():
    V, F = icosphere(1)
    m = TriangleMesh(V, F)
    with pytest.raises(ValueError, match="read-only"):
        m.V[0, 0] = np.nan
    with pytest.raises(ValueError, match="read-only"):
        m.F[0, 0] = 1
    V[0, 0] = np.nan                     # the caller's array is not the mesh's
    assert np.isfinite(m.V).all() and V.flags.writeable
    V2, F2 = igl_hhj.validate_mesh(m.V, m.F)
    V2[0] = 0.0                          # validate_mesh still returns writable copies


# --------------------------------------------------------------------------- 5. CLI
@pytest.fixture()
def sphere_off(tmp_path):
    return write_off(tmp_path / "s.off", *icosphere(2))


def test_demo_negative_seed_is_one_line(capsys):
    assert cli.main(["demo", "--seed", "-1", "--no-screenshot"]) == cli.EXIT_USAGE
    assert "--seed" in one_error_line(capsys.readouterr().err)


@pytest.mark.parametrize("exc, code, match", [
    (SolverError("face-Schwarz setup failed", faces=[3]), cli.EXIT_SOLVER, "the solver failed"),
    (np.linalg.LinAlgError("Singular matrix"), cli.EXIT_SOLVER, "Singular matrix"),
    (RuntimeError("Factor is exactly\nsingular"), cli.EXIT_SOLVER, "Factor is exactly singular"),
    (MemoryError("Unable to allocate 16 GiB"), cli.EXIT_MEMORY, "out of memory"),
    (KeyError("oops"), cli.EXIT_INTERNAL, "internal error: KeyError"),
])
def test_solver_and_other_failures_are_one_line(sphere_off, monkeypatch, capsys, exc, code, match):
    def boom(*a, **k):
        raise exc
    for name in ("estimate", "hhj_vertex"):     # what `curvature` calls for the default method
        monkeypatch.setattr(baselines, name, boom)
    assert cli.main(["curvature", str(sphere_off)]) == code
    assert match in one_error_line(capsys.readouterr().err)
    with pytest.raises(type(exc)):                       # --debug: the traceback
        cli.main(["curvature", str(sphere_off), "--debug"])


def test_interrupt_during_command_is_one_line(sphere_off, monkeypatch, capsys):
    def interrupted(*a, **k):
        raise KeyboardInterrupt
    for name in ("estimate", "hhj_vertex"):
        monkeypatch.setattr(baselines, name, interrupted)
    assert cli.main(["curvature", str(sphere_off)]) == cli.EXIT_INTERRUPTED
    assert capsys.readouterr().err.strip() == "igl-hhj: interrupted"


def _wait_for_library(pid, name, timeout=60):
    """Poll /proc/pid/maps until the shared object ``name`` is mapped (import under way)."""
    t = time.perf_counter()
    while time.perf_counter() - t < timeout:
        try:
            with open(f"/proc/{pid}/maps") as fh:
                if name in fh.read():
                    return True
        except OSError:
            return False
        time.sleep(0.002)
    return False


@pytest.mark.skipif(not LINUX, reason="POSIX signals, /proc")
@pytest.mark.parametrize("library", ["_multiarray_umath", "_sparsetools", "pyigl_core"])
def test_ctrl_c_during_imports_is_one_line(sphere_off, library):
    """SIGINT while the igl-hhj command is importing numpy (module level of the igl_hhj.cli package),
    scipy.sparse or libigl (inside main): one line, exit 130, no traceback."""
    import shutil
    from pathlib import Path
    exe = Path(sys.executable).with_name("igl-hhj")          # the venv's console script
    exe = str(exe) if exe.exists() else shutil.which("igl-hhj")
    assert exe, "the igl-hhj console script is not installed next to the interpreter"
    proc = subprocess.Popen([exe, "curvature", str(sphere_off)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    loaded = _wait_for_library(proc.pid, library)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert loaded or proc.returncode == 0
    assert "Traceback" not in err
    assert proc.returncode == 0 or (proc.returncode == cli.EXIT_INTERRUPTED
                                    and err.strip() == "igl-hhj: interrupted"), (proc.returncode, err)


@pytest.mark.skipif(not LINUX, reason="RLIMIT_AS / /proc are Linux")
def test_out_of_memory_under_a_cap_is_one_line(tmp_path):
    path = tmp_path / "big.off"
    igl.write_triangle_mesh(str(path), *icosphere(6))
    (rec,) = run_capped([["curvature", path]], extra_mb=40)
    assert check_outcome(rec, {cli.EXIT_MEMORY}) == cli.EXIT_MEMORY
    assert "out of memory" in rec["err"]


# --------------------------------------------------------------------------- 6. work limits
def test_degree_and_quadrature_limits():
    from igl_hhj import regge
    from igl_hhj.regge.examples import graph_metric, structured_square
    P, F = structured_square(1)
    g = regge.interpolate(P, F, graph_metric, 1)
    t = time.perf_counter()
    with pytest.raises(ValueError, match="degree must be <= 12"):
        regge.lift_gauss_curvature(g, degree=50)
    with pytest.raises(ValueError, match="Regge degree k must be <= 12"):
        regge.interpolate(P, F, graph_metric, 50)
    with pytest.raises(ValueError, match="quad_degree must be >= 4 = 2k"):
        regge.interpolate(P, F, graph_metric, 2, quad_degree=0)
    with pytest.raises(ValueError, match="quad_degree must be >= 2 = 2 max"):
        regge.lift_gauss_curvature(g, quad_degree=0)
    with pytest.raises(ValueError, match="quad_degree must be <= 64"):
        regge.lift_gauss_curvature(g, quad_degree=1000)
    assert time.perf_counter() - t < 5


# --------------------------------------------------------------------------- 7. messages
def test_messages_name_the_real_cause():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    F = np.array([[0, 1, 2], [1, 3, 2]])
    big = np.array([[0.0, 0, 0], [1e9, 0, 0], [5e8, 29.9, 0]])        # area 1.5e10, thin
    with pytest.raises(ValueError, match=r"near-degenerate.*area 1.5e\+10"):
        TriangleMesh(big, [[0, 1, 2]])
    with pytest.raises(ValueError, match="out-of-range vertex indices"):
        TriangleMesh(V, np.array([[0, 1, np.iinfo(np.uint64).max]], dtype=np.uint64))
    with pytest.raises(ValueError, match="F is empty"):
        TriangleMesh(V, [])
    with pytest.raises(ValueError, match="V is empty"):
        TriangleMesh([], F)
    with pytest.raises(ValueError, match=r"igl.bfs_orient\(F\)"):
        TriangleMesh(V, [[0, 1, 2], [1, 2, 3]])


def test_triangle_soup_warns_api_and_cli(tmp_path, capsys):
    V, F = icosphere(1)
    Vs, Fs = V[F].reshape(-1, 3), np.arange(3 * len(F)).reshape(-1, 3)       # unwelded
    with pytest.warns(MeshWarning, match="triangle soup.*remove_duplicate_vertices"):
        TriangleMesh(Vs, Fs)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        TriangleMesh(V, F)                                                 # welded: silent
    path = write_off(tmp_path / "soup.off", Vs, Fs)
    assert cli.main(["curvature", str(path)]) == 0
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(err) == 1 and err[0].startswith("igl-hhj: warning: ") and "soup" in err[0]


@pytest.mark.parametrize("scale", [1e-59, 1.0, 1e30, 1e60, 1e74])
@pytest.mark.parametrize("bc", ["clamped", "closed"])
def test_biharmonic_extreme_scales_finite_or_solver_error(scale, bc):
    """u grows like length⁴: at large accepted scales the closed solve overflowed
    into silent NaN; now finite on every referenced vertex, or SolverError."""
    V, F = icosphere(2)
    if bc == "clamped":
        F = F[V[F].mean(axis=1)[:, 2] > 0]
    kw = {"bc": "closed", "project_mean": True} if bc == "closed" else {}
    try:
        u1, u2 = igl_hhj.biharmonic_solve(V * scale, F, np.cos(V[:, 0]), **kw)
    except SolverError as exc:
        assert "rescale" in str(exc) and scale > 1e30
        return
    ref = TriangleMesh(V, F).referenced_vertices
    assert np.isfinite(u1[ref]).all() and np.isfinite(u2[ref]).all()


def test_file_guard_reports_the_right_line_across_chunks(tmp_path, monkeypatch):
    """The body scan runs in chunks of _CHUNK bytes: line numbers stay exact."""
    from igl_hhj import mesh_io
    from igl_hhj.mesh_io import scan
    monkeypatch.setattr(scan, "_CHUNK", 4096)                    # many chunks on a small file
    V, F = icosphere(3)
    path = write_off(tmp_path / "s.off", V, F)
    lines = path.read_bytes().split(b"\n")
    k = len(lines) - 7
    lines[k] = lines[k].replace(b" ", b" 1x ", 1)
    path.write_bytes(b"\n".join(lines))
    with pytest.raises(mesh_io.MeshFileError, match=rf"line {k + 1}: face corner is not"):
        mesh_io.read_mesh(path)
    path.write_bytes(write_off(tmp_path / "t.off", V, F).read_bytes())
    V2, F2, _ = mesh_io.read_mesh(path)                            # the valid file still reads
    assert len(F2) == len(F)
