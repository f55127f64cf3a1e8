"""What C and C++ libraries print, captured: libigl's readers, polyscope's EGL start-up.

They write to the process's file descriptors 1 and 2 (C stdio, ``std::cerr``), past
Python's ``sys.stdout`` / ``sys.stderr``.  :class:`CapturedOutput` redirects the two
descriptors into a temporary file for the duration of a ``with`` block and keeps the
first lines, so that the mesh readers can quote libigl's message in one-line errors
and the command line can keep a terminal free of polyscope's chatter.
"""
from __future__ import annotations

import os
import tempfile

__all__ = ["CapturedOutput", "flush_c_stdio"]

_READ_BYTES = 1 << 16
"""At most this many bytes of the captured output are read back."""


def flush_c_stdio():
    """Flush C stdio buffers (libigl's readers print with printf to a buffered stdout)."""
    try:
        import ctypes
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):  # no C runtime handle (e.g. Windows)
        pass


class CapturedOutput:
    """Context manager: redirect file descriptors 1 and 2 into a temporary file.

    Silences C/C++ libraries (libigl's readers, polyscope's EGL start-up)
    that print to the process's stdout/stderr; afterwards ``lines`` holds
    their first 20 non-empty lines, non-ASCII characters replaced by '?'.
    """

    def __enter__(self):
        import sys
        sys.stdout.flush()
        sys.stderr.flush()
        flush_c_stdio()
        self._tmp = tempfile.TemporaryFile()
        self._saved = [os.dup(1), os.dup(2)]
        os.dup2(self._tmp.fileno(), 1)
        os.dup2(self._tmp.fileno(), 2)
        return self

    def __exit__(self, *exc):
        flush_c_stdio()
        for fd, saved in zip((1, 2), self._saved):
            os.dup2(saved, fd)
            os.close(saved)
        self._tmp.seek(0)
        text = self._tmp.read(_READ_BYTES).decode("utf-8", "replace")
        self._tmp.close()
        lines = [" ".join("".join(c if " " <= c <= "~" else "?" for c in ln).split())
                 for ln in text.splitlines()[:20]]
        self.lines = [ln for ln in lines if ln]
        return False
