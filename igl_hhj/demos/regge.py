"""Gauss curvature from edge lengths alone (Regge, k = 0) beside HHJ and the exact K.

    igl-hhj demo regge                               # Walker's torus, 4 levels, interactive
    igl-hhj demo regge --jitter 0.3 --screenshot out.png
    igl-hhj demo regge path/to/mesh.off --screenshot out.png
    igl-hhj demo regge --levels 2 --screenshot out.png   # fast

igl_hhj.regge.gauss_curvature(V, F) treats the squared edge lengths of a mesh
as a degree-0 Regge metric and lifts its distributional Gauss curvature (the
angle deficits) into P1: M K_h = Θ (Gopalakrishnan et al. 2024, Definition 2.3, k = 0).  It
needs only edge lengths, and Σ_V (M K_h)_V = Σ_V Θ_V = 2πχ exactly on closed
meshes (discrete Gauss–Bonnet).

Generated surface (no MESH argument): Walker's torus (x²+y²-0.6)² + 1.5z² = 0.25,
a perturbed (φ, t) grid with random diagonals refined ``--levels`` times
(new vertices projected).  With ``--jitter A`` every level is in addition
moved tangentially by up to A × the local edge length (re-projected).

What you see: three copies of the finest torus, tilted towards the camera,
coloured coolwarm on ONE range symmetric about 0 (± the largest exact |K|; on
a mesh file from the 5th/95th percentiles of all values, --robust): left
Regge K_h (per vertex), middle HHJ Gauss curvature det(S_h + ν⊗ν) (per face),
right the exact K.  K < 0 (blue) around the hole,
K > 0 on the outer half (pale red: the range is set by the much larger
|K| = 15 at the inner equator), white on the top and bottom circles.  Without
jitter all three look alike.  With --jitter 0.3 the Regge copy turns into
red/blue noise (its pointwise values no longer approximate K) while the HHJ
copy still looks like the exact one.  On a mesh file: Regge K_h beside HHJ's
K; on scanned meshes K_h is visibly noisier (more saturated red/blue speckle).

Printed: per level Σ M K_h beside 2πχ (Gauss–Bonnet; equal to rounding), and
for the generated torus the L2 errors ‖K_h - K‖ (consistent P1 mass) and
‖κ_g - K‖ of HHJ (Walker's norm) with EOCs.  Measured: on the refined grid
K_h converges at about O(h) (EOC 1.1-1.2 on the finer levels); on re-jittered
meshes its L2 error GROWS under refinement (negative EOCs) while HHJ's κ_g
error keeps decreasing.  The re-jittered meshes contain sliver triangles (the
table prints the minimum angle: 0.1-0.8° at --jitter 0.3); the angle deficit
divided by a tiny vertex area is what blows up (lumped mass does the same), so
read this as "the P1-lifted degree-0 curvature is not robust to slivers" (paper
004 proves convergence of the k = 0 lifting only in weaker norms), not as a
statement about reasonable meshes.
"""
from __future__ import annotations

import numpy as np

from . import _common

TILT = _common.rotation(0.0, -60.0)  # generated surfaces: seen obliquely from above


def torus_levels(n_levels, jitter=0.0, seed=10):
    from igl_hhj.surfaces.exact import WalkerTorus
    from igl_hhj.surfaces.meshing import jitter_tangentially, mesh_sequence, torus_coarse
    s = WalkerTorus()
    out = []
    for k, (V, F) in enumerate(mesh_sequence(*torus_coarse(24, 12, amount=0.25, seed=0), s, n_levels)):
        if jitter > 0:
            V = jitter_tangentially(V, F, s, jitter, seed=seed + k)
        out.append((V, F))
    return s, out


def gauss_bonnet(mesh):
    """(Σ M K_h, 2πχ): total lifted curvature (geodesic boundary convention, which
    adds the boundary turning π - Σθ; = natural on closed meshes) and 2π(V - E + F)."""
    import igl

    from igl_hhj.regge import gauss_curvature
    K = gauss_curvature(mesh.V, mesh.F, boundary="geodesic")
    M = igl.massmatrix(mesh.V, mesh.F, igl.MASSMATRIX_TYPE_FULL)
    ok = mesh.referenced_vertices
    chi = int(ok.sum()) - len(mesh.edges) + mesh.n_faces
    return float(np.sum(M @ np.where(ok, K, 0.0))), 2 * np.pi * chi


def measure(surface, levels):
    import igl

    from igl_hhj.convergence import shape_operator_errors
    from igl_hhj.curvature import shape_operator
    from igl_hhj.mesh import as_mesh
    from igl_hhj.regge import gauss_curvature
    rows = []
    for V, F in levels:
        mesh = as_mesh(V, F)
        row = {"mesh": mesh, "faces": mesh.n_faces, "h": mesh.max_edge_length,
               "min_angle": float(np.degrees(igl.internal_angles(mesh.V, mesh.F).min()))}
        row["total"], row["2pichi"] = gauss_bonnet(mesh)
        if surface is not None:
            e = gauss_curvature(mesh.V, mesh.F) - surface.gauss_curvature(mesh.V)
            M = igl.massmatrix(mesh.V, mesh.F, igl.MASSMATRIX_TYPE_FULL)
            row["regge"] = float(np.sqrt(e @ (M @ e)))
            row["hhj"] = shape_operator_errors(mesh.V, mesh.F, shape_operator(mesh.V, mesh.F), surface)["kappa_g"]
        rows.append(row)
    return rows


def table(rows, title):
    header = ["level", "faces", "h", "min angle (°)", "Σ M K_h", "2πχ"]
    cols = []
    if "regge" in rows[0]:
        hs = [r["h"] for r in rows]
        er, eh = (_common.eocs([r[k] for r in rows], hs) for k in ("regge", "hhj"))
        header += ["‖K_h - K‖ Regge", "EOC", "‖κ_g - K‖ HHJ", "EOC"]
        cols = [[r["regge"], er[k], r["hhj"], eh[k]] for k, r in enumerate(rows)]
    body = [[k, r["faces"], r["h"], f"{r['min_angle']:.2f}", f"{r['total']:.10g}", f"{r['2pichi']:.10g}"]
            + (cols[k] if cols else [])
            for k, r in enumerate(rows)]
    _common.print_table(title, header, body)


def show(mesh, surface, args, rotate):
    viewer = _common.start_viewer(args)
    V = mesh.V @ TILT.T if rotate else mesh.V
    V = V - V.mean(axis=0)
    ext = V.max(axis=0) - V.min(axis=0)
    step = np.array([1.15 * ext[0], 0.0, 0.0])
    if surface is None:
        from igl_hhj.curvature import face_gaussian_curvature
        from igl_hhj.regge import gauss_curvature
        vrange = viewer.color_range(gauss_curvature(mesh.V, mesh.F), face_gaussian_curvature(mesh.V, mesh.F),
                                    robust=args.robust)
    else:
        K = surface.gauss_curvature(mesh.V)
        vrange = viewer.color_range(K)
    faces = f"{mesh.n_faces:,} faces"
    left = viewer.register_regge_curvature(V, mesh.F, name="Regge K_h", enabled="K_h", vminmax=vrange,
                                           title=f"Regge K_h (edge lengths), per vertex — {faces}")
    mid = viewer.register_regge_curvature(V, mesh.F, name="HHJ K", enabled="hhj", vminmax=vrange, offset=step,
                                          title=f"HHJ det(S_h + ν⊗ν), per face — {faces}")
    regs = [left, mid]
    if surface is not None:
        regs.append(_common.register_field(viewer, V + 2 * step, mesh.F, "Gauss curvature K", K, vrange,
                                           name="exact K", cmap="coolwarm", title=f"exact K — {faces}"))
    print(f"colour range of K (all copies): [{vrange[0]:.3g}, {vrange[1]:.3g}]")
    _common.finish(viewer, args, regs)


def main(argv=None, prog=None):
    p = _common.parser(__doc__, prog=prog, levels=4, size=(1800, 600))
    p.add_argument("mesh", nargs="?", help="mesh file (default: generated torus)")
    p.add_argument("--jitter", type=float, default=0.0, metavar="A",
                   help="re-jitter every generated level by up to A x the local edge length (e.g. 0.3)")
    p.add_argument("--robust", type=float, default=5.0, metavar="P",
                   help="mesh file: colour range from the [P, 100-P] percentiles of all K values (default 5)")
    args = p.parse_args(argv)
    if not 0 <= args.robust < 50:
        _common.fail(f"--robust must be a percentile in [0, 50), got {args.robust}")
    if not 0 <= args.jitter < 0.5:
        _common.fail(f"--jitter must be in [0, 0.5), got {args.jitter}")
    if args.mesh is None:
        surface, levels = torus_levels(_common.check_levels(args.levels, 2, 6), args.jitter)
        title = "Walker's torus" + (f", re-jittered {args.jitter:g}" if args.jitter else ", refined grid")
    else:
        surface, levels = None, [_common.read_mesh(args.mesh)]
        title = args.mesh
    rows = measure(surface, levels)
    table(rows, f"{title}: Gauss–Bonnet and L2 errors of the Gauss curvature")
    show(rows[-1]["mesh"], surface, args, rotate=surface is not None)


if __name__ == "__main__":
    main()
