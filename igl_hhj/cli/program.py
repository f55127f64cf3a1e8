"""The ``igl-hhj`` program: its parser (one sub-command per module of this package),
failures turned into one line and an exit code, and :func:`main`."""
from __future__ import annotations

import signal
import sys
import warnings

import numpy as np

from . import batch, curvature, demo, info, view
from ._common import EXIT_INTERRUPTED, EXIT_INTERNAL, EXIT_MEMORY, EXIT_SOLVER, EXIT_USAGE, UserError, _Parser


def _version():
    from importlib import metadata

    from .. import __version__
    try:
        libigl = metadata.version("libigl")
    except metadata.PackageNotFoundError:  # pragma: no cover - libigl is a dependency
        libigl = "not installed"
    return f"igl-hhj {__version__} (libigl {libigl})"


def build_parser():
    parser = _Parser(prog="igl-hhj",
                     description="igl_hhj: convergent finite-element (HHJ) curvature of triangle meshes.",
                     epilog="exit codes: 0 ok, 1 info: mesh rejected, 2 user error, 3 unreadable "
                            "mesh file, 4 solver failure, 5 out of memory, 70 internal error, "
                            "130 interrupted, 141 output pipe closed (e.g. | head)")
    parser.add_argument("--debug", action="store_true",
                        help="show the Python traceback of a failure (anywhere on the command line)")
    parser.add_argument("--version", action="version", version=_version(),
                        help="print the versions of igl-hhj and libigl and exit")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for command in (demo, curvature, batch, view, info):
        command.add_parser(sub)
    return parser


def _one_line(text):
    """Collapse a message to one line (C++/numpy messages may span several)."""
    return " ".join(str(text).split()) or "(no message)"


_WARNED: set[str] = set()


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """Warnings as ``igl-hhj: warning: ...`` lines, each message once per run."""
    text = _one_line(message)
    if text not in _WARNED:
        _WARNED.add(text)
        print(f"igl-hhj: warning: {text}", file=sys.stderr, flush=True)


def _failure(exc):
    """(exit code, one-line message) for an exception that ended a command."""
    from ..errors import SolverError
    if isinstance(exc, UserError):
        return exc.code, _one_line(exc)
    if isinstance(exc, MemoryError) or (isinstance(exc, ImportError) and any(
            m in str(exc) for m in ("failed to map segment", "annot allocate memory"))):
        return EXIT_MEMORY, ("out of memory" + (f" ({_one_line(exc)})" if str(exc) else "")
                             + ": the computation needs more memory than this process may use; "
                               "try a smaller mesh or raise the memory limit")
    from ..errors import install_hint, missing_optional
    package = missing_optional(exc)
    if package is not None:
        if "pip install" in str(exc):                 # the message already says what needs it (mesh_io)
            return EXIT_USAGE, _one_line(exc)
        return EXIT_USAGE, f"this needs the optional '{package}' package: {install_hint(package)}"
    if isinstance(exc, (SolverError, np.linalg.LinAlgError)):
        return EXIT_SOLVER, (f"the solver failed: {_one_line(exc)} (check the mesh with "
                             f"'igl-hhj info'; rerun with --debug for the traceback)")
    if isinstance(exc, RuntimeError):
        return EXIT_SOLVER, (f"computation failed: {_one_line(exc)} (rerun with --debug for "
                             f"the traceback)")
    if isinstance(exc, OSError):
        return EXIT_USAGE, _one_line(f"{exc.filename + ': ' if exc.filename else ''}"
                                     f"{exc.strerror or exc}")
    return EXIT_INTERNAL, (f"internal error: {type(exc).__name__}: {_one_line(exc)} (please "
                           f"report it; rerun with --debug for the traceback)")


EXIT_BROKEN_PIPE = 128 + 13
"""The reader of stdout went away (``igl-hhj info m.off | head -3``): no message, the exit
status of a process ended by SIGPIPE, as the Unix tools."""


def _stdout_closed():
    """Quiet end after a broken pipe: stdout points to /dev/null from here on, so the
    interpreter's final flush cannot fail again (it would print 'Exception ignored')."""
    import os
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):   # no real stdout (captured): nothing to redirect
        pass
    return EXIT_BROKEN_PIPE


_SIGINT_SEEN = [False]


def _on_sigint(signum, frame):
    _SIGINT_SEEN[0] = True
    raise KeyboardInterrupt


def _import_deferring_sigint(name):
    """Import a C++ extension with Ctrl-C deferred to the end of the import: a
    KeyboardInterrupt inside pybind11 module initialisation aborts the process
    (``terminate called after throwing pybind11::error_already_set``)."""
    import importlib
    pending = []

    def defer(signum, frame):
        pending.append(signum)
        _SIGINT_SEEN[0] = True

    try:
        previous = signal.signal(signal.SIGINT, defer)
    except (ValueError, OSError):
        previous = None
    try:
        importlib.import_module(name)
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    if pending:
        raise KeyboardInterrupt


def main(argv=None):
    """Run the command line; returns the exit code (``sys.exit(main())``).

    Every exception ends as one ``igl-hhj: error: ...`` line and an exit code
    (module docstring); ``--debug`` anywhere on the command line re-raises
    failures other than user errors, with their traceback.
    """
    _SIGINT_SEEN[0] = False
    try:
        signal.signal(signal.SIGINT, _on_sigint)          # KeyboardInterrupt from here on
    except (ValueError, OSError):
        pass
    try:
        argv = list(sys.argv[1:] if argv is None else argv)
        debug = "--debug" in argv
        argv = [a for a in argv if a != "--debug"]
        _WARNED.clear()
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning
            try:
                named = demo._named_demo(argv)
                if named is not None:
                    return named
                args = build_parser().parse_args(argv)
                _import_deferring_sigint("igl")
                return args.func(args)
            except SystemExit as exc:                    # --help
                return exc.code if isinstance(exc.code, int) else 0
            except KeyboardInterrupt:
                raise
            except BrokenPipeError:
                return _stdout_closed()
            except Exception as exc:
                if _SIGINT_SEEN[0]:            # e.g. pybind11 turned the interrupt into ImportError
                    raise KeyboardInterrupt from exc
                if debug and not isinstance(exc, UserError):
                    raise
                code, message = _failure(exc)
                print(f"igl-hhj: error: {message}", file=sys.stderr)
                return code
    except KeyboardInterrupt:
        print("igl-hhj: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
