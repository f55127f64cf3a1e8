"""``igl-hhj curvature MESH``: the curvature of one mesh file, its summary, output file,
view or screenshot."""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from ._common import (UserError, _camera, _check_writable, _first_line, _quietly, _read, _say, _Stages, _viewer,
                      _with_hint)


LARGE_MESH_FACES = 100_000
"""Meshes with more faces get stage-by-stage progress lines on stderr."""


def _curvature(args):
    from ..batch import check_curvature_options, default_radius
    from ..batch.compute import MeshRefusedError, compute_curvature_repairing

    say = _say(args)
    if args.tile_faces is not None:            # out of core, tile by tile (igl_hhj.tiled)
        from ..tiled.command import run
        return run(args, say)

    per = args.per
    try:
        check_curvature_options(args.method, per, args.radius, args.feature_angle)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    if not 0 <= args.robust < 50:
        raise UserError(f"--robust must be a percentile in [0, 50), got {args.robust}")
    if args.out is not None:
        if not str(args.out).strip():
            raise UserError("-o/--out: empty output path")
        if os.path.realpath(args.out) == os.path.realpath(args.mesh):
            raise UserError(f"-o {args.out}: is the input mesh itself; refusing to overwrite it "
                            f"(choose another output file)")
        _check_writable(args.out)
    if args.screenshot is not None:
        _check_writable(args.screenshot, (".png",))
        if min(args.size) < 16:
            raise UserError(f"--size must be at least 16 16 pixels, got {args.size[0]} {args.size[1]}")

    t = time.perf_counter()
    mf = _read(args.mesh)
    V, F = mf.V, mf.F
    t_read = time.perf_counter() - t
    large = len(F) > LARGE_MESH_FACES and not args.quiet
    keep_S = args.out is not None and Path(args.out).suffix.lower() == ".npz"
    n_stages = (2 + (keep_S and args.method == "hhj") + (args.out is not None)
                + (args.screenshot is not None))
    stages = _Stages(n_stages, large)
    stages.done(f"reading {len(F)} faces", t_read)

    radius = args.radius if args.radius is not None else default_radius(args.method, per)

    t = time.perf_counter()
    try:             # what the drop-in repairs is repaired (one warning line), unless --strict
        est, S, mesh, R = compute_curvature_repairing(
            V, F, strict=args.strict, method=args.method, per=per, radius=args.radius,
            keep_shape_operator=keep_S, run=stages.run, feature_angle=args.feature_angle)
    except MeshRefusedError as exc:
        strict = (" (--strict; without it the mesh is repaired as igl_hhj.principal_curvature does)"
                  if exc.defect else "")
        raise UserError(f"{args.mesh}: igl_hhj cannot use this mesh: {exc}{strict} "
                        f"(run 'igl-hhj info {args.mesh}' for a diagnosis)") from None
    dt = time.perf_counter() - t
    shown_est = est                  # the summary, the creases and the viewer: on the repaired mesh
    if R is not None:
        shown_est = _rows_of(est, R.vertex_map if est.location == "vertex" else R.face_map)

    say(f"{args.mesh}: {len(V)} vertices, {len(F)} faces, "
          f"{int(mesh.boundary_edges.sum())} boundary edges" + ("" if R is None else " (after the repair)"))
    if mf.split.n_split:
        say(f"  {mf.split.describe()}")
    say(f"  method {args.method} per {per}: {dt:.2f} s")
    if args.method == "hhj":
        say(f"  smoothing scale (--radius): {radius}" + (" (none: Walker's S_h per face)" if radius == 0 else ""))
        if mesh.has_boundary:
            say("  boundary: clamped with estimated normals (quadric fits; igl_hhj.boundary_estimation)")
        if args.feature_angle is not None:
            from ..features import crease_edges, crease_network
            net = crease_network(mesh, crease_edges(mesh, args.feature_angle))
            say(f"  creases (--feature-angle {args.feature_angle:g}): {len(net.edge_index)} edges in "
                f"{net.n_chains} chains, {len(net.corners)} corners; cut along them, each side clamped "
                f"with its own estimated normals; Σ θ_e|e| = {net.total_angle_length:.4g}")
    elif args.method == "igl":
        say(f"  radius: {radius} rings")
    for name, x in [("k1", est.k1), ("k2", est.k2), ("H", est.H), ("K", est.K)]:
        q = np.nanpercentile(x, [1, 50, 99]) if np.isfinite(x).any() else [np.nan] * 3
        say(f"  {name:>3}: 1% {q[0]: .4g}   median {q[1]: .4g}   99% {q[2]: .4g}")
    n_nan = int(np.isnan(est.k1).sum())
    if n_nan:
        why = (_nan_reasons(mesh, est, args.method) if R is None else
               "left without a usable face by the repair, or on a two-sided patch (no outside: "
               "no sign), or as on a clean mesh")
        say(f"  {n_nan} {'vertice' if per == 'vertex' else 'face'}s have no value (NaN): {why}")

    if args.out is not None:
        _write(stages, args, V, F, est, S)

    if args.screenshot is not None or args.view:
        viewer = _viewer()
        name = Path(args.mesh).stem
        robust = args.robust if args.robust > 0 else None
        shown = dict(estimate=shown_est, name=name, robust=robust, enabled=args.quantity, view=args.camera)
        def creases():           # --feature-angle: the crease network on the surface, coloured by θ_e
            if args.feature_angle is None or args.method != "hhj":
                return []
            return [viewer.register_creases(mesh.V, mesh.F, feature_angle=args.feature_angle,
                                            name=f"{name} creases", view=args.camera)]

        if args.view:            # first: the interactive window cannot open after an EGL render
            try:
                viewer.register_curvature(mesh.V, mesh.F, **shown)
                creases()
                viewer.show()
            except viewer.ViewerUnavailable as exc:
                raise UserError(f"cannot open the viewer window: {_first_line(exc)} "
                                f"(without a display use --screenshot PNG)") from None
        if args.screenshot is not None:
            try:
                if args.feature_angle is None:
                    stages.run("screenshot", _quietly, viewer.register_curvature, mesh.V, mesh.F,
                               screenshot=str(args.screenshot), size=tuple(args.size), **shown)
                else:
                    def shot():
                        viewer.init("openGL3_egl")
                        regs = [viewer.register_curvature(mesh.V, mesh.F, **shown)] + creases()
                        viewer.screenshot(str(args.screenshot), regs, size=tuple(args.size))
                    stages.run("screenshot", _quietly, shot)
            except viewer.ViewerUnavailable as exc:
                raise UserError(f"no screenshot: {_with_hint(exc)}") from None
            say(f"  wrote {args.screenshot}")
    return 0


def _nan_reasons(mesh, est, method):
    """Why rows are NaN, with counts (the causes ``bad_vertices`` documents)."""
    nan = np.isnan(est.k1)
    if est.location != "vertex":
        return "the solver returned no value there"
    unref = nan & ~mesh.referenced_vertices
    folded = nan & mesh.folded_vertices
    rest = nan & ~unref & ~folded
    parts = []
    if unref.any():
        parts.append(f"{int(unref.sum())} unreferenced")
    if folded.any():
        parts.append(f"{int(folded.sum())} without a tangent plane (the faces around them cancel: "
                     f"a two-sided or folded sheet, first vertex {int(np.flatnonzero(folded)[0])})")
    if rest.any():
        why = "flagged by libigl (< 6 neighbours)" if method == "igl" else "non-finite estimate"
        parts.append(f"{int(rest.sum())} {why}")
    return ", ".join(parts)


def _rows_of(est, rows):
    """``est`` restricted to the rows ``rows`` (the repaired mesh's vertices or faces)."""
    from dataclasses import replace
    take = {f: getattr(est, f)[rows] for f in ("k1", "k2", "H", "K", "d1", "d2") if getattr(est, f) is not None}
    bad = ~np.isfinite(take["k1"])
    return replace(est, bad=np.flatnonzero(bad), **take)


def _write(stages, args, V, F, est, S):
    """``est`` (and ``S``) on the file's own ``V``, ``F`` (the caller's rows, as the drop-in)."""
    from ..mesh_io import write_curvature
    try:
        stages.run(f"writing {args.out}", write_curvature, args.out, V, F, est,
                   method=args.method, S=S, quantity=args.quantity)
    except OSError as exc:
        raise UserError(f"{args.out}: cannot write: {exc.strerror or exc}") from None
    _say(args)(f"  wrote {args.out}")


def add_parser(sub):
    """The ``curvature`` sub-command."""
    c = sub.add_parser("curvature", help="curvature of a mesh file (libigl's formats, glTF, 3MF, VTK)",
                       description="Principal curvatures k1 >= k2, directions d1, d2, mean H and "
                                   "Gauss K curvature of a triangle mesh (.obj .off .ply .stl .wrl "
                                   ".mesh .msh with libigl; .gltf .glb .3mf with trimesh, .vtp .vtu "
                                   ".vtk with pyvista or meshio). Polygons are split into triangles "
                                   "(fan from each polygon's first corner). Sign: +1/R on a sphere "
                                   "with outward normals.")
    c.add_argument("mesh", metavar="MESH")
    c.add_argument("--method", choices=["hhj", "igl", "heine"], default="hhj",
                   help="hhj: Walker's HHJ shape operator (default); igl: igl.principal_curvature "
                        "(quadric fit); heine: Heine's P1 Weingarten map (does not converge)")
    c.add_argument("--per", choices=["face", "vertex"], default="vertex",
                   help="vertex (default, comparable with libigl) or face (HHJ's native "
                        "piecewise-constant values; hhj only)")
    c.add_argument("--radius", type=int, default=None, metavar="R",
                   help="scale: for hhj the smoothing length in rings / mean edge lengths "
                        "(default 5 per vertex as igl.principal_curvature, 0 per face: Walker's S_h); "
                        "for igl the k-ring size (default 5)")
    c.add_argument("--feature-angle", type=float, default=None, metavar="DEG",
                   help="hhj: sharp features; edges whose normals turn by more than DEG degrees "
                        "(e.g. 40) are creases: the surface is cut along them and each side gets "
                        "its own values (default: off, as libigl)")
    c.add_argument("-o", "--out", metavar="OUT",
                   help="output file, by extension: OUT.npz (k1, k2, H, K, d1, d2, V, F, and the "
                        "shape operator S for hhj), OUT.csv (one row per vertex or face), OUT.ply "
                        "(the values as vertex or face properties, --quantity as MeshLab's quality), "
                        "OUT.vtp / OUT.vtu / OUT.vtk (point or cell data for ParaView/pyvista, "
                        "--quantity the active scalars), "
                        "OUT.obj (vertices coloured by --quantity)")
    c.add_argument("--view", action="store_true", help="open the polyscope viewer")
    c.add_argument("--screenshot", metavar="PNG", help="render the curvature headless to PNG")
    c.add_argument("--quantity", choices=["k1", "k2", "H", "K"], default="H",
                   help="what --view/--screenshot and .obj colours and the .ply 'quality' property show: "
                        "k1, k2 (principal curvatures), H (mean, default), K (Gauss)")
    c.add_argument("--camera", type=_camera, default="auto", metavar="DIR",
                   help="side the --view/--screenshot camera looks from: auto (largest projected "
                        "area, default), +x, -x, +y, -y, +z, -z, or a direction X,Y,Z")
    c.add_argument("--size", type=int, nargs=2, default=(1024, 768), metavar=("W", "H"),
                   help="--screenshot size in pixels (default 1024 768)")
    c.add_argument("--robust", type=float, default=1.0, metavar="P",
                   help="colour range of --view/--screenshot from the P-th to the (100-P)-th "
                        "percentile (default 1; 0: full range)")
    c.add_argument("--strict", action="store_true",
                   help="refuse a mesh that igl_hhj.principal_curvature would repair (non-manifold "
                        "edges or vertices, duplicate, two-sided or flipped faces, degenerate faces, "
                        "repeated corners); default: repair it as the drop-in does, with one warning "
                        "naming the repairs, values on the file's own vertices/faces")
    c.add_argument("-q", "--quiet", action="store_true",
                   help=f"print nothing but warnings and errors: no summary on stdout, no progress "
                        f"lines (stderr, meshes > {LARGE_MESH_FACES} faces)")
    c.add_argument("--tile-faces", type=int, default=None, metavar="N",
                   help="meshes larger than memory: compute in tiles of about N faces (grown by "
                        "the overlap the computation needs) on Dask; -o OUT is then a folder of "
                        ".npy arrays (igl_hhj/docs/tiled.md)")
    c.add_argument("--scheduler", metavar="ADDRESS",
                   help="with --tile-faces: a Dask scheduler (default: embedded cluster)")
    c.add_argument("--workers", type=int, metavar="N",
                   help="with --tile-faces: worker processes of the embedded cluster (default: cores; 0: in-process)")
    c.add_argument("--resume", action=argparse.BooleanOptionalAction, default=True,
                   help="with --tile-faces: continue an interrupted run into OUT (default on)")
    c.set_defaults(func=_curvature)
