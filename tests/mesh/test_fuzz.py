"""Property-based fuzzing: no accepted input crashes, hangs, exhausts memory or
returns NaN silently — either finite output (NaN only at the vertices listed in
``bad_vertices``) or a clear exception.

Families: perturbed spheres, random face subsets (boundaries, unreferenced
vertices), slivers down to the validation threshold on small and on large
(> 50k edges) meshes, folded / two-sided sheets, coordinate scales 1e-80 …
1e77, int32/float32 inputs, 1,000 seeded meshes with the defects the drop-in
repairs (compared with ``igl.principal_curvature``), and random mutations of valid OFF/OBJ/PLY/STL files
run through ``igl-hhj info`` and ``igl-hhj curvature`` in a memory-capped child
process.  Example counts are bounded (whole module ≈ 30–60 s); the number of
inputs tried is counted in ``FUZZ_COUNTS`` and printed in pytest's summary.
"""
import collections
import struct
import sys
import warnings

import igl
import numpy as np
import pytest
from cli_driver import check_outcome, run_capped
from conftest import defect_mesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import igl_hhj
from igl_hhj import cli
from igl_hhj import repair as rp
from igl_hhj.mesh import DEGENERATE_AREA_RTOL, MeshWarning, TriangleMesh
from igl_hhj.surfaces import icosphere
from igl_hhj.surfaces.meshing import square_grid

V1, F1 = icosphere(1)
V2, F2 = icosphere(2)
ALLOWED = (ValueError, TypeError)
SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
FEW = settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
FUZZ_COUNTS = collections.Counter()
"""family -> number of inputs tried (printed by conftest's terminal summary)."""


def _check(V, F, family, solver="auto"):
    FUZZ_COUNTS[family] += 1
    try:
        S = igl_hhj.shape_operator(V, F, solver=solver)
        PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(V, F, solver=solver)
    except ALLOWED as exc:
        assert str(exc)            # a message that names the problem
        return "rejected"
    assert np.isfinite(S).all()
    rows = np.column_stack([PD1, PD2, PV1, PV2])
    nan = ~np.isfinite(rows).all(axis=1)
    assert np.isnan(rows[nan]).all()                       # a bad row is NaN throughout
    assert np.flatnonzero(nan).tolist() == bad             # every NaN row is listed, no other
    m = TriangleMesh(V, F)
    assert set(bad) <= set(np.flatnonzero(~m.referenced_vertices | m.folded_vertices))
    ok = ~nan
    assert np.all(PV1[ok] >= PV2[ok])
    return "ok"


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), amp=st.floats(0.0, 0.6))
def test_perturbed_spheres(seed, amp):
    rng = np.random.default_rng(seed)
    _check(V1 + amp * rng.normal(size=V1.shape), F1, "perturbed spheres")


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), frac=st.floats(0.05, 1.0))
def test_random_face_subsets_with_boundary(seed, frac):
    rng = np.random.default_rng(seed)
    keep = rng.uniform(size=len(F2)) < frac
    if not keep.any():
        keep[0] = True
    _check(V2, F2[keep], "face subsets")          # unreferenced vertices stay in V on purpose


def _sliver(V, F, f, rel):
    """Move corner 0 of face f towards the opposite edge's midpoint: relative area ≈ rel."""
    V = V.copy()
    a, b, c = F[f]
    mid = 0.5 * (V[b] + V[c])
    X = V[F[f]]
    r0 = np.linalg.norm(np.cross(X[1] - X[0], X[2] - X[0])) / max(np.sum((X[[1, 2, 0]] - X) ** 2, 1))
    V[a] = mid + (V[a] - mid) * (rel / r0)
    return V


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), squash=st.floats(0.0, 1.0), exponent=st.integers(1, 14))
def test_near_degenerate_triangles(seed, squash, exponent):
    """Move a vertex towards the midpoint of an opposite edge until the triangle is
    a sliver of relative height 10^-exponent (or exactly degenerate)."""
    rng = np.random.default_rng(seed)
    V = V1.copy()
    f = rng.integers(len(F1))
    a, b, c = F1[f]
    mid = 0.5 * (V[b] + V[c])
    t = 1.0 - (10.0 ** -exponent) * squash
    V[a] = V[a] + t * (mid - V[a])
    _check(V, F1, "slivers (small mesh)")


@pytest.fixture(scope="module")
def large_grid():
    P, F = square_grid(135)
    V = np.column_stack([P, 0.3 * np.sin(3 * P[:, 0]) * np.cos(2 * P[:, 1])])
    assert TriangleMesh(V, F).n_edges > 50_000
    return V, F


@pytest.mark.slow
@FEW
@given(seed=st.integers(0, 2**32 - 1), log_rel=st.floats(-0.5, 2.0))
def test_slivers_at_the_threshold_on_a_large_mesh(large_grid, seed, log_rel):
    """> 50k edges (solver='auto' takes the face-Schwarz PCG path), one sliver of
    relative area DEGENERATE_AREA_RTOL × 10^log_rel (from below to far above the
    validation threshold): the strict shape operator rejects it with a message below
    the threshold, the drop-in then drops the sliver (one MeshWarning, issue 24) and
    gives finite output (one solve per example: the drop-in, whose rows come from S_h)."""
    V, F = large_grid
    f = int(np.random.default_rng(seed).integers(len(F)))
    FUZZ_COUNTS["slivers (> 50k edges)"] += 1
    Vs = _sliver(V, F, f, DEGENERATE_AREA_RTOL * 10.0 ** log_rel)
    try:
        TriangleMesh(Vs, F)
        rejected = False
    except ValueError as exc:
        assert "near-degenerate" in str(exc) and log_rel < 0.01
        rejected = True
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(Vs, F)
    repaired = [w for w in rec if issubclass(w.category, MeshWarning)]
    assert len(repaired) == int(rejected)
    assert bad == [] and np.isfinite(np.column_stack([PD1, PD2, PV1, PV2])).all()


def _patch(seed, rings):
    """A disc of icosphere(2) faces around a random vertex."""
    rng = np.random.default_rng(seed)
    v0 = int(rng.integers(len(V2)))
    inside = np.zeros(len(V2), bool)
    inside[v0] = True
    for _ in range(rings):
        inside[F2[inside[F2].any(axis=1)].ravel()] = True
    return F2[inside[F2].all(axis=1)] if rings > 1 else F2[inside[F2].any(axis=1)]


@pytest.mark.filterwarnings("ignore::igl_hhj.mesh.MeshWarning")   # the glued sheets' duplicates
@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), rings=st.integers(1, 3),
       offset=st.sampled_from([0.0, 1e-12, 1e-6, 1e-2]), kind=st.sampled_from(
           ["pillow", "two-sided face", "bow-tie", "fold"]))
def test_folded_and_two_sided_meshes(seed, rings, offset, kind):
    """Two sheets glued along their boundary (a pillow, flat when offset = 0),
    a face plus its reverse, a bow-tie of two fans with opposite orientation,
    a sheet folded onto a copy of itself: NaN only where listed."""
    rng = np.random.default_rng(seed)
    P = _patch(seed, rings)
    used = np.unique(P)
    if kind == "two-sided face":
        f = P[int(rng.integers(len(P)))]
        V, F = V2[f], np.array([[0, 1, 2], [0, 2, 1]])
        V = V + offset * np.array([[0, 0, 0], [0, 0, 0], [1, 0, 0]])
    elif kind == "bow-tie":
        a, b = P[0], P[-1]
        V = np.vstack([V2[a], V2[b] - V2[b[0]] + V2[a[0]] + offset])
        F = np.array([[0, 1, 2], [0, 5, 4]])
    else:
        # second sheet: copies of the interior (or all) vertices, reversed faces
        edges = np.sort(np.concatenate([P[:, [0, 1]], P[:, [1, 2]], P[:, [2, 0]]]), axis=1)
        uniq, cnt = np.unique(edges, axis=0, return_counts=True)
        rim = np.unique(uniq[cnt == 1]) if kind == "pillow" else np.zeros(0, int)
        copy = np.setdiff1d(used, rim)
        new = np.arange(len(V2), len(V2) + len(copy))
        remap = np.arange(len(V2))
        remap[copy] = new
        N = V2[copy] / np.linalg.norm(V2[copy], axis=1, keepdims=True)
        V = np.vstack([V2, V2[copy] - offset * N])
        F = np.vstack([P, remap[P][:, ::-1]])
    _check(V, F, "folded / two-sided")


@SETTINGS
@given(exponent=st.integers(-80, 77), solver=st.sampled_from(["auto", "cg"]))
def test_extreme_coordinate_scales(exponent, solver):
    """Curvature scales as 1/length: accepted scales reproduce the unit-scale
    result, the others are rejected with a rescaling hint."""
    s = 10.0 ** exponent
    FUZZ_COUNTS["coordinate scales"] += 1
    try:
        PV1 = igl_hhj.principal_curvature(V1 * s, F1, solver=solver)[2]
    except ValueError as exc:
        assert "escale" in str(exc)
        return
    np.testing.assert_allclose(PV1 * s, igl_hhj.principal_curvature(V1, F1, solver=solver)[2],
                               rtol=1e-6)


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1))
def test_random_int32_float32_inputs(seed):
    rng = np.random.default_rng(seed)
    V = (V1 + 0.1 * rng.normal(size=V1.shape)).astype(np.float32)
    _check(V, F1.astype(np.int32), "int32/float32")


# --------------------------------------------------------------------------- mutated files
def _valid_files():
    """The same small sphere as ascii OFF/OBJ/PLY, binary PLY, ascii and binary STL."""
    V, F = V1, F1
    vt = "\n".join(" ".join(f"{x:.6f}" for x in v) for v in V)
    ft = "\n".join(" ".join(map(str, f)) for f in F)
    ply_head = (f"ply\nformat {{}} 1.0\nelement vertex {len(V)}\nproperty float x\nproperty float y\n"
                f"property float z\nelement face {len(F)}\nproperty list uchar int vertex_indices\n"
                f"end_header\n")
    face_rec = np.zeros(len(F), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    face_rec["n"], face_rec["i"] = 3, F
    tri = V[F]
    nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    stl_rec = np.zeros(len(F), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    stl_rec["n"], stl_rec["v"] = nrm, tri
    ascii_stl = "solid s\n" + "".join(
        f"facet normal {n[0]:.6f} {n[1]:.6f} {n[2]:.6f}\nouter loop\n"
        + "".join(f"vertex {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}\n" for p in t) + "endloop\nendfacet\n"
        for n, t in zip(nrm, tri)) + "endsolid s\n"
    return {
        ".off": f"OFF\n{len(V)} {len(F)} 0\n{vt}\n" + "\n".join("3 " + ln for ln in ft.split("\n")) + "\n",
        ".obj": "".join(f"v {ln}\n" for ln in vt.split("\n"))
                + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in F),
        ".ply": ply_head.format("ascii") + vt + "\n" + "\n".join("3 " + ln for ln in ft.split("\n")) + "\n",
        "_bin.ply": ply_head.format("binary_little_endian").encode() + V.astype("<f4").tobytes()
                    + face_rec.tobytes(),
        "_ascii.stl": ascii_stl,
        ".stl": b"\0" * 80 + struct.pack("<I", len(F)) + stl_rec.tobytes(),
    }


VALID = {k: (v.encode() if isinstance(v, str) else v) for k, v in _valid_files().items()}
MUTATIONS = ["flip", "truncate", "count", "delete line", "duplicate line", "insert token"]


def _mutate(data, kind, seed):
    rng = np.random.default_rng(seed)
    b = bytearray(data)
    if kind == "flip":
        for i in rng.integers(0, len(b), size=int(rng.integers(1, 6))):
            b[i] = int(rng.integers(0, 256))
    elif kind == "truncate":
        b = b[: int(rng.integers(0, len(b)))]
    elif kind in ("count", "insert token"):
        digits = [i for i in range(len(b)) if 48 <= b[i] <= 57]
        pos = int(rng.choice(digits[:400] if rng.uniform() < 0.5 else digits))
        start = pos
        while start > 0 and 48 <= b[start - 1] <= 57:
            start -= 1
        end = pos
        while end < len(b) and 48 <= b[end] <= 57:
            end += 1
        new = str(rng.choice([0, 1, 2, 4, -1, 255, 65536, 2 ** 31, 2 ** 32 + 3, 10 ** 12,
                              int(rng.integers(0, 10 ** 9))])).encode()
        if kind == "insert token":
            new = b[start:end] + rng.choice([b" x", b" nan", b" 1e999", b" -0", b" 3"])
        b[start:end] = new
    else:
        lines = bytes(b).split(b"\n")
        i = int(rng.integers(len(lines)))
        lines = lines[:i] + ([lines[i]] * 2 if kind == "duplicate line" else []) + lines[i + 1:]
        b = bytearray(b"\n".join(lines))
    return bytes(b)


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS / /proc are Linux")
@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
@given(batch=st.lists(st.tuples(st.sampled_from(sorted(VALID)), st.sampled_from(MUTATIONS),
                                st.integers(0, 2**32 - 1)), min_size=30, max_size=30))
def test_mutated_files_through_the_cli(tmp_path_factory, batch):
    """Byte flips, truncations, count changes, deleted/duplicated lines and inserted
    tokens in valid files, each through ``igl-hhj info`` and ``igl-hhj curvature``
    in a child capped at +1 GB: exit 0 (or 1 for a rejected mesh in info) or one
    error line, each in seconds."""
    folder = tmp_path_factory.mktemp("mutated")
    jobs = []
    for k, (fmt, kind, seed) in enumerate(batch):
        path = folder / f"m{k}{fmt}"
        path.write_bytes(_mutate(VALID[fmt], kind, seed))
        jobs += [["info", path], ["curvature", path]]
    codes = collections.Counter()
    for rec in run_capped(jobs, extra_mb=1024, seconds=20):
        ok = {0, 1, cli.EXIT_UNREADABLE, cli.EXIT_MEMORY} if rec["argv"][0] == "info" else \
            {0, cli.EXIT_USAGE, cli.EXIT_UNREADABLE, cli.EXIT_SOLVER, cli.EXIT_MEMORY}
        codes[check_outcome(rec, ok)] += 1
        assert rec["seconds"] < 10, rec["argv"]
    FUZZ_COUNTS["mutated files (CLI runs)"] += len(jobs)
    assert codes[cli.EXIT_MEMORY] == 0, "a file guard let a memory explosion through"


def test_valid_files_are_accepted(tmp_path):
    """Control for the mutation fuzzer: every unmutated file reads and is accepted."""
    for fmt, data in VALID.items():
        path = tmp_path / f"valid{fmt}"
        path.write_bytes(data)
        assert cli.main(["info", str(path)]) == 0, fmt
        V, F = igl.read_triangle_mesh(str(path))
        assert len(F) == len(F1), fmt


@pytest.mark.slow
def test_defect_meshes_against_libigl():
    """1,000 seeded small spheres / tori with 1-3 defects each (duplicate and reversed
    duplicate faces, flips, fins, zero-area faces, repeated corners, slivers, holes,
    Möbius components; ``conftest.defect_mesh``), every 5th as float32 / int32: the
    drop-in repairs them (issue 24) and its result has libigl's structure (shapes; float64
    as libigl on float64 input), NaN rows are exactly ``bad_vertices``, at most one
    MeshWarning, and a vertex that libigl gives finite values is bad only when the
    repaired mesh leaves it no face or no tangent plane, or only faces of a two-sided patch."""
    n_repaired = 0
    for seed in range(1000):
        V, F, kinds = defect_mesh(seed)
        FUZZ_COUNTS["defect meshes (drop-in repairs)"] += 1
        if seed % 5 == 4:
            V, F = V.astype(np.float32), F.astype(np.int32)
        with warnings.catch_warnings(record=True) as rec:
            warnings.simplefilter("always")
            PD1, PD2, PV1, PV2, bad = out = igl_hhj.principal_curvature(V, F, solver="direct")
        ws = [w for w in rec if issubclass(w.category, MeshWarning)]
        assert len(ws) <= 1, (seed, kinds)
        n_repaired += len(ws)
        rows = np.column_stack([PD1, PD2, PV1, PV2])
        assert rows.dtype == np.float64 and all(a.dtype == np.float64 for a in out[:4])
        nan = ~np.isfinite(rows).all(axis=1)
        assert np.isnan(rows[nan]).all() and np.flatnonzero(nan).tolist() == bad, (seed, kinds)
        assert isinstance(bad, list) and all(type(i) is int for i in bad)
        assert np.all(PV1[~nan] >= PV2[~nan])
        try:
            ref = igl.principal_curvature(V, F)
        except Exception:                                  # libigl refused: only our structure
            ref = None
        if ref is None:
            continue
        for a, b in zip(out[:4], ref[:4]):
            b = np.asarray(b)
            assert a.shape == b.shape, (seed, kinds)
            assert V.dtype != np.float64 or a.dtype == b.dtype, (seed, kinds)
        igl_finite = np.isfinite(np.column_stack(ref[:4])).all(axis=1)
        R = rp.repair_mesh(V, F)
        explained = np.ones(len(V), dtype=bool)
        if len(R.F):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", MeshWarning)   # split seams coincide on purpose
                m = TriangleMesh(R.V, R.F)
            # a vertex on a two-sided patch (every face also given reversed) has no sign: NaN
            explained[R.vertex_map[m.referenced_vertices & ~m.folded_vertices & ~rp.two_sided_vertices(R)]] = False
        assert not (nan & igl_finite & ~explained).any(), (seed, kinds)
    assert n_repaired > 900
