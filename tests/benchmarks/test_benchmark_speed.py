"""The speed benchmark runs (on its quick meshes) and reports what it measured."""
import numpy as np
import pytest

from igl_hhj.benchmarks import speed


@pytest.mark.slow
def test_speed_run_quick():
    rows = speed.run(speed.QUICK, repeat=1, progress=False, memory=True, fresh=2)
    assert len(rows) == 3
    for r in rows:
        assert r["libigl"] > 0 and r["dropin"] > 0 and r["S_auto"] > 0 and r["S_cg"] > 0
        assert r["libigl_r2"] > 0 and r["dropin_r2"] > 0                # radius 2 beside 5
        assert r["chosen"].split()[0] in ("cg", "direct") and r["iterations"] >= 0
        assert r["kb_per_face"] > 0 and r["first_over_later"] > 0 and 0 < r["min_angle"] < 60
        assert len(r["first_over_later_runs"]) == 2       # the median of two fresh processes
        assert r["first_over_later"] == np.median(r["first_over_later_runs"])
    table = speed.markdown(rows)
    assert table.count("\n") == len(rows) + 1 and "peak KB/face" in table and "ratio r2" in table
    assert speed.markdown([{k: v for k, v in r.items() if "_r2" not in k} for r in rows]).count("ratio r2") == 0


def test_real_meshes_read_off_and_obj_above_a_face_count(tmp_path):
    import igl
    from igl_hhj.surfaces import icosphere
    V, F = icosphere(2)                                   # 320 faces
    igl.write_triangle_mesh(str(tmp_path / "a.off"), V, F)
    igl.write_triangle_mesh(str(tmp_path / "b.obj"), *icosphere(1))     # 80 faces
    assert [m[0] for m in speed._build("real", tmp_path)] == ["a.off", "b.obj"]
    assert [m[0] for m in speed._build("real", tmp_path, min_faces=100)] == ["a.off"]


def test_min_angle_of_equilateral_triangle():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]])
    assert abs(speed.min_angle_degrees(V, np.array([[0, 1, 2]])) - 60.0) < 1e-9


def test_rtol_study_small():
    rows = speed.rtol_study(faces=(5_000,), rtols=(1e-4, 1e-12), torus_levels=0)
    assert len(rows) == 4
    tight = [r for r in rows if r["rtol"] == 1e-12]
    loose = [r for r in rows if r["rtol"] == 1e-4]
    assert all(r["change"] == 0 for r in tight)
    assert all(r["deviation"] == 0 for r in tight)
    assert all(0 < lo["deviation"] < 0.5 for lo in loose)
    assert all(lo["iterations"] < ti["iterations"] for lo, ti in zip(loose, tight))
    assert "change vs rtol 1e-12" in speed.rtol_markdown(rows)


@pytest.mark.slow
def test_profile_stages_follows_the_default_drop_in():
    """--profile: every stage of the default drop-in timed, with its iterations and faults."""
    from igl_hhj.benchmarks.speed import profile_stages
    from igl_hhj.surfaces import icosphere
    out = profile_stages(*icosphere(3))
    for key in ("validation + topology", "HHJ solve (auto)", "intrinsic patch recovery",
                "smoothing (pilot + adaptive radius + twiced)", "principal values"):
        assert out[key] > 0
        assert out["x above floor"][key] > 0           # seconds over the bandwidth floor of its arrays
    assert out["bandwidth GB/s"] > 0 and 0 < out["floor of the stages"] < out["total of the stages"]
    assert out["large-call heap scope"] is False          # 1280 faces: below glibc's ceiling
    assert out["smoothing iterations"] > 0 and out["HHJ solver"] in ("direct", "cg")
    assert out["minor page faults"] == sum(out["page faults per stage"].values())


def test_tiny_study_reports_every_tiny_mesh():
    """--tiny: the fixed-cost table covers closed and open meshes under 1,000 faces (plus the
    1,280-face icosphere(3) as the upper end) and states the ≤ 2× target."""
    rows = speed.tiny_study(calls=2)
    assert [r["mesh"] for r in rows][:2] == ["octahedron", "cube"]
    assert {"open grid 18", "open grid 128"} <= {r["mesh"] for r in rows}
    assert all(r["faces"] <= 1280 and r["libigl_ms"] > 0 and r["hhj_ms"] > 0 for r in rows)
    assert all(abs(r["ratio"] - r["hhj_ms"] / r["libigl_ms"]) < 1e-12 for r in rows)
    assert "target ≤ 2" in speed.tiny_markdown(rows)


def test_feature_study_reports_the_feature_meshes():
    """--features: the cost of feature_angle=40 against the plain drop-in on the shared
    fandisk (skipped without the shared meshes), CPU times on one thread."""
    from conftest import MESH_DIR
    if not (MESH_DIR / "fandisk.off").is_file():
        pytest.skip("shared meshes not found")
    rows = speed.feature_study(mesh_dir=MESH_DIR, calls=1)
    assert [r["mesh"] for r in rows] == ["fandisk.off"]
    assert all(r["plain_ms"] > 0 and r["features_ms"] > 0 for r in rows)
    assert all(abs(r["ratio"] - r["features_ms"] / r["plain_ms"]) < 1e-12 for r in rows)
    assert "target ≤ 1.3" in speed.feature_markdown(rows)


def test_smoothing_preconditioner_study_uses_the_dropin_system():
    """smoothing_preconditioners: the h system is symmetric positive definite, Jacobi-CG on
    it converges to the drop-in's tolerance, and symmetric Gauss-Seidel needs fewer
    iterations than Jacobi (the study's premise, on a jittered sphere and the shared bunny)."""
    from conftest import MESH_DIR

    from igl_hhj.benchmarks import smoothing_preconditioners as spc
    from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially
    V, F = icosphere(3)
    V = jitter_tangentially(V, F, Sphere(), amount=0.3, seed=1)
    A, b, info = spc.smoothing_system(V, F, radius=5)
    assert info["status"] == 0 and info["dropin_iterations"] > 0
    assert abs(A - A.T).max() <= 1e-12 * abs(A).max()
    assert np.linalg.eigvalsh(A.toarray()).min() > 0
    pre = spc.preconditioners(A)
    its = {k: spc.pcg_iterations(A, b, apply, info["rtol"]) for k, (apply, _) in pre.items()}
    assert 0 < its["sgs"] < its["jacobi"] < 5000
    if (MESH_DIR / "bunny.off").is_file():
        rows = spc.study(MESH_DIR)
        assert "bunny.off" in [r["mesh"] for r in rows]
        assert all(0 < r["sgs"] < r["jacobi"] for r in rows)
        assert spc.markdown(rows).count("\n") == len(rows) + 3
