"""The readable numpy reference of the compiled S_h (:func:`igl_hhj.pipeline.face_shape_operator`):
the numpy HHJ element (:class:`igl_hhj.hhj.HHJProjection`) with the same boundary treatment;
only the tests use it."""
import numpy as np

from igl_hhj.boundary import (boundary_partition, clamped_load, normalised_boundary_normals,
                              simply_supported_values)
from igl_hhj.hhj import HHJProjection


def shape_operator_reference(mesh, boundary_normals=None, boundary_shape_operator=None,
                              simply_supported=None, solver="direct", estimated=False):
    """The readable numpy reference of :func:`igl_hhj.pipeline.face_shape_operator` (:mod:`igl_hhj.hhj`)."""
    clamped, ss_edges = boundary_partition(mesh, boundary_normals, boundary_shape_operator,
                                            simply_supported, estimated)
    proj = HHJProjection(mesh, fixed_edges=ss_edges, solver=solver)
    X = mesh.V
    load = proj.plain_boundary_load(X)
    if clamped.any():
        N = normalised_boundary_normals(mesh, boundary_normals, clamped)
        P = np.eye(3)[None] - N[:, :, None] * N[:, None, :]
        P[~np.isfinite(P)] = 0.0
        load[clamped] = clamped_load(mesh, clamped, P)[clamped]
    fixed_values = simply_supported_values(mesh, boundary_shape_operator, ss_edges) \
        if ss_edges.any() else None
    s = proj.solve(X, load=load, fixed_values=fixed_values)
    c = -np.einsum("fjk,fk->fj", s[mesh.face_edges], mesh.face_normals)
    return np.einsum("fj,fjab->fab", c, proj.phi)
