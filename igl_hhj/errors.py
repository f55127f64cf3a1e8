"""The library's documented exception types.

Every failure igl_hhj reports on purpose is one of Python's ``TypeError`` /
``ValueError`` (bad input, named in the message) or one of the classes below.

* :class:`SolverError` (a ``RuntimeError``): a linear solve could not produce a
  finite answer for an accepted mesh.  ``faces`` lists the faces responsible
  when they are known (e.g. near-degenerate triangles), else it is empty.
* :class:`SolverDidNotConverge` (a :class:`SolverError`): an iterative solve
  stopped at its iteration cap above its tolerance.
* :class:`MeshFileError` (a ``ValueError``): a mesh or output file that cannot be
  used (:mod:`igl_hhj.mesh_io`, :mod:`igl_hhj.polygon_io`), one line naming the file
  and the problem.

A missing optional package is an ``ImportError``; :func:`install_hint` says
how to install it (the command line and the demos print it).
"""
from __future__ import annotations

import numpy as np

__all__ = ["SolverError", "SolverDidNotConverge", "MeshFileError", "OPTIONAL_PACKAGES", "install_hint", "missing_optional"]

OPTIONAL_PACKAGES = {
    "matplotlib": ("matplotlib", "demos"),
    "triangle": ("triangle", "demos"),
    "gpytoolbox": ("gpytoolbox", "demos"),
    "meshio": ("meshio", "io"),
    "dask": ("dask[distributed]", "distributed"),
    "distributed": ("dask[distributed]", "distributed"),
    "pyarrow": ("pyarrow", "test"),
    "trimesh": ("trimesh", "io"),
    "pyvista": ("pyvista", "io"),
    "lxml": ("lxml", "io"),
    "networkx": ("networkx", "io"),
    "tqdm": ("tqdm", "benchmark"),
    "pymeshlab": ("pymeshlab", "benchmark"),
}
"""Import name -> (what ``pip install`` takes, the extra of igl-hhj's pyproject.toml that
brings it) of the optional packages some features use."""


def install_hint(package: str) -> str:
    """The install commands for optional ``package`` (an import name), e.g.
    ``pip install gpytoolbox (in a checkout of igl-hhj: pip install ".[demos]")``.

    Both commands work as printed: the extra is named by the checkout's path ``.``,
    not by the project name (which pip would look up on the package index).
    """
    top = str(package).split(".")[0]
    pip_name, extra = OPTIONAL_PACKAGES.get(top, (top, None))
    quoted = f'"{pip_name}"' if "[" in pip_name else pip_name
    return f'pip install {quoted}' + (f' (in a checkout of igl-hhj: pip install ".[{extra}]")' if extra else "")


def missing_optional(exc: BaseException) -> str | None:
    """The top-level name of the optional package whose absence raised ``exc``
    (a ``ModuleNotFoundError``), or None for anything else (e.g. a missing module
    of igl_hhj itself, which is a bug)."""
    name = getattr(exc, "name", None) if isinstance(exc, ModuleNotFoundError) else None
    top = str(name).split(".")[0] if name else None
    return top if top in OPTIONAL_PACKAGES else None


class SolverError(RuntimeError):
    """A linear solve failed on an accepted mesh.

    Parameters
    ----------
    message : str
        What failed, naming the face(s) responsible when known and the fix.
    faces : array_like of int, optional
        Indices of the faces responsible (empty when unknown).
    """

    def __init__(self, message, faces=()):
        super().__init__(message)
        self.faces = np.asarray(faces, dtype=np.int64).ravel()


class SolverDidNotConverge(SolverError):
    """An iterative solve stopped at its iteration cap above its tolerance."""


class MeshFileError(ValueError):
    """A mesh or output file the command line cannot use (message: one line)."""
