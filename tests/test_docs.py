"""The API reference (Sphinx sources in igl_hhj/docs/) builds with warnings as errors
(issue 14): every documented function imports and its numpy-style docstring renders."""
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_api_reference_builds_without_warnings(tmp_path):
    pytest.importorskip("sphinx")
    res = subprocess.run([sys.executable, "-m", "sphinx", "-q", "-W", "--keep-going", "-b", "html",
                          str(ROOT / "igl_hhj" / "docs"), str(tmp_path / "html")],
                         capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    api = (tmp_path / "html" / "api.html").read_text()
    for name in ("shape_operator", "principal_curvature", "plot_convergence", "register_comparison",
                 "write_curvature", "to_meshio"):
        assert f'<span class="pre">{name}</span>' in api, name
