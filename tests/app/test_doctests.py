"""The Examples sections of the public docstrings run (issue 14); rendering examples
are marked +SKIP (they need EGL and write files)."""
import doctest
import importlib
import pkgutil

import pytest

PACKAGES = ["igl_hhj.viewer", "igl_hhj.mesh_io"]
"""Packages whose every module's docstrings run (doctest.testmod sees only the objects a
module defines, not those its package re-exports)."""
MODULES = ["igl_hhj.curvature", "igl_hhj.convergence", "igl_hhj.interop", "igl_hhj.demos", "igl_hhj.repair",
           "igl_hhj.features", "igl_hhj.curved.hessian"]
MODULES += [m for p in PACKAGES
            for m in [p] + [f"{p}.{i.name}" for i in pkgutil.iter_modules(importlib.import_module(p).__path__)]]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    if name == "igl_hhj.convergence":
        import matplotlib
        matplotlib.use("Agg")
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0


def test_the_main_functions_have_examples():
    import igl_hhj
    from igl_hhj import convergence, viewer
    for fn in (igl_hhj.shape_operator, igl_hhj.principal_curvature, igl_hhj.surface_hessian,
               igl_hhj.face_principal_curvature, convergence.plot_convergence, viewer.register_curvature,
               viewer.register_comparison, viewer.best_view_direction):
        assert "Examples\n    --------\n    >>>" in fn.__doc__, fn.__qualname__
