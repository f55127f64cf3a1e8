"""The speed benchmark runs (on tiny sizes) and reports what it measured."""
from igl_hhj.benchmarks import speed


def test_speed_run_small(tmp_path):
    rows = speed.run(max_faces=25_000, repeat=1, solvers=("auto", "cg"), progress=False)
    assert {r["surface"] for r in rows} == {"ellipsoid", "torus"}
    for r in rows:
        assert r["libigl"] > 0 and r["hhj_auto"] > 0 and r["hhj_cg"] > 0 and r["dropin"] > 0
    table = speed.markdown(rows, solvers=("auto", "cg"))
    assert table.count("\n") == len(rows) + 1 and "ratio libigl/drop-in" in table
