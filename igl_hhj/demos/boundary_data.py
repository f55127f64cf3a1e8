"""Open surfaces need boundary data: HHJ shape operator without data, clamped, simply supported.

    igl-hhj demo boundary_data                               # saddle, 4 levels, interactive
    igl-hhj demo boundary_data --surface dumbbell --screenshot out.png
    igl-hhj demo boundary_data --levels 2 --screenshot out.png   # fast

The surfaces are Walker's (Walker 2023, §6): the saddle z = (sin(3.5(x - 1/2)) + cos(4.2(y - 1/2)))/2
over [0, 1]² (``--surface saddle``) and the graph z = exp(-x²) sin 2y over the
wavy dumbbell domain (``--surface dumbbell``), on Walker's non-uniform mesh
sequences (jittered constrained-Delaunay coarse mesh, refined; the dumbbell
with curved boundary elements).  igl_hhj.shape_operator is solved three ways:

(a) no boundary data: the plain assembly (what you get without telling the
    solver anything about the boundary);
(b) clamped: ``boundary_normals`` = the exact normal ν at the boundary vertices;
(c) simply supported: ``boundary_shape_operator`` = the exact ∇ν at the
    boundary vertices (surfaces.boundary_data.walker_boundary_data).

What you see: three copies of the finest mesh side by side, left to right
(a), (b), (c), seen obliquely from above, coloured by the error of the face
shape operator, |S_h - S| (Frobenius norm, root mean square over the three
edge midpoints of the face against the interpolated exact S, i.e. the face's
share of Walker's L2 error), viridis with ONE range for all three copies
(0 = dark purple to the 99th percentile of all errors = yellow).  Copy (a)
has a thin yellow rim along the boundary (one layer of faces); (b) and (c)
have none.  The green/yellow patches inside are where the curvature varies
fastest; they are the same in all three copies.

Printed: the L2 error ‖S - S_h‖ and the maximum error (over face corners) per
level for (a), (b), (c) with their EOCs: with boundary data both converge at
O(h) (EOC about 1, the max error as well on the finer levels); without data
the L2 EOC drops to about 0.7 (saddle) or 0.55 (dumbbell) and the maximum
error does not decrease at all (EOC about 0).
"""
from __future__ import annotations

import numpy as np

from . import _common

KINDS = (("no data", "plain"), ("clamped", "clamped"), ("simply supported", "simply_supported"))


def sequence(name, n_levels):
    """(surface, [(V, F)]) Walker's saddle or dumbbell sequence (needs the ``triangle`` package)."""
    try:
        from igl_hhj.surfaces.dumbbell import WalkerDumbbell, dumbbell_sequence, saddle_sequence
        from igl_hhj.surfaces.exact import WalkerSaddle
        if name == "saddle":
            return WalkerSaddle(), saddle_sequence(n_levels, pre_refine=1)
        return WalkerDumbbell(), dumbbell_sequence(n_levels, pre_refine=1)
    except ImportError as exc:
        from igl_hhj.errors import install_hint
        _common.fail(f"the {name} meshes need the '{exc.name}' package: {install_hint(exc.name or 'triangle')}")


def face_errors(mesh, S, surface):
    """(#F,) RMS over the edge midpoints of |I_h S - S_h|_F (the face's part of Walker's L2 error)."""
    Sx = surface.shape_operator(mesh.V)[mesh.F]               # (#F, 3, 3, 3) exact S at the corners
    mid = 0.5 * (Sx[:, [1, 2, 0]] + Sx[:, [2, 0, 1]])
    D = mid - S[:, None]
    return np.sqrt((D ** 2).sum(axis=(2, 3)).mean(axis=1))


def measure(surface, seq):
    from igl_hhj.convergence import shape_operator_errors
    from igl_hhj.curvature import shape_operator
    from igl_hhj.mesh import as_mesh
    from igl_hhj.surfaces.boundary_data import walker_boundary_data
    rows = []
    for V, F in seq:
        mesh = as_mesh(V, F)
        row = {"mesh": mesh, "h": mesh.max_edge_length, "faces": mesh.n_faces, "err": {}, "field": {}}
        for label, kind in KINDS:
            S = shape_operator(mesh.V, mesh.F, **walker_boundary_data(mesh.V, mesh.F, surface, kind))
            row["err"][label] = shape_operator_errors(mesh.V, mesh.F, S, surface)
            row["field"][label] = face_errors(mesh, S, surface)
        rows.append(row)
    return rows


def tables(rows, name):
    for key, title in (("S", "L2 error ‖S - S_h‖"), ("S_inf", "max error |S - S_h| over face corners")):
        _common.print_eoc_table(f"{name}: {title}", rows, [(lab, [r["err"][lab][key] for r in rows])
                                                            for lab, _ in KINDS])


VIEW = {"saddle": (-30.0, -20.0), "dumbbell": (0.0, -25.0)}


def show(rows, args):
    viewer = _common.start_viewer(args)
    last = rows[-1]
    V = last["mesh"].V @ _common.rotation(*VIEW[args.surface]).T
    V = V - V.mean(axis=0)
    vrange = _common.error_range(*last["field"].values(), robust=1.0)
    offsets = _common.grid_offsets(V, len(KINDS), 1)[0]
    regs = [_common.register_field(viewer, V, last["mesh"].F, "|S_h - S|", last["field"][lab], vrange,
                                   name=f"{args.surface} {lab}", offset=off,
                                   title=f"({'abc'[i]}) {lab} — {args.surface}, {last['faces']:,} faces")
            for i, ((lab, _), off) in enumerate(zip(KINDS, offsets))]
    print(f"colour range of |S_h - S| (all copies, {last['faces']} faces): [0, {vrange[1]:.3g}]")
    _common.finish(viewer, args, regs)


def main(argv=None, prog=None):
    p = _common.parser(__doc__, prog=prog, levels=4, size=(1800, 600))
    p.add_argument("--surface", default="saddle", choices=["saddle", "dumbbell"])
    args = p.parse_args(argv)
    n = _common.check_levels(args.levels, 2, 6)
    surface, seq = sequence(args.surface, n)
    rows = measure(surface, seq)
    tables(rows, args.surface)
    show(rows, args)


if __name__ == "__main__":
    main()
