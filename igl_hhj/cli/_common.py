"""What every command of the ``igl-hhj`` program shares: exit codes, one-line user
errors, the guarded read of a mesh file, output checks, progress lines, the viewer
imported on demand with polyscope's start-up chatter captured."""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from ..capture import CapturedOutput


EXIT_REJECTED, EXIT_USAGE, EXIT_UNREADABLE, EXIT_SOLVER, EXIT_MEMORY = 1, 2, 3, 4, 5
EXIT_INTERNAL, EXIT_INTERRUPTED = 70, 130
EGL_HINT = ("headless rendering needs EGL; on Debian/Ubuntu: "
            "apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri")


class UserError(Exception):
    """A problem with the user's input: printed as one line, exit code ``code``."""

    def __init__(self, message, code=2):
        super().__init__(message)
        self.code = code


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (argparse prints usage + error = two lines)."""

    def error(self, message):
        raise UserError(f"{message} (see '{self.prog} --help')")


class _Stages:
    """``[i/n] label ... t s`` lines on stderr, only when enabled (large meshes)."""

    def __init__(self, total, enabled):
        self.total, self.enabled, self.i = total, enabled, 0

    def done(self, label, seconds):
        """Report a stage that has already finished."""
        self.i += 1
        if self.enabled:
            print(f"[{self.i}/{self.total}] {label} ... {seconds:.1f} s", file=sys.stderr, flush=True)

    def run(self, label, fn, *args, **kwargs):
        self.i += 1
        if self.enabled:
            print(f"[{self.i}/{self.total}] {label} ...", end=" ", file=sys.stderr, flush=True)
        t = time.perf_counter()
        out = fn(*args, **kwargs)
        if self.enabled:
            print(f"{time.perf_counter() - t:.1f} s", file=sys.stderr, flush=True)
        return out


def _read(path):
    """Guarded read (:func:`igl_hhj.mesh_io.read_mesh_file`); the reader's warnings become
    one warning line.  Polygons split into triangles are not a warning: the callers say so."""
    from ..mesh_io import MeshFileError, read_mesh_file
    try:
        mf = read_mesh_file(path)
    except MeshFileError as exc:
        raise UserError(str(exc), EXIT_UNREADABLE) from None
    messages = mf.messages
    if messages:
        more = f" (+{len(messages) - 2} more)" if len(messages) > 2 else ""
        print(f"igl-hhj: warning: {path}: " + "; ".join(messages[:2]) + more, file=sys.stderr)
    return mf


def _check_writable(path, extensions=None):
    from ..mesh_io import MeshFileError, check_output_path, probe_writable
    try:
        if extensions is None:
            check_output_path(path)
        else:
            if Path(path).suffix.lower() not in extensions:
                raise MeshFileError(f"{path}: unknown image extension {Path(path).suffix!r} "
                                    f"(use {', '.join(extensions)})")
            probe_writable(path)
    except MeshFileError as exc:
        raise UserError(str(exc)) from None


def _say(args):
    """``print`` for the summary lines, or a no-op with ``-q``."""
    return (lambda *a, **k: None) if getattr(args, "quiet", False) else print


def _viewer():
    from .. import viewer
    return viewer


def _quietly(fn, *args, **kwargs):
    """Call ``fn`` with file descriptors 1/2 captured (polyscope's EGL start-up chatter).

    Python warnings raised meanwhile are held back and shown once the descriptors
    are restored (they used to be written into the capture and lost).
    """
    caught: list = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            with CapturedOutput():
                return fn(*args, **kwargs)
    finally:
        for w in caught:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)


def _with_hint(exc):
    """The viewer's message, with the EGL package hint unless it already has one."""
    msg = _first_line(exc)
    return msg if "libegl1" in msg else f"{msg}; {EGL_HINT}"


def _first_line(exc):
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def _camera(text):
    """``--camera`` value: a name of :data:`igl_hhj.viewer.VIEWS` or ``X,Y,Z``."""
    names = ("auto", "+x", "-x", "+y", "-y", "+z", "-z")
    if text in names:
        return text
    try:
        d = [float(x) for x in text.split(",")]
    except ValueError:
        d = []
    if len(d) != 3 or not np.all(np.isfinite(d)) or not np.any(d):
        raise argparse.ArgumentTypeError(f"expected one of {', '.join(names)} or a nonzero direction X,Y,Z, "
                                         f"got {text!r}")
    return tuple(d)
