"""``igl-hhj info MESH``: what a mesh is made of and whether igl_hhj accepts it."""
from __future__ import annotations

from ._common import _read


def _info(args):
    from ..mesh_report import mesh_report
    mf = _read(args.mesh)
    report = mesh_report(mf.V, mf.F, split=mf.split)
    print(f"{args.mesh}")
    for line in report.lines():
        print(f"  {line}")
    return 0 if report.accepted else 1


def add_parser(sub):
    """The ``info`` sub-command."""
    i = sub.add_parser("info", help="mesh statistics and whether igl_hhj accepts the mesh",
                       description="Vertices, faces, edges, components, boundary loops, Euler "
                                   "characteristic, genus, manifoldness, orientation, degenerate and "
                                   "duplicate faces, the repairs the drop-in principal_curvature would "
                                   "make, and igl_hhj's verdict. Exit 0 accepted, "
                                   "1 rejected, 2 unreadable.")
    i.add_argument("mesh", metavar="MESH")
    i.set_defaults(func=_info)
