"""Shared plumbing of the demos: command line, mesh loading, tables, rendering.

Used by the modules of :mod:`igl_hhj.demos` only (not public API).
"""
from __future__ import annotations

import argparse
import sys

import numpy as np


_PROG = [None]   # program name in messages: set by parser() (``igl-hhj demo NAME`` or the script's name)


def parser(doc, *, levels=None, size=(1600, 800), prog=None):
    """argparse parser with the demo docstring as description, ``--screenshot``,
    ``--size`` and (if ``levels`` is given) ``--levels``; ``prog`` names the
    program in usage and error lines (default: the running script's name)."""
    _PROG[0] = prog
    p = argparse.ArgumentParser(prog=prog, description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--screenshot", metavar="PNG",
                   help="render headless (EGL) to this PNG and exit instead of opening the viewer")
    p.add_argument("--size", nargs=2, type=int, default=list(size), metavar=("W", "H"),
                   help=f"screenshot size in pixels (default {size[0]} {size[1]})")
    if levels is not None:
        p.add_argument("--levels", type=int, default=levels,
                       help=f"number of refinement levels (default {levels}; 2 is fast)")
    return p


def fail(message, code=2):
    """One-line error on stderr and exit (no traceback for user errors)."""
    prog = _PROG[0] or (sys.argv[0].rsplit("/", 1)[-1] if sys.argv and sys.argv[0] else "demo")
    print(f"{prog}: error: {message}", file=sys.stderr)
    raise SystemExit(code)


def check_levels(levels, minimum=2, maximum=7):
    if not (minimum <= levels <= maximum):
        fail(f"--levels must be between {minimum} and {maximum}, got {levels}")
    return levels


def read_mesh(path):
    """(V, F) of any file ``igl.read_triangle_mesh`` reads, through the guarded
    reader :func:`igl_hhj.mesh_io.read_mesh`, validated; exits with a one-line
    message (code 2) if the file is missing, unreadable or not a valid mesh."""
    from igl_hhj.mesh import as_mesh
    from igl_hhj.mesh_io import MeshFileError
    from igl_hhj.mesh_io import read_mesh as guarded_read
    try:
        V, F, _ = guarded_read(path)
        mesh = as_mesh(V, F)
    except (MeshFileError, TypeError, ValueError) as exc:
        fail(f"{path}: {str(exc).splitlines()[0]}" if str(path) not in str(exc) else str(exc).splitlines()[0])
    return mesh.V, mesh.F


# --------------------------------------------------------------------------- tables
def eocs(values, hs):
    """EOCs between successive levels (first entry NaN), as a list."""
    from igl_hhj.convergence import eoc
    if len(values) < 2:
        return [np.nan] * len(values)
    with np.errstate(divide="ignore", invalid="ignore"):
        return [np.nan] + list(eoc(values, hs))


def fmt(x):
    if x is None or (isinstance(x, (float, np.floating)) and not np.isfinite(x)):
        return "-"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    if isinstance(x, str):
        return x
    return f"{x:.3g}" if 1e-3 <= abs(x) < 1e4 or x == 0 else f"{x:.2e}"


def print_table(title, header, rows):
    """Plain-text table on stdout (markdown-compatible)."""
    cells = [[str(h) for h in header]] + [[fmt(c) for c in r] for r in rows]
    w = [max(len(r[i]) for r in cells) for i in range(len(header))]
    print(f"\n{title}")
    line = lambda r: "| " + " | ".join(c.rjust(w[i]) for i, c in enumerate(r)) + " |"  # noqa: E731
    print(line(cells[0]))
    print("|" + "|".join("-" * (x + 2) for x in w) + "|")
    for r in cells[1:]:
        print(line(r))
    sys.stdout.flush()


def print_eoc_table(title, rows, series):
    """Table of errors per refinement level with their EOCs.

    rows : list of dicts with "faces" and "h" (longest edge), one per level.
    series : list of (label, [error per level]).
    """
    hs = [r["h"] for r in rows]
    rates = [eocs(values, hs) for _, values in series]
    header = ["level", "faces", "h"] + [x for label, _ in series for x in (label, "EOC")]
    body = [[k, r["faces"], r["h"]] + [x for (_, values), e in zip(series, rates) for x in (values[k], e[k])]
            for k, r in enumerate(rows)]
    print_table(title, header, body)


# --------------------------------------------------------------------------- viewer
def start_viewer(args):
    """The viewer module, with polyscope started for headless rendering
    (``--screenshot``) or for an interactive window."""
    from igl_hhj import viewer
    from igl_hhj.capture import CapturedOutput
    try:
        with CapturedOutput():          # polyscope's EGL start-up chatter
            ps = viewer.init("openGL3_egl" if args.screenshot else "auto")
    except viewer.ViewerUnavailable as exc:
        hint = "" if args.screenshot else " (no display? use --screenshot out.png for headless rendering)"
        fail(f"{exc}{hint}".splitlines()[0], code=1)
    # copies laid side by side must be seen from the same direction: no perspective
    ps.set_view_projection_mode("orthographic")
    return viewer


def finish(viewer, args, registrations):
    """Write the screenshot of ``registrations`` or open the interactive viewer."""
    if args.screenshot:
        try:
            viewer.screenshot(args.screenshot, list(registrations), size=tuple(args.size))
        except (ValueError, viewer.ViewerUnavailable) as exc:
            fail(str(exc).splitlines()[0], code=1)
        print(f"\nwrote {args.screenshot} ({args.size[0]} x {args.size[1]})")
    else:
        try:
            viewer.show()
        except viewer.ViewerUnavailable as exc:
            fail(f"{str(exc).splitlines()[0]} (use --screenshot out.png for headless rendering)", code=1)


def register_field(viewer, V, F, label, values, vrange, *, name, offset=None, cmap="viridis", title=None):
    """One structure carrying one scalar field coloured on the given range ``vrange``
    (several of them laid side by side share one range and one colour bar);
    ``title`` is drawn above it in screenshots."""
    return viewer.register_scalars(V, F, {label: values}, name=name, offset=offset, cmap=cmap,
                                   vminmax=tuple(vrange), title=title)


def error_range(*arrays, robust=1.0):
    """(0, hi): one colour range for non-negative error fields, ``hi`` the
    ``100 - robust`` percentile of all values together."""
    from igl_hhj import viewer
    _, hi = viewer.color_range(*arrays, symmetric=False, robust=robust)
    return 0.0, max(hi, 1e-300)


def rotation(spin=0.0, tilt=-60.0):
    """(3, 3) rotation by ``spin`` degrees about z, then ``tilt`` degrees about x:
    applied to a surface around the z axis (``V @ R.T``) it is seen obliquely
    from above by polyscope's default camera (looking down -z, y up)."""
    c, s = np.cos(np.radians(spin)), np.sin(np.radians(spin))
    Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    c, s = np.cos(np.radians(tilt)), np.sin(np.radians(tilt))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]) @ Rz


def grid_offsets(V, n_cols, n_rows, gap=0.15):
    """Translations laying out copies of a mesh in a grid (columns along x, rows along -y
    in a plane facing the default camera)."""
    ext = V.max(axis=0) - V.min(axis=0)
    dx, dy = (1 + gap) * ext[0], (1 + gap) * ext[1]
    return [[np.array([c * dx, -r * dy, 0.0]) for c in range(n_cols)] for r in range(n_rows)]
