"""Package-level contracts: lazy optional imports, the CLI."""
import subprocess
import sys

import numpy as np

from igl_hhj import cli


def test_import_is_light():
    code = ("import sys, igl_hhj; import igl_hhj.regge, igl_hhj.biharmonic; "
            "print(any(m in sys.modules for m in ('polyscope', 'matplotlib', 'tqdm', 'triangle')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_lazy_attributes():
    import igl_hhj
    assert callable(igl_hhj.biharmonic_solve)
    assert callable(igl_hhj.regge.gauss_curvature)
    try:
        igl_hhj.no_such_thing
    except AttributeError as exc:
        assert "no_such_thing" in str(exc)
    else:
        raise AssertionError("missing attribute did not raise")


def test_cli_demo(capsys):
    assert cli.main(["demo", "--levels", "3"]) == 0
    out = capsys.readouterr().out
    assert "HHJ err H" in out and "EOC (last level)" in out
    rows = [line for line in out.splitlines() if line.strip()[:1].isdigit()]
    assert len(rows) == 3


def test_cli_curvature(tmp_path, capsys):
    import igl
    V, F = igl.icosahedron()
    for _ in range(2):
        V, F = igl.upsample(V, F)
        V = V / np.linalg.norm(V, axis=1, keepdims=True)
    path = tmp_path / "sphere.off"
    igl.write_triangle_mesh(str(path), V, F)
    out_npz = tmp_path / "k.npz"
    assert cli.main(["curvature", str(path), "--out", str(out_npz)]) == 0
    data = np.load(out_npz)
    assert data["S"].shape == (len(F), 3, 3)
    assert abs(np.median(data["PV1"]) - 1.0) < 0.05
    assert "median" in capsys.readouterr().out


def test_cli_reports_bad_mesh(tmp_path, capsys):
    path = tmp_path / "bad.off"
    path.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n")
    assert cli.main(["curvature", str(path)]) == 2
    assert "degenerate" in capsys.readouterr().err
