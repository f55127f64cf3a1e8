"""HHJ mean curvature converges under refinement; the cotangent formula and Heine's P1 map do not.

    igl-hhj demo refinement                          # 5 levels, interactive
    igl-hhj demo refinement --screenshot out.png     # headless (EGL)
    igl-hhj demo refinement --levels 3 --plot conv.png

The surface is Heine's ellipsoid (5.1c) x² + (2y)² + (2z/3)² = 1, meshed by a
perturbed icosahedron refined uniformly; every level is then RE-JITTERED: its
vertices move tangentially by up to 30 % of the local edge length (seeded) and
are put back on the surface, so no regular structure survives refinement.

What you see: a grid of copies of the ellipsoid (long axis horizontal).
Columns are the refinement levels, coarse (left) to fine (right); rows are the
methods: top = HHJ (igl_hhj.face_mean_curvature, one value per face),
middle = libigl's cotangent mean curvature (per vertex), bottom = Heine's P1
Weingarten map (per vertex).  The colour is the pointwise error
|H_h - H| (viridis, ONE range for all copies: dark purple = 0, yellow = the
95th percentile of all errors or more).  The HHJ row turns uniformly dark
from left to right (the error halves with every level); the cotangent row
stops darkening after the third level and keeps a speckle of green vertices;
the Heine row keeps green and yellow patches at every level.

Printed: the relative L2 error of H per level for the three methods and its
EOC (experimental order of convergence, log(e_k/e_k+1) / log(h_k/h_k+1)):
about 1 for HHJ, about 0 for the cotangent formula on the finer levels and for
Heine's map throughout.
"""
from __future__ import annotations

import numpy as np

from . import _common

METHODS = (("HHJ faces", "hhj_face"), ("cotan", "libigl_cotan"), ("Heine P1", "heine"))


def levels_sequence(n_levels, jitter=0.3, seed=100):
    """[(V, F)] re-jittered levels of Heine's ellipsoid (5.1c), and the surface."""
    from igl_hhj.surfaces.heine import heine_sequence
    return heine_sequence("5.1c", n_levels, pre_refine=0, jitter=jitter, seed=seed)


def pointwise_error(mesh, est, surface):
    """|H_h - H| per face (at the projected centroid) or per vertex."""
    if est.location == "face":
        X = surface.project(mesh.V[mesh.F].mean(axis=1))
    else:
        X = mesh.V
    return np.abs(est.H - surface.mean_curvature(X))


def measure(levels, surface):
    """Per level: mesh, estimates, relative L2 errors (compare_estimators' norms)."""
    from igl_hhj.baselines import ESTIMATORS
    from igl_hhj.benchmarks.compare_estimators import errors
    from igl_hhj.mesh import as_mesh
    rows = []
    for V, F in levels:
        mesh = as_mesh(V, F)
        row = {"mesh": mesh, "h": mesh.max_edge_length, "faces": mesh.n_faces, "err": {}, "field": {}}
        for label, key in METHODS:
            est = ESTIMATORS[key](mesh.V, mesh.F)
            row["err"][label] = errors(mesh, est, surface)["H"]
            row["field"][label] = pointwise_error(mesh, est, surface)
        rows.append(row)
    return rows


def table(rows):
    _common.print_eoc_table("Relative L2 error of the mean curvature H on re-jittered ellipsoid meshes", rows,
                            [(f"{lab} rel. L2(H)", [r["err"][lab] for r in rows]) for lab, _ in METHODS])


def plot(rows, path):
    try:
        from igl_hhj.convergence import plot_convergence
        plot_convergence([r["h"] for r in rows], [[r["err"][lab] for r in rows] for lab, _ in METHODS],
                         [lab for lab, _ in METHODS], ylabel="relative L2 error of H", eoc_labels=True,
                         title="re-jittered ellipsoid meshes", path=path)
    except ImportError as exc:
        from igl_hhj.errors import install_hint
        _common.fail(f"--plot needs matplotlib: {install_hint('matplotlib')} ({exc})")
    print(f"wrote {path}")


# display: long axis (z) horizontal, middle axis (x) vertical, thin axis (y) towards the camera
ROBUST = 5.0  # colour range: 0 to the 95th percentile of all pointwise errors
DISPLAY = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def show(rows, args):
    viewer = _common.start_viewer(args)
    vrange = _common.error_range(*(r["field"][lab] for r in rows for lab, _ in METHODS), robust=ROBUST)
    offsets = _common.grid_offsets(rows[-1]["mesh"].V @ DISPLAY.T, len(rows), len(METHODS))
    regs = []
    for i, (lab, _) in enumerate(METHODS):
        for k, r in enumerate(rows):
            regs.append(_common.register_field(viewer, r["mesh"].V @ DISPLAY.T, r["mesh"].F, "|H_h - H|",
                                               r["field"][lab], vrange, name=f"{lab} level {k}",
                                               offset=offsets[i][k],
                                               title=f"{lab}, level {k}: {r['faces']:,} faces"))
    print(f"colour range of |H_h - H| (all copies): [0, {vrange[1]:.3g}] ({100 - ROBUST:g}th percentile)")
    _common.finish(viewer, args, regs)


def main(argv=None, prog=None):
    p = _common.parser(__doc__, prog=prog, levels=5, size=(1600, 800))
    p.add_argument("--plot", metavar="PNG", help="also write a matplotlib log-log convergence plot")
    args = p.parse_args(argv)
    n = _common.check_levels(args.levels, 2, 7)
    levels, surface = levels_sequence(n)
    rows = measure(levels, surface)
    table(rows)
    if args.plot:
        plot(rows, args.plot)
    show(rows, args)


if __name__ == "__main__":
    main()
