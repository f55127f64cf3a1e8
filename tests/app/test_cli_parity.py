"""The command line does what the drop-in does: ``igl-hhj curvature`` and ``batch`` repair what
:func:`igl_hhj.principal_curvature` repairs (one ``igl-hhj: warning:`` line naming the repair,
values on the file's own rows, equal to the drop-in's), ``--strict`` refuses; tiny meshes are
"too small", never all-NaN; two-sided patches have no sign."""
from __future__ import annotations

import csv
import warnings
from pathlib import Path

import igl
import numpy as np
import pytest
from conftest import defect_mesh, fin, write_off

import igl_hhj
from igl_hhj import cli, repair
from igl_hhj.mesh import MeshDefectError, TriangleMesh
from igl_hhj.surfaces import icosphere


def voxel_pair_obj(path):
    """Two unit cubes side by side written as quads, the shared square once per cube (so in
    both orientations), as libigl's ``cube_40k.obj`` voxel soup: quads split, a two-sided
    face, four faces on each edge of the shared square."""
    V = np.array([[x, y, z] for x in (0, 1, 2) for y in (0, 1) for z in (0, 1)], dtype=float)
    idx = {tuple(v): i + 1 for i, v in enumerate(V.astype(int))}
    quads = []
    for x0 in (0, 1):
        c = lambda x, y, z: idx[(x0 + x, y, z)]           # noqa: E731
        quads += [(c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)), (c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)),
                  (c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)), (c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)),
                  (c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)), (c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1))]
    path.write_text("".join(f"v {x:g} {y:g} {z:g}\n" for x, y, z in V)
                    + "".join("f " + " ".join(map(str, q)) + "\n" for q in quads))
    return path


def dropin(V, F):
    with warnings.catch_warnings(record=True) as ws:
        warnings.simplefilter("always")
        out = igl_hhj.principal_curvature(V, F)
    return out, [str(w.message) for w in ws]


def warning_lines(err):
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert all(ln.startswith("igl-hhj: warning: ") for ln in lines), lines
    return lines


# --------------------------------------------------------------------------- curvature = the drop-in
@pytest.mark.parametrize("seed", range(8))
def test_curvature_repairs_what_the_dropin_repairs(tmp_path, capsys, seed):
    V, F, kinds = defect_mesh(seed)
    path = write_off(tmp_path / "m.off", V, F)
    V, F = igl.read_triangle_mesh(str(path))
    (PD1, PD2, PV1, PV2, bad), said = dropin(V, F)
    out = tmp_path / "m.npz"
    assert cli.main(["curvature", str(path), "-o", str(out), "-q"]) == 0, capsys.readouterr().err
    lines = warning_lines(capsys.readouterr().err)
    repaired = bool(said)
    assert len(lines) == int(repaired), (kinds, lines)
    if repaired:
        assert "the mesh was repaired" in lines[0] and repair.repair_mesh(V, F).describe() in lines[0]
    with np.load(out) as z:
        assert z["V"].shape == V.shape and z["F"].shape == F.shape       # the file's own rows
        np.testing.assert_array_equal(z["H"], 0.5 * (PV1 + PV2))
        np.testing.assert_array_equal(np.isnan(z["k1"]), np.isin(np.arange(len(V)), bad))
    if repaired:
        assert cli.main(["curvature", str(path), "--strict"]) == 2
        err = capsys.readouterr().err
        assert "--strict" in err and "cannot use this mesh" in err


def test_curvature_voxel_soup_like_cube_40k(tmp_path, capsys):
    """Quads, a face given in both orientations, non-manifold edges: exit 0, one warning."""
    path = voxel_pair_obj(tmp_path / "cubes.obj")
    with pytest.raises(MeshDefectError):
        TriangleMesh(*igl.read_triangle_mesh(str(path)))
    out = tmp_path / "c.csv"
    assert cli.main(["curvature", str(path), "-o", str(out)]) == 0
    cap = capsys.readouterr()
    lines = warning_lines(cap.err)
    assert len(lines) == 1 and "two-sided" in lines[0] and "non-manifold" in lines[0]
    assert "quads split" in cap.out
    assert len(out.read_text().splitlines()) == 1 + 12         # one row per vertex of the file


def test_batch_repairs_and_strict_refuses(tmp_path):
    pytest.importorskip("distributed")
    V, F = icosphere(2)
    V, F, _ = fin(V, F)
    path = write_off(tmp_path / "fin.off", V, F)
    cubes = voxel_pair_obj(tmp_path / "cubes.obj")
    for strict, status in ((False, "ok"), (True, "error")):
        out = tmp_path / f"out{strict}"
        code = cli.main(["batch", str(path), str(cubes), "-o", str(out), "--workers", "0", "-q"]
                        + ["--strict"] * strict)
        assert code == (1 if strict else 0)
        rows = {r["path"]: r for r in csv.DictReader(open(out / "summary.csv"))}
        for p in (path, cubes):
            r = rows[str(p)]
            assert r["status"] == status, r
            if strict:
                assert "--strict" in r["error"] and "non-manifold" in r["error"]
            else:
                assert "the mesh was repaired" in r["warnings"] and Path(r["output"]).is_file()


# --------------------------------------------------------------------------- tiny meshes
@pytest.mark.parametrize("defect", [None, "repeated corner", "fin"])
def test_tiny_mesh_is_too_small_not_all_nan(tmp_path, capsys, defect):
    """Edges ~1e-85: the squared areas underflow; the size test comes before the zero-area one."""
    V, F = icosphere(1)
    if defect == "repeated corner":
        F = np.vstack([F, [[0, 0, 1]]])
    elif defect == "fin":
        V, F, _ = fin(V, F)
    V = V * 1e-85
    with pytest.raises(ValueError, match="too small"):
        igl_hhj.principal_curvature(V, F)
    with pytest.raises(ValueError, match="too small"):
        repair.repair_mesh(V, F)
    path = write_off(tmp_path / "tiny.off", V, F)
    assert cli.main(["curvature", str(path)]) == 2
    assert "too small" in capsys.readouterr().err
    # the same mesh at a sane scale is accepted (or repaired): the size is the only problem
    out, _ = dropin(V * 1e85, F)
    assert np.isfinite(out[2][np.unique(F)]).any()


# --------------------------------------------------------------------------- two-sided meshes
def test_two_sided_mesh_has_no_sign(tmp_path, capsys):
    V, F = icosphere(2)
    for FF in (np.vstack([F, F[:, ::-1]]), np.vstack([F[:, ::-1], F])):     # either face order
        (PD1, PD2, PV1, PV2, bad), said = dropin(V, FF)
        assert np.isnan(PV1).all() and bad == list(range(len(V)))
        assert len(said) == 1 and "two-sided" in said[0]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            S = igl_hhj.shape_operator(V, FF, repair=True)
        assert np.isnan(S).all()
    path = write_off(tmp_path / "two.off", V, np.vstack([F, F[:, ::-1]]))
    assert cli.main(["info", str(path)]) == 1
    out = capsys.readouterr().out
    assert "orientation       ambiguous" in out and "consistent" not in out.split("orientation")[1].split("\n")[0]
    # a few reversed faces on a sphere: the rest of the sphere says which side is out
    (_, _, PV1, _, bad), said = dropin(V, np.vstack([F, F[:5, ::-1]]))
    assert bad == [] and np.all(PV1 > 0) and "two-sided" not in said[0]


def test_repair_flags_only_patches_without_a_one_sided_face():
    V, F = icosphere(1)
    V2 = V + [3.0, 0, 0]
    FF = np.vstack([F, F[:, ::-1], F + len(V), F[:3, ::-1] + len(V)])    # sphere 1 two-sided
    R = repair.repair_mesh(np.vstack([V, V2]), FF)
    assert R.summary["two-sided"] == len(F) and R.two_sided.sum() == len(F)
    assert (R.face_map[R.two_sided] < len(F)).all()
    assert not repair.two_sided_vertices(R)[R.F[~R.two_sided].ravel()].any()


# --------------------------------------------------------------------------- small things
def test_closed_stdout_pipe_is_quiet(tmp_path):
    """``igl-hhj info m.off | head``: the reader is gone; no 'error: Broken pipe', exit 141."""
    import os
    import subprocess
    import sys
    V, F = icosphere(1)
    path = write_off(tmp_path / "s.off", V, F)
    r, w = os.pipe()
    os.close(r)                                     # every write to w fails with EPIPE
    try:
        run = subprocess.run([sys.executable, "-m", "igl_hhj.cli", "info", str(path)], stdout=w,
                             stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(w)
    assert run.returncode == cli.program.EXIT_BROKEN_PIPE == 141 and run.stderr == "", run.stderr


@pytest.mark.parametrize("content, why", [("{\"a\":" * 100000 + "1" + "}" * 100000, "nested too deeply"),
                                          ("[1, 2]", "a JSON list"), ("{oops", "not JSON")])
def test_batch_bad_options_file_is_a_usage_error(tmp_path, capsys, content, why):
    """A deeply nested options file stopped batch with exit 4 'computation failed'."""
    from igl_hhj import batch
    V, F = icosphere(1)
    path = write_off(tmp_path / "s.off", V, F)
    out = tmp_path / "out"
    out.mkdir()
    (out / batch.OPTIONS_FILE).write_text(content)
    assert cli.main(["batch", str(path), "-o", str(out), "--workers", "0", "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and batch.OPTIONS_FILE in err[0] and why in err[0] and "delete it" in err[0]


def test_batch_does_not_wait_forever_without_workers(tmp_path, monkeypatch):
    """The embedded cluster lost its last worker (its nanny gives up on a worker that stopped
    answering, dask/distributed#8537): the tasks become error rows after NO_WORKER_SECONDS
    instead of the client waiting forever (batch --workers 1 hung 110 s, 300 s)."""
    distributed = pytest.importorskip("distributed")
    import time

    from igl_hhj.batch import jobs, run
    monkeypatch.setattr(run, "NO_WORKER_SECONDS", 1.0)
    monkeypatch.setattr(run, "WATCH_SECONDS", 0.2)
    V, F = icosphere(1)
    path = write_off(tmp_path / "s.off", V, F)
    job = jobs.Job(str(path), str(tmp_path / "s.npz"))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address="127.0.0.1:0") as cluster, \
            distributed.Client(cluster) as client:
        cluster.scale(0)
        t = time.monotonic()
        while client.scheduler_info()["workers"] and time.monotonic() - t < 30:
            time.sleep(0.05)
        rows = []
        t = time.monotonic()
        run._on_dask(client, [[job]], jobs.Options(), rows.append)
        assert time.monotonic() - t < 20
    assert len(rows) == 1 and rows[0]["status"] == "error" and "no worker process left" in rows[0]["error"]


def test_quad_split_is_a_note_everywhere(tmp_path, capsys):
    """A quad split is a plain line of curvature / info and its own summary column in batch,
    never an 'igl-hhj: warning:' line (batch printed it as a warning)."""
    pytest.importorskip("distributed")
    path = tmp_path / "q.obj"                                       # a cube of 6 quads
    V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    Q = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])
    lines = [f"v {x:g} {y:g} {z:g}" for x, y, z in V] + ["f " + " ".join(str(i + 1) for i in q) for q in Q]
    path.write_text("\n".join(lines) + "\n")
    assert cli.main(["curvature", str(path)]) == 0
    cap = capsys.readouterr()
    assert "6 quads split into 12 triangles" in cap.out and "warning" not in cap.err
    out = tmp_path / "out"
    assert cli.main(["batch", str(path), "-o", str(out), "--workers", "0", "-q"]) == 0
    assert "warning" not in capsys.readouterr().err
    row = next(csv.DictReader(open(out / "summary.csv")))
    assert row["warnings"] == "" and row["polygons"].startswith("6 quads split into 12 triangles")
