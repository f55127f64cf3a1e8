"""The public API is annotated and type-checks (issue 14): mypy on the modules listed
in pyproject's [tool.mypy] (mypy is in the test extra; first run about a minute)."""
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_mypy_on_the_public_modules():
    pytest.importorskip("mypy")
    res = subprocess.run([sys.executable, "-m", "mypy", "--no-error-summary"], cwd=ROOT, capture_output=True,
                         text=True, timeout=600)
    assert res.returncode == 0, res.stdout[-4000:] + res.stderr[-2000:]


def test_public_functions_are_annotated():
    import inspect

    import igl_hhj
    from igl_hhj import convergence, interop, mesh_io, viewer
    functions = [igl_hhj.shape_operator, igl_hhj.surface_hessian, igl_hhj.principal_curvature,
                 igl_hhj.face_principal_curvature, igl_hhj.face_mean_curvature, igl_hhj.face_gaussian_curvature,
                 convergence.eoc, convergence.plot_convergence, mesh_io.write_curvature,
                 interop.mesh_arrays, interop.to_trimesh, interop.to_pyvista, interop.to_meshio,
                 viewer.register_curvature, viewer.register_comparison, viewer.register_scalars,
                 viewer.screenshot, viewer.view_rotation, viewer.best_view_direction]
    for fn in functions:
        sig = inspect.signature(fn)
        assert sig.return_annotation is not inspect.Signature.empty, fn.__qualname__
