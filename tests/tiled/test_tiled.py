"""``igl_hhj.tiled``: tiled curvature equal to the whole-mesh drop-in, resume, the streaming
PLY reader against libigl's, a loopback Dask cluster, bad input.

The equality tests run at ``rtol=1e-12`` (smoothing solves to 1e-6), so that what they
measure is the cut's effect, which the overlap rule bounds by ``eps`` = 1e-6 × max |κ|;
at the default ``rtol`` the tiled and whole-mesh values differ by the solvers' tolerance
(``igl_hhj/docs/tiled.md``).  Network: 127.0.0.1 only.
"""
from __future__ import annotations

import warnings

import igl
import numpy as np
import pytest
from conftest import fins

import igl_hhj
import igl_hhj.tiled as tiled
from igl_hhj.surfaces import Ellipsoid, ellipsoid_coarse, icosphere, jitter_tangentially, refine
from igl_hhj.tiled import reach
from igl_hhj.tiled.ply import write_binary_ply
from igl_hhj.tiled.source import open_mesh_file

TIGHT = 1e-12


def _ellipsoid(levels, noise=0.0, seed=6):
    ell = Ellipsoid()
    V, F = ellipsoid_coarse(ell, subdivisions=3, amount=0.2)
    V, F = refine(V, F, ell, levels)
    if noise:
        h = igl.avg_edge_length(V, F)
        V = V + noise * h * np.random.default_rng(seed).normal(size=(len(V), 1)) * ell.normal(V)
    return V, F


def _open_saddle(n=90):
    from igl_hhj.benchmarks.speed_meshes import _open_scan
    return _open_scan(n)


def _relative_difference(A, B):
    """max |ΔPV| / max |κ| over the vertices, and the worst direction error where the
    principal curvatures are apart (|PD1·PD1'| < 1 measures the angle)."""
    kmax = np.nanmax(np.abs(np.r_[B[2], B[3]]))
    dv = max(np.nanmax(np.abs(A[2] - B[2])), np.nanmax(np.abs(A[3] - B[3]))) / kmax
    gap = (B[2] - B[3]) > 1e-2 * kmax
    cos = np.abs(np.einsum("ij,ij->i", A[0][gap], B[0][gap]))
    return dv, float(1.0 - cos.min()) if gap.any() else 0.0


def _assert_equal_to_whole(V, F, tile_faces, min_tiles, rtol=TIGHT, **kw):
    W = igl_hhj.principal_curvature(V, F, rtol=rtol)
    T = tiled.principal_curvature(V, F, tile_faces=tile_faces, workers=0, rtol=rtol, **kw)
    assert T[4] == W[4]
    for a, b in zip(T[:4], W[:4]):
        assert np.array_equal(np.isnan(a), np.isnan(b))
    dv, dd = _relative_difference(T, W)
    assert dv <= reach.DEFAULT_TOLERANCE, dv
    assert dd <= 1e-6, dd
    from igl_hhj.tiled.partition import plan_tiles
    from igl_hhj.tiled.source import ArraySource
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        assert plan_tiles(ArraySource(V, F), d, tile_faces).n_tiles >= min_tiles
    return dv


# --------------------------------------------------------------------------- equality
@pytest.mark.slow
def test_closed_smooth_mesh_with_real_cuts():
    """icosphere(6): r_T ≈ 1, overlap 19 rings, 10 tiles whose cuts lie inside the mesh."""
    _assert_equal_to_whole(*icosphere(6), tile_faces=8000, min_tiles=8)


@pytest.mark.slow
def test_jittered_closed_mesh():
    _assert_equal_to_whole(*_ellipsoid(3), tile_faces=10000, min_tiles=8)        # 82k faces


@pytest.mark.slow
def test_noisy_closed_mesh():
    _assert_equal_to_whole(*_ellipsoid(1, noise=0.05), tile_faces=600, min_tiles=8)   # 5k faces


@pytest.mark.slow
def test_open_mesh():
    _assert_equal_to_whole(*_open_saddle(), tile_faces=1400, min_tiles=8)


def test_small_mesh_several_tiles_fast():
    V, F = icosphere(3)
    V = jitter_tangentially(V, F, igl_hhj.surfaces.Sphere(), amount=0.3, seed=1)
    _assert_equal_to_whole(V, F, tile_faces=200, min_tiles=4)


@pytest.mark.slow
def test_fixed_small_overlap_is_visible_and_rule_is_not():
    """A fixed overlap of 2 rings leaves the cut's effect in the values (the test can fail)."""
    V, F = _ellipsoid(3)
    W = igl_hhj.principal_curvature(V, F, rtol=TIGHT)
    T = tiled.principal_curvature(V, F, tile_faces=10000, workers=0, rtol=TIGHT, overlap=2)
    assert _relative_difference(T, W)[0] > 1e-3


@pytest.mark.slow
def test_bad_vertices_and_repairs_as_the_dropin():
    """Unreferenced vertex, fins (non-manifold edges), a duplicate face, a Möbius band, a
    two-sided sheet: the same NaN rows, the same values, one MeshWarning."""
    from conftest import moebius
    V, F = icosphere(5)
    V, F = fins(V, F, [5, 4000, 9000])
    F = np.vstack([F, F[100:101]])
    Vm, Fm = moebius(12)
    V, F = np.vstack([V, Vm, [[9.0, 9.0, 9.0]]]), np.vstack([F, Fm + len(V)])
    sheet = np.array([[0, 0, 5.0], [1, 0, 5.0], [0, 1, 5.0]])
    F = np.vstack([F, [[len(V), len(V) + 1, len(V) + 2], [len(V), len(V) + 2, len(V) + 1]]])
    V = np.vstack([V, sheet])
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        W = igl_hhj.principal_curvature(V, F, rtol=TIGHT)
        T = tiled.principal_curvature(V, F, tile_faces=2000, workers=0, rtol=TIGHT)
    assert T[4] == W[4] and len(W[4]) >= 4
    assert _relative_difference(T, W)[0] <= reach.DEFAULT_TOLERANCE
    tiled_warnings = [x for x in w if "tiles warned" in str(x.message)]
    assert len(tiled_warnings) == 1 and "repaired" in str(tiled_warnings[0].message)


# --------------------------------------------------------------------------- files, resume
def _ply(tmp_path, V, F, name="m.ply"):
    p = tmp_path / name
    write_binary_ply(p, len(V), len(F), [V], [F])
    return p


def test_curvature_file_equals_in_memory_and_reads_back(tmp_path, capsys):
    V, F = _ellipsoid(1)
    res = tiled.curvature_file(_ply(tmp_path, V, F), tmp_path / "out", tile_faces=1500, workers=0,
                               overlap=3, progress=True)
    assert capsys.readouterr().err.count("faces computed for") == len(res.stats)     # not a terminal: lines
    assert res.read == "memory-mapped" and len(res.stats) >= 4 and res.n_faces == len(F)
    PD1, PD2, PV1, PV2, bad = tiled.read_result(tmp_path / "out")
    assert isinstance(PV1, np.memmap)
    T = tiled.principal_curvature(V, F, tile_faces=1500, workers=0, overlap=3)
    for a, b in zip((PD1, PD2, PV1, PV2), T[:4]):
        assert np.array_equal(a, b)
    assert bad.tolist() == T[4]
    assert (tmp_path / "out" / "tiles.csv").read_text().count("\n") == len(res.stats) + 1


@pytest.mark.slow
def test_resume_computes_only_unfinished_tiles(tmp_path, monkeypatch):
    V, F = _ellipsoid(1)
    mesh = _ply(tmp_path, V, F)
    fresh = tiled.curvature_file(mesh, tmp_path / "fresh", tile_faces=1000, workers=0, overlap=3)
    from igl_hhj.tiled import runner
    real, calls = runner.compute_tile, []

    def interrupted(*a, **k):
        if len(calls) == 3:
            raise KeyboardInterrupt
        calls.append(a[2])
        return real(*a, **k)

    monkeypatch.setattr(runner, "compute_tile", interrupted)
    with pytest.raises(KeyboardInterrupt):
        tiled.curvature_file(mesh, tmp_path / "out", tile_faces=1000, workers=0, overlap=3)
    monkeypatch.setattr(runner, "compute_tile", real)
    again = tiled.curvature_file(mesh, tmp_path / "out", tile_faces=1000, workers=0, overlap=3)
    assert again.resumed and sorted(again.computed) == sorted(set(fresh.stats) - set(calls))
    for a, b in zip(tiled.read_result(tmp_path / "out"), tiled.read_result(tmp_path / "fresh")):
        assert np.array_equal(a, b)
    done = tiled.curvature_file(mesh, tmp_path / "out", tile_faces=1000, workers=0, overlap=3)
    assert done.resumed and done.computed == []
    other = tiled.curvature_file(mesh, tmp_path / "out", tile_faces=1000, workers=0, overlap=4)
    assert not other.resumed and len(other.computed) == len(other.stats)      # options changed


# --------------------------------------------------------------------------- streaming PLY
def _quads(n=6):
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    V = np.stack([i.ravel(), j.ravel(), np.sin(i.ravel() + 0.3 * j.ravel())], axis=1).astype(float)
    q = (i[:-1, :-1] * n + j[:-1, :-1]).ravel()
    return V, np.stack([q, q + n, q + n + 1, q + 1], axis=1)


def _write_ply(path, V, P, fmt="binary_little_endian", extra=True):
    """A PLY with normals and uchar colours besides x, y, z, and polygons P."""
    order = {"binary_little_endian": "<", "binary_big_endian": ">"}.get(fmt)
    props = ["float x", "float y", "float z", "float nx", "float ny", "float nz"] if extra else \
        ["double x", "double y", "double z"]
    props += ["uchar red", "uchar green", "uchar blue"] if extra else []
    head = ["ply", f"format {fmt} 1.0", f"element vertex {len(V)}", *[f"property {p}" for p in props],
            f"element face {len(P)}", "property list uchar int vertex_indices", "end_header"]
    k = P.shape[1]
    with open(path, "wb") as fh:
        fh.write(("\n".join(head) + "\n").encode())
        if order is None:
            for v in V:
                fh.write((" ".join(repr(float(x)) for x in v) + (" 0 0 1 10 20 30" if extra else "") + "\n").encode())
            for p in P:
                fh.write((f"{k} " + " ".join(map(str, p)) + "\n").encode())
            return path
        if extra:
            dt = np.dtype([(c, order + "f4") for c in ("x", "y", "z", "nx", "ny", "nz")]
                          + [(c, "u1") for c in ("r", "g", "b")])
        else:
            dt = np.dtype([(c, order + "f8") for c in "xyz"])
        rec = np.zeros(len(V), dt)
        for a, c in enumerate("xyz"):
            rec[c] = V[:, a]
        fh.write(rec.tobytes())
        frec = np.zeros(len(P), np.dtype([("n", "u1"), ("i", order + "i4", (k,))]))
        frec["n"], frec["i"] = k, P
        fh.write(frec.tobytes())
    return path


@pytest.mark.parametrize("fmt", ["binary_little_endian", "binary_big_endian", "ascii"])
@pytest.mark.parametrize("shape", ["triangles", "quads"])
def test_streaming_ply_reader_equals_libigl(tmp_path, fmt, shape):
    from igl_hhj.mesh_io import read_mesh
    if shape == "triangles":
        V, F = icosphere(2)
        P = F
    else:
        V, P = _quads()
    path = _write_ply(tmp_path / "m.ply", V.astype(np.float32).astype(float), P, fmt)
    src, how = open_mesh_file(path, tmp_path / "w")
    assert how == ("converted" if fmt == "ascii" else "memory-mapped")
    if shape == "triangles":
        V2, F2 = igl.read_triangle_mesh(str(path))
    else:
        V2, F2, _ = read_mesh(path)                  # libigl cannot read polygons: the fans
    assert np.array_equal(src.vertices(slice(None)), V2)
    assert np.array_equal(src.faces(slice(None)), F2)
    rows = np.array([len(F2) - 1, 0, 3])
    assert np.array_equal(src.faces(rows), F2[rows])


def test_off_and_other_formats_are_converted(tmp_path):
    V, F = icosphere(2)
    igl.write_triangle_mesh(str(tmp_path / "m.off"), V, F)
    igl.write_triangle_mesh(str(tmp_path / "m.obj"), V, F)
    for name, how in (("m.off", "converted"), ("m.obj", "read whole")):
        src, got = open_mesh_file(tmp_path / name, tmp_path / ("w" + name))
        V2, F2 = igl.read_triangle_mesh(str(tmp_path / name))
        assert got == how
        assert np.array_equal(src.vertices(slice(None)), V2) and np.array_equal(src.faces(slice(None)), F2)


def test_corrupt_ply_face_count_is_named(tmp_path):
    from igl_hhj.mesh_io import MeshFileError
    V, F = icosphere(1)
    p = _write_ply(tmp_path / "m.ply", V, F, extra=False)
    raw = bytearray(p.read_bytes())
    at = raw.index(b"end_header\n") + len(b"end_header\n") + 24 * len(V) + 13 * 7
    raw[at] = 4
    p.write_bytes(bytes(raw))
    with pytest.raises(MeshFileError, match="face 7 declares 4 corners"):
        open_mesh_file(p, tmp_path / "w")


# --------------------------------------------------------------------------- loopback cluster
@pytest.mark.slow
def test_loopback_cluster_equals_in_process(loopback_cluster, tmp_path):
    address, _ = loopback_cluster
    V, F = _ellipsoid(1)
    mesh = _ply(tmp_path, V, F)
    a = tiled.curvature_file(mesh, tmp_path / "dask", tile_faces=1500, scheduler=address)
    b = tiled.curvature_file(mesh, tmp_path / "local", tile_faces=1500, workers=0)
    assert len(a.computed) == len(a.stats) >= 4
    for x, y in zip(tiled.read_result(a.out), tiled.read_result(b.out)):
        assert np.array_equal(x, y)


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kw, exc, match", [
    (dict(tile_faces=0), ValueError, "tile_faces must be ≥ 1"),
    (dict(tile_faces=2.5), TypeError, "tile_faces must be an int"),
    (dict(overlap=-1), ValueError, "overlap must be ≥ 0"),
    (dict(eps=0), ValueError, "eps must be a number in"),
    (dict(radius=0), ValueError, "radius must be positive"),
    (dict(rtol=2.0), ValueError, "rtol must be in"),
    (dict(solver="lu"), ValueError, "solver must be"),
    (dict(boundary="x"), ValueError, "boundary must be one of"),
    (dict(workers=-2), ValueError, "workers must be ≥ 0"),
])
def test_bad_options(kw, exc, match):
    V, F = icosphere(1)
    with pytest.raises(exc, match=match):
        tiled.principal_curvature(V, F, **{"workers": 0, **kw})


@pytest.mark.parametrize("change, exc, match", [
    (lambda V, F: (np.where(np.arange(len(V))[:, None] == 3, np.nan, V), F), ValueError, "NaN or inf"),
    (lambda V, F: (V, np.where(F == F.max(), len(V) + 5, F)), ValueError, "out-of-range"),
    (lambda V, F: (V, -F), ValueError, "negative vertex indices"),
    (lambda V, F: (V[:, :2], F), ValueError, r"shape \(#V, 3\)"),
    (lambda V, F: (V, F.astype(float)), TypeError, "integer vertex indices"),
    (lambda V, F: (V, F[:0]), ValueError, "empty"),
])
def test_bad_mesh_in_memory_and_in_file(tmp_path, change, exc, match):
    V, F = change(*icosphere(1))
    with pytest.raises(exc, match=match):
        tiled.principal_curvature(V, F, workers=0)
    if V.ndim == 2 and V.shape[1] == 3 and np.issubdtype(F.dtype, np.integer) and len(F) and F.min() >= 0:
        with pytest.raises(exc, match=match):
            tiled.curvature_file(_ply(tmp_path, V, F), tmp_path / "out", workers=0)


def test_missing_file_and_unfinished_output(tmp_path):
    from igl_hhj.mesh_io import MeshFileError
    with pytest.raises(MeshFileError, match="no such file"):
        tiled.curvature_file(tmp_path / "nope.ply", tmp_path / "out", workers=0)
    with pytest.raises(ValueError, match="not a finished"):
        tiled.read_result(tmp_path)


@pytest.mark.slow
def test_a_tile_given_too_few_rings_is_regrown():
    """The radius the vertex stage chose decides: a tile started with 2 rings is regrown to the
    rule's rings for it (or until it holds whole components)."""
    import tempfile
    from igl_hhj.tiled.partition import plan_tiles
    from igl_hhj.tiled.source import ArraySource
    from igl_hhj.tiled.tile import compute_tile
    V, F = _ellipsoid(3)
    src = ArraySource(V, F)
    with tempfile.TemporaryDirectory() as d:
        plan = plan_tiles(src, d, 10000)
        params = dict(radius=5.0, rtol=1e-6, solver="auto", boundary="estimate", eps=1e-6, rings=2,
                      rings_bound=reach.overlap_rings(25.0), fixed=False)
        _, _, st = compute_tile(src, plan, 3, params)
    assert st["rounds"] >= 2 and st["radius_max"] > 1.0
    assert st["complete"] or st["rings"] >= reach.overlap_rings(st["radius_max"]) > 2


def test_overlap_rule():
    assert reach.overlap_rings(25.0) > reach.overlap_rings(5.0) > reach.overlap_rings(1.0) > reach.hhj_rings()
    assert reach.overlap_rings(5.0, 1e-9) > reach.overlap_rings(5.0, 1e-6)
    assert reach.overlap_rings(5.0, boundary=True) > reach.overlap_rings(5.0)
    assert reach.radius_bound(5) == 25.0
    x = reach.gamma_tail_root(4, 1e-6)
    assert abs(np.exp(-x) * (1 + x + x * x / 2 + x ** 3 / 6) - 1e-6) < 1e-12


# --------------------------------------------------------------------------- command line
@pytest.mark.slow
def test_cli_tile_faces(tmp_path, capsys):
    from igl_hhj import cli
    V, F = _ellipsoid(1)
    mesh = _ply(tmp_path, V, F)
    assert cli.main(["curvature", str(mesh), "-o", str(tmp_path / "out"), "--tile-faces", "1500",
                     "--workers", "0"]) == 0
    said = capsys.readouterr().out
    assert "tiles computed" in said and "PV1.npy" in said
    ref = tiled.principal_curvature(V, F, tile_faces=1500, workers=0)
    for a, b in zip(tiled.read_result(tmp_path / "out"), ref):
        assert np.array_equal(a, b)
    for extra, match in ((["--per", "face"], "--per cannot be used"), ([], "needs -o OUT")):
        args = ["curvature", str(mesh), "--tile-faces", "1500", *extra]
        if extra:
            args += ["-o", str(tmp_path / "o2")]
        assert cli.main(args) == 2
        assert match in capsys.readouterr().err
    assert cli.main(["curvature", str(tmp_path / "nope.ply"), "-o", str(tmp_path / "o3"), "--tile-faces", "9"]) == 3
