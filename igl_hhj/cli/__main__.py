"""``python -m igl_hhj.cli``: the ``igl-hhj`` command."""
import os
import sys

from . import EXIT_INTERRUPTED, main

if __name__ == "__main__":
    _code = main()
    if _code == EXIT_INTERRUPTED:
        # CPython remembers a KeyboardInterrupt raised inside C-level PyRun_* calls
        # (library imports) even when it was handled, and `python -m` then ends
        # with a re-raised SIGINT (-2) instead of our exit code: leave directly.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_code)
    sys.exit(_code)
