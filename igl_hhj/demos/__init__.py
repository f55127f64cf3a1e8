"""The demos, installed with the package: ``igl-hhj demo NAME [options]``.

From a source checkout the same demos run as ``python demos/NAME.py`` (thin
wrappers around these modules).  Each demo's ``--help`` says what the picture
shows and which numbers it prints.  Some need the ``demos`` extra
(``pip install ".[demos]"`` in a checkout: triangle, gpytoolbox); without it they
stop with that command and exit code 2.

=====================  ==========================================================
``quickstart``         a mesh file to a curvature picture and saved results, step by step
``compare_curvature``  HHJ beside ``igl.principal_curvature`` on a mesh file or a generated torus
``refinement``         ``|H_h - H|`` of HHJ, cotan and Heine P1 under refinement of re-jittered ellipsoids
``boundary_data``      open surfaces without boundary data, clamped, simply supported
``biharmonic``         mixed P1 biharmonic solution and its error, convergence rates
``regge``              Regge Gauss curvature K_h beside HHJ's and the exact K, Gauss–Bonnet
``curved``             HHJ on curved triangles of order m = 1, 2, 3 (Walker's torus / genus 3)
``features``           fandisk: libigl, HHJ without and with crease handling, the crease network
=====================  ==========================================================
"""
from __future__ import annotations

import importlib
from typing import Sequence

DEMOS = ("quickstart", "compare_curvature", "refinement", "boundary_data", "biharmonic", "regge",
         "curved", "features")
"""Names accepted by :func:`run` and ``igl-hhj demo NAME``."""


def summary(name: str) -> str:
    """First line of the demo's docstring."""
    return (importlib.import_module(f".{name}", __name__).__doc__ or "").strip().splitlines()[0]


def run(name: str, argv: Sequence[str] | None = None, prog: str | None = None) -> int:
    """Run demo ``name`` with command-line arguments ``argv``; returns the exit code.

    Examples
    --------
    >>> from igl_hhj import demos
    >>> demos.run("regge", ["--levels", "2", "--screenshot", "regge.png"])  # doctest: +SKIP
    0
    """
    if name not in DEMOS:
        raise ValueError(f"unknown demo {name!r}; choose one of {', '.join(DEMOS)}")
    from ..errors import install_hint, missing_optional
    module = importlib.import_module(f".{name}", __name__)
    prog = prog or f"igl-hhj demo {name}"
    try:
        module.main(list(argv or []), prog=prog)
    except SystemExit as exc:           # argparse --help / errors, _common.fail
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    except ModuleNotFoundError as exc:  # an optional package the demo needs (the demos extra)
        package = missing_optional(exc)
        if package is None:
            raise
        import sys
        print(f"{prog}: error: this demo needs the '{package}' package: {install_hint(package)}",
              file=sys.stderr)
        return 2
    return 0
