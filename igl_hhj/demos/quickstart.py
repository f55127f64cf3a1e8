"""From a mesh file to a curvature picture and saved results, step by step.

    igl-hhj demo quickstart                          # a generated torus, written and read back
    igl-hhj demo quickstart path/to/mesh.off --out-dir results
    igl-hhj demo quickstart MESH --no-screenshot     # no EGL needed

The steps, each one line of library code (read this file: it is the example):

1. read the file with the guarded libigl reader (igl_hhj.mesh_io.read_mesh);
2. ask whether igl_hhj accepts the mesh (igl_hhj.mesh_report.mesh_report);
3. curvature per vertex with libigl's call and return values
   (igl_hhj.principal_curvature) and per face (igl_hhj.face_principal_curvature);
4. a picture: HHJ beside igl.principal_curvature, one colour range, titles, a
   colour bar, the view with the largest projected area
   (igl_hhj.viewer.register_comparison(..., screenshot=...), headless EGL);
5. save the results for other tools: .ply (MeshLab colours by its quality =
   H), .vtp (ParaView / pyvista open it coloured by H) and .npz (numpy).

What you see: MESH_H.png in --out-dir (or the --screenshot PNG): two copies of the mesh, left HHJ per
face, right libigl's quadric fit per vertex, coloured by the mean curvature H
(coolwarm, symmetric about 0, the 1st-99th percentile range of both), each
with its title, one colour bar below.

Printed: each step with what it produced (sizes, the verdict, the H
percentiles of both methods, the files written).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from . import _common


def generated_mesh(folder):
    """Write a jittered mesh of Walker's torus to ``folder/torus.off`` and return its path."""
    import igl

    from igl_hhj.surfaces.exact import WalkerTorus
    from igl_hhj.surfaces.meshing import jitter_tangentially, refine, torus_coarse
    s = WalkerTorus()
    V, F = refine(*torus_coarse(24, 12, amount=0.25, seed=0), s, 1)
    V = jitter_tangentially(V, F, s, amount=0.3, seed=1)
    path = Path(folder) / "torus.off"
    igl.write_triangle_mesh(str(path), V, F)
    return path


def main(argv=None, prog=None):
    p = _common.parser(__doc__, prog=prog, size=(1200, 560))
    p.add_argument("mesh", nargs="?", help="mesh file (default: a generated torus written to --out-dir)")
    p.add_argument("--out-dir", default=".", metavar="DIR",
                   help="where the picture and files go, created if missing (default .)")
    p.add_argument("--no-screenshot", action="store_true", help="skip step 4 (no EGL needed)")
    args = p.parse_args(argv)
    out = Path(args.out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)          # created when missing, like batch -o
    except FileExistsError:
        _common.fail(f"--out-dir {out}: is a file, not a folder")
    except OSError as exc:
        _common.fail(f"--out-dir {out}: cannot create it: {exc.strerror or exc}")

    import igl_hhj
    from igl_hhj import baselines, mesh_io, mesh_report

    path = Path(args.mesh) if args.mesh else generated_mesh(out)
    # 1. read
    try:
        V, F, messages = mesh_io.read_mesh(path)
    except mesh_io.MeshFileError as exc:
        _common.fail(str(exc))
    print(f"1. read {path}: {len(V)} vertices, {len(F)} faces" + (f" ({messages[0]})" if messages else ""))
    # 2. check
    report = mesh_report.mesh_report(V, F)
    verdict = [ln for ln in report.lines() if ln.startswith("verdict")]
    print(f"2. {' '.join(verdict[0].split()) if verdict else report.accepted}")
    if not report.accepted:
        _common.fail(f"{path}: igl_hhj cannot use this mesh (see 'igl-hhj info {path}')")
    # 3. curvature
    PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(V, F)         # per vertex, libigl's call
    FD1, FD2, FV1, FV2 = igl_hhj.face_principal_curvature(V, F)          # per face, HHJ's native values
    H = 0.5 * (PV1 + PV2)
    print(f"3. curvature: H per vertex 1/50/99% {np.nanpercentile(H, [1, 50, 99]).round(4).tolist()}, "
          f"per face {np.nanpercentile(0.5 * (FV1 + FV2), [1, 50, 99]).round(4).tolist()}, "
          f"{len(bad)} vertices without a value")
    # 4. picture
    stem = path.stem
    if not args.no_screenshot:
        from types import SimpleNamespace
        viewer = _common.start_viewer(SimpleNamespace(screenshot=True))
        png = args.screenshot or out / f"{stem}_H.png"
        try:
            viewer.register_comparison(V, F, name=stem, enabled="H", robust=1, view="auto",
                                       screenshot=str(png), size=tuple(args.size))
        except (ValueError, viewer.ViewerUnavailable) as exc:
            _common.fail(str(exc).splitlines()[0], code=1)
        print(f"4. picture: wrote {png}")
    else:
        print("4. picture: skipped (--no-screenshot)")
    # 5. save
    est = baselines.hhj_vertex(V, F)
    written = []
    for ext in (".ply", ".vtp", ".npz"):
        target = out / f"{stem}_curvature{ext}"
        mesh_io.write_curvature(target, np.asarray(V, float), np.asarray(F), est, method="hhj")
        written.append(str(target))
    print(f"5. saved {', '.join(written)}")


if __name__ == "__main__":
    main()
