"""The README is the first ten minutes (issue 26): it starts with the two set-up
commands CI runs, stays short, its Python runs as written (issue 14: every ```python
block, in order, in one namespace, in a fresh folder holding the README's ``bunny.off``,
copied from shared/data/meshes; the viewer on polyscope's mock backend with
``viewer.show`` a no-op), its links resolve, and its command table and install facts
agree with the ``igl-hhj`` parser and pyproject.toml.  The code and numbers that moved
to the Sphinx pages are checked there (tests/app/test_docs.py)."""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from conftest import MESH_DIR

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")

#: the two set-up commands; .ci/run executes line 2 of the first ```bash block
SETUP = ["python3 -m venv .venv && . .venv/bin/activate && pip install . && igl-hhj demo",
         'python3 -m venv .venv && . .venv/bin/activate && pip install ".[test]" && python -m pytest -q']
VIEWER_HARNESS = ("from igl_hhj import viewer\n"
                  "viewer.init('openGL_mock')\n"
                  "viewer.show = lambda *a, **k: None\n")


def python_blocks(text=README):
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


def run_blocks(blocks, folder, label):
    """Run ``blocks`` in order as one script in ``folder`` (holding bunny.off)."""
    script = VIEWER_HARNESS + "\n".join(f"# --- {label} block {i}\n{b}" for i, b in enumerate(blocks))
    (folder / "blocks.py").write_text(script)
    res = subprocess.run([sys.executable, "blocks.py"], cwd=folder, capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    return res


def bunny_folder(tmp_path):
    bunny = MESH_DIR / "bunny.off"
    if not bunny.exists():
        pytest.skip(f"{bunny} absent")
    shutil.copy(bunny, tmp_path / "bunny.off")
    return tmp_path


def test_readme_starts_with_the_setup_commands():
    lines = README.splitlines()
    assert lines[0].startswith("# igl_hhj")
    assert lines[1] == "" and lines[2] == "```bash" and lines[5] == "```", lines[:6]
    assert lines[3:5] == SETUP
    # what .ci/run extracts
    first = re.search(r"^```bash\n(.*?)^```", README, flags=re.S | re.M).group(1).splitlines()
    assert first[1] == SETUP[1]


def test_readme_is_short_and_has_the_newcomer_sections():
    assert len(README.splitlines()) <= 250
    heads = re.findall(r"^## (.+)$", README, flags=re.M)
    for want in ("What it is", "Installing", "Quick start", "Command line", "Which file for which tool",
                 "Which estimator when", "Documentation"):
        assert any(h.startswith(want) for h in heads), (want, heads)
    assert "](demos/images/demo_cli.png)" in README


def test_readme_has_python_blocks():
    blocks = python_blocks()
    assert len(blocks) >= 1
    quick = blocks[0]
    # read -> curvature -> save -> view, in at most 5 lines
    assert len(quick.strip().splitlines()) <= 5
    for step in ("read_mesh", "hhj_vertex", "write_curvature", "viewer."):
        assert step in quick, step
    assert "igl_hhj.principal_curvature" in quick


def test_readme_python_runs_as_written(tmp_path):
    folder = bunny_folder(tmp_path)
    run_blocks(python_blocks(), folder, "README")
    assert (folder / "bunny_curvature.ply").stat().st_size > 0


def test_readme_links_resolve():
    links = re.findall(r"\]\(([^)\s]+)\)", README)
    local = [u for u in links if not re.match(r"[a-z]+://", u)]
    assert len(local) >= 10, local
    for url in local:
        assert (ROOT / url.split("#")[0]).exists(), url
    # every docs page is linked from the README
    for page in (ROOT / "igl_hhj" / "docs").glob("*.*"):
        if page.suffix in (".md", ".rst") and page.stem != "index":
            assert f"](igl_hhj/docs/{page.name})" in README, page.name


def test_readme_command_table_matches_the_cli():
    from igl_hhj import cli
    from igl_hhj.demos import DEMOS
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    section = README.split("## Command line", 1)[1].split("\n## ", 1)[0]
    listed = set(re.findall(r"^\| `igl-hhj (\w+)", section, flags=re.M))
    assert listed == set(sub.choices), (listed, set(sub.choices))
    assert "`igl-hhj --version`" in section
    for name in DEMOS:
        assert f"`{name}`" in section, name
    for code in ("0 ok", "2 user error", "3 unreadable mesh file", "4 solver failure", "5 out of memory",
                 "70 internal", "130 interrupted"):
        assert code in " ".join(section.split()), code


def test_readme_install_facts_match_pyproject():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    py = meta["project"]["requires-python"]          # ">=3.10"
    cmake = meta["tool"]["scikit-build"]["cmake"]["version"]    # ">=3.18"
    section = " ".join(README.split("## Installing", 1)[1].split("\n## ", 1)[0].split())
    assert f"Python ≥ {py.lstrip('>=')}" in section
    assert f"cmake ≥ {cmake.lstrip('>=')}" in section
    assert "C++17" in section and "Linux x86_64" in section
    for extra in meta["project"]["optional-dependencies"]:
        assert f'".[{extra}]"' in section, extra
