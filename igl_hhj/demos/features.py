"""Sharp features: libigl, HHJ without and HHJ with crease handling, on a CAD part.

    igl-hhj demo features                                  # fandisk from shared/data/meshes
    igl-hhj demo features path/to/mesh.off --feature-angle 30
    igl-hhj demo features --per face --screenshot out.png  # Walker's S_h per face (saw-tooth)

What you see: three copies of the mesh side by side, coloured by the mean curvature
H with one diverging colour range (coolwarm, symmetric about 0, the 1st-99th
percentiles of the right copy's values, so the smooth parts' curvature is visible and
the other two saturate where they smear a crease): white = flat, red = convex, blue =
concave.  Left:
igl.principal_curvature (quadric fit over a 5-ring).  Middle: igl_hhj without
features (the drop-in, or --per face Walker's S_h).  Right: igl_hhj with
--feature-angle (default 40°): the surface is cut along the creases and each side is
clamped with its own estimated normals (igl_hhj.features), and the crease network is
drawn as tubes coloured by its dihedral angle θ_e in degrees (red convex, blue
concave; second colour bar).  Left and middle smear each crease's Dirac measure into
a band of strong colour (per face: a red/blue saw-tooth); on the right the planes
stay white up to the creases and the curvature sits on the creases, as θ_e.

Printed: the creases (edges, chains, corners, Σ θ_e|e|), the run times, and the
saw-tooth measure: the RMS jump of the per-face H between neighbouring faces next to
the creases over the same RMS away from them (about 1 when there is no saw-tooth).
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from . import _common

FANDISK = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "meshes" / "fandisk.off"


def saw_tooth(mesh, crease, H_face):
    """RMS jump of ``H_face`` across the non-crease edges between faces touching a crease
    vertex, over the same RMS away from the creases (≈ 1: no saw-tooth)."""
    near = np.zeros(mesh.n_vertices, dtype=bool)
    near[mesh.edges[crease].ravel()] = True
    strip = near[mesh.F].any(axis=1)
    inner = np.flatnonzero((mesh.edge_face_count == 2) & ~crease)
    f0, f1 = mesh.edge_faces[inner, 0], mesh.edge_faces[inner, 1]
    d = H_face[f0] - H_face[f1]
    s = np.sqrt(np.mean(d[strip[f0] & strip[f1]] ** 2))
    a = np.sqrt(np.mean(d[~strip[f0] & ~strip[f1]] ** 2))
    return s / a


def main(argv=None, prog=None):
    p = _common.parser(__doc__, prog=prog, size=(1800, 700))
    p.add_argument("mesh", nargs="?", help=f"mesh file (default: {FANDISK})")
    p.add_argument("--feature-angle", type=float, default=40.0, metavar="DEG",
                   help="crease threshold in degrees (default 40)")
    p.add_argument("--per", default="vertex", choices=["vertex", "face"],
                   help="HHJ values per vertex (drop-in, default) or per face (Walker's S_h)")
    p.add_argument("--camera", default="auto", choices=["auto", "+x", "-x", "+y", "-y", "+z", "-z"],
                   help="the side the camera looks from (default auto: largest projected area)")
    args = p.parse_args(argv)
    path = args.mesh or str(FANDISK)
    if args.mesh is None and not FANDISK.is_file():
        _common.fail(f"{FANDISK} not found: give a mesh file")
    V, F = _common.read_mesh(path)
    import igl

    import igl_hhj
    from igl_hhj import features as ft
    from igl_hhj.mesh import as_mesh
    try:
        angle = ft.check_feature_angle(args.feature_angle)
    except ValueError as exc:
        _common.fail(f"--{exc}".replace("feature_angle", "feature-angle", 1))
    mesh = as_mesh(V, F)
    t = time.perf_counter()
    _, _, a1, a2, _ = igl.principal_curvature(mesh.V, mesh.F)
    t_igl = time.perf_counter() - t
    t = time.perf_counter()
    if args.per == "vertex":
        _, _, b1, b2, _ = igl_hhj.principal_curvature(mesh.V, mesh.F)
        H_off = 0.5 * (b1 + b2)
    else:
        H_off = 0.5 * np.trace(igl_hhj.shape_operator(mesh.V, mesh.F), axis1=1, axis2=2)
    t_off = time.perf_counter() - t
    t = time.perf_counter()
    res = ft.feature_principal_curvature(mesh.V, mesh.F, feature_angle=angle)
    H_on = 0.5 * (res.PV1 + res.PV2) if args.per == "vertex" else 0.5 * np.trace(
        igl_hhj.shape_operator(mesh.V, mesh.F, feature_angle=angle), axis1=1, axis2=2)
    t_on = time.perf_counter() - t
    net = res.creases
    crease = np.zeros(mesh.n_edges, dtype=bool)
    crease[net.edge_index] = True
    S_off = 0.5 * np.trace(igl_hhj.shape_operator(mesh.V, mesh.F), axis1=1, axis2=2)
    S_on = 0.5 * np.trace(igl_hhj.shape_operator(mesh.V, mesh.F, feature_angle=angle), axis1=1, axis2=2)
    name = Path(path).stem
    print(f"mesh: {name}, {mesh.n_vertices} vertices, {mesh.n_faces} faces")
    _common.print_table(f"Creases above {angle:g} degrees",
                        ["edges", "chains", "corners", "end points", "Σ θ_e|e|"],
                        [[len(net.edge_index), net.n_chains, len(net.corners), len(net.endpoints),
                          net.total_angle_length]])
    _common.print_table("Run times (s) and per-face saw-tooth (RMS jump next to creases / away; 1 = none)",
                        ["estimator", "time (s)", "saw-tooth"],
                        [["libigl quadric fit", t_igl, "-"],
                         [f"HHJ without features ({args.per})", t_off, saw_tooth(mesh, crease, S_off)],
                         [f"HHJ with features ({args.per})", t_on, saw_tooth(mesh, crease, S_on)]])
    viewer = _common.start_viewer(args)
    R = viewer.view_rotation(args.camera, mesh.V, mesh.F)
    Vd = mesh.V @ R.T
    dx = 1.1 * (Vd.max(axis=0) - Vd.min(axis=0))[0]
    H_igl = 0.5 * (a1 + a2)
    rng = viewer.color_range(H_on, symmetric=True, robust=1.0)     # the smooth parts' range
    where = "vertex" if args.per == "vertex" else "face"
    regs = []
    for k, (label, H) in enumerate([("libigl quadric fit", H_igl),
                                    (f"HHJ, no features, per {where}", H_off),
                                    (f"HHJ, creases > {angle:g}°, per {where}", H_on)]):
        regs.append(viewer.register_scalars(
            mesh.V, mesh.F, {"mean curvature H [1/length unit]": H}, name=f"{name} {k}",
            vminmax=rng, offset=(k * dx, 0.0, 0.0), view=R, title=label))
    regs.append(viewer.register_creases(mesh.V, mesh.F, net, name=f"{name} creases",
                                        offset=(2 * dx, 0.0, 0.0), view=R, radius=0.005))
    print(f"colour range of H (all three copies): [{rng[0]:.3g}, {rng[1]:.3g}]")
    _common.finish(viewer, args, regs)


if __name__ == "__main__":
    main()
