"""The library's documented exception types.

Every failure igl_hhj reports on purpose is one of Python's ``TypeError`` /
``ValueError`` (bad input, named in the message) or one of the classes below.

* :class:`SolverError` (a ``RuntimeError``): a linear solve could not produce a
  finite answer for an accepted mesh.  ``faces`` lists the faces responsible
  when they are known (e.g. near-degenerate triangles), else it is empty.
* :class:`SolverDidNotConverge` (a :class:`SolverError`): an iterative solve
  stopped at its iteration cap above its tolerance.
"""
from __future__ import annotations

import numpy as np

__all__ = ["SolverError", "SolverDidNotConverge"]


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
