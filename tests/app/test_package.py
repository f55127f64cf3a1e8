"""Package-level contracts: lazy optional imports (the CLI is tested in test_cli.py)."""
import subprocess
import sys


def test_import_is_light():
    code = ("import sys, igl_hhj; import igl_hhj.regge, igl_hhj.biharmonic; "
            "print(any(m in sys.modules for m in ('polyscope', 'matplotlib', 'tqdm', 'triangle')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"



def test_dropin_path_does_not_load_scipys_blas():
    """The drop-in's usual path (PCG, QDLDL) never needs scipy.sparse.linalg: it is imported
    only by the pivoted-LU fallback, because loading it starts scipy's OpenBLAS threads,
    which spin for a while and slowed the first call after import (fandisk 1.5x)."""
    code = ("import sys; from igl_hhj import principal_curvature; "
            "from igl_hhj.surfaces import icosphere, Sphere, jitter_tangentially; "
            "v, f = icosphere(4); principal_curvature(jitter_tangentially(v, f, Sphere(), 0.45, seed=7), f); "
            "print('scipy.sparse.linalg' in sys.modules)")
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


def test_benchmark_progress_bars_stay_out_of_redirected_logs():
    """tqdm draws only on a terminal (disable=None): a log file gets no bar frames."""
    code = "from igl_hhj.benchmarks import progress\nfor _ in progress(range(50), 'x', 'it'): pass\n"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stderr == "" and out.stdout == ""


def test_extras_and_license():
    """A `demos` extra with what the demos import, an `all` extra, and the MPL-2.0 text."""
    import tomllib
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    extras = tomllib.loads((root / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    names = {e: {r.split(">")[0].split("[")[0].split("=")[0].strip() for r in reqs} for e, reqs in extras.items()}
    assert {"matplotlib", "triangle", "gpytoolbox"} <= names["demos"]
    assert any("demos" in r and "benchmark" in r for r in extras["all"])
    assert (root / "LICENSE").read_text().startswith("Mozilla Public License Version 2.0")


def test_a_plain_install_annotates_screenshots():
    """Issue 26 (1): ``pip install . && igl-hhj demo`` must draw the titles and colour bars,
    so matplotlib (and with it Pillow, for the palette PNGs) is a core dependency."""
    import tomllib
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    deps = tomllib.loads((root / "pyproject.toml").read_text())["project"]["dependencies"]
    assert "matplotlib" in {r.split(">")[0].split("[")[0].split("=")[0].strip() for r in deps}
