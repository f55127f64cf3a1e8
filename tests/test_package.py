"""Package-level contracts: lazy optional imports (the CLI is tested in test_cli.py)."""
import subprocess
import sys


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
