"""The ``igl-hhj`` command line (also ``python -m igl_hhj.cli``).

Commands
--------
``igl-hhj demo``
    HHJ vs libigl curvature errors on a jittered ellipsoid sequence, then a
    screenshot of the finest mesh (headless; skipped with a warning when EGL
    is missing).
``igl-hhj curvature MESH``
    principal curvatures and directions, mean and Gauss curvature of a mesh
    file, written to ``.npz``, ``.csv``, ``.ply``, ``.vtp``, ``.vtu``, ``.vtk`` or
    ``.obj``; optional polyscope view or screenshot.
``igl-hhj view RESULT``
    re-open a saved result (``curvature -o`` ``.npz``, ``.ply``, ``.vtp``, ``.vtu``,
    ``.vtk``) with its stored quantities in the viewer, or ``--screenshot PNG``.
``igl-hhj info MESH``
    what the mesh is made of, whether igl_hhj accepts it, and which repairs the
    drop-in ``principal_curvature`` would make to a refused one.
``igl-hhj batch INPUT... -o OUTDIR``
    ``curvature -o`` for many meshes on an embedded or existing Dask cluster
    (:mod:`igl_hhj.batch`); exit 1 when some meshes failed (rows in
    ``OUTDIR/summary.csv``).

Exit codes
----------
0 success; 1 ``info``: the file was read but igl_hhj rejects the mesh;
2 user error (a mesh igl_hhj rejects in ``curvature``, bad options, unwritable
output, viewer unavailable for ``--view`` / ``--screenshot``); 3 unreadable mesh
file (missing, unreadable, malformed, truncated); 4 the solver failed on an
accepted mesh; 5 out of memory; 70 internal error (a bug: please report it);
130 interrupted (Ctrl-C).  Every failure prints exactly one line
``igl-hhj: error: ...`` on stderr (warnings: ``igl-hhj: warning: ...``); no
traceback unless ``--debug`` is given.

Modules
-------
One per command: :mod:`.demo`, :mod:`.curvature`, :mod:`.batch`, :mod:`.view`,
:mod:`.info` (each its sub-parser and its function); :mod:`.program` (the parser,
failures as exit codes, :func:`main`); :mod:`._common` (what the commands share).
"""
from __future__ import annotations

import os
import signal
import sys


def _interrupted_at_startup(signum, frame):      # Ctrl-C while the imports below run
    sys.stderr.write("igl-hhj: interrupted\n")
    os._exit(130)


# Only when this package is the program: the ``igl-hhj`` console script, or
# ``python -m igl_hhj.cli`` (sys.argv[0] is "-m" while the package is imported, before
# __main__.py runs).  Not in batch workers: they inherit SIGINT ignored; each used to
# print "interrupted" too.
if (os.path.basename(sys.argv[0] if sys.argv else "") == "igl-hhj" or sys.argv[:1] == ["-m"]) \
        and signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
    try:
        signal.signal(signal.SIGINT, _interrupted_at_startup)
    except (ValueError, OSError):                # not the main thread
        pass

from ._common import (EGL_HINT, EXIT_INTERNAL, EXIT_INTERRUPTED, EXIT_MEMORY, EXIT_REJECTED,  # noqa: E402
                      EXIT_SOLVER, EXIT_UNREADABLE, EXIT_USAGE, UserError)
from .batch import batch_formats, batch_group_bytes  # noqa: E402
from .curvature import LARGE_MESH_FACES  # noqa: E402
from .program import build_parser, main  # noqa: E402

__all__ = ["main", "build_parser", "UserError", "EXIT_REJECTED", "EXIT_USAGE", "EXIT_UNREADABLE", "EXIT_SOLVER",
           "EXIT_MEMORY", "EXIT_INTERNAL", "EXIT_INTERRUPTED", "EGL_HINT", "LARGE_MESH_FACES", "batch_formats",
           "batch_group_bytes"]
