"""igl_hhj.curvature_of (issue 26 item 6): one quantity of any accepted mesh as plain
arrays; the values are exactly those of the underlying functions (the drop-in per vertex,
the per-face functions of Walker's S_h per face), bad ``kind`` / ``per`` are ValueErrors
listing the choices, and trimesh / pyvista / meshio objects give the results of their
arrays (each skips when its library is missing)."""
from __future__ import annotations

import re
import types

import numpy as np
import pytest

import igl_hhj
from igl_hhj.curvature import CURVATURE_KIND_ALIASES, CURVATURE_KINDS
from igl_hhj.surfaces.exact import Ellipsoid
from igl_hhj.surfaces.meshing import ellipsoid_coarse, jitter_tangentially, refine
from igl_hhj.mesh import TriangleMesh
from igl_hhj.surfaces import icosphere


@pytest.fixture(scope="module")
def mesh():
    s = Ellipsoid()
    V, F = refine(*ellipsoid_coarse(s, subdivisions=1), s, 1)
    return jitter_tangentially(V, F, s, 0.2, seed=4), F


@pytest.fixture(scope="module")
def reference(mesh):
    V, F = mesh
    PD1, PD2, PV1, PV2, _ = igl_hhj.principal_curvature(V, F)
    fPD1, fPD2, fPV1, fPV2 = igl_hhj.face_principal_curvature(V, F)
    return {"vertex": {"mean": 0.5 * (PV1 + PV2), "gauss": PV1 * PV2, "k1": PV1, "k2": PV2,
                       "directions": (PD1, PD2)},
            "face": {"mean": igl_hhj.face_mean_curvature(V, F), "gauss": igl_hhj.face_gaussian_curvature(V, F),
                     "k1": fPV1, "k2": fPV2, "directions": (fPD1, fPD2)}}


def _equal(got, want):
    if isinstance(want, tuple):
        assert isinstance(got, tuple) and len(got) == len(want)
        for g, w in zip(got, want):
            np.testing.assert_array_equal(g, w)
    else:
        assert isinstance(got, np.ndarray) and got.dtype == np.float64
        np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("per", ["vertex", "face"])
def test_values_are_the_underlying_functions(mesh, reference, per):
    V, F = mesh
    for kind in CURVATURE_KINDS:
        _equal(igl_hhj.curvature_of(V, F, kind=kind, per=per), reference[per][kind])
    for alias, canonical in CURVATURE_KIND_ALIASES.items():
        _equal(igl_hhj.curvature_of(V, F, kind=alias, per=per), reference[per][canonical])
    _equal(igl_hhj.curvature_of(V, F), reference["vertex"]["mean"])          # defaults: mean per vertex
    n = len(V) if per == "vertex" else len(F)
    assert reference[per]["mean"].shape == (n,) and reference[per]["directions"][0].shape == (n, 3)


def test_face_values_agree_with_the_principal_values(reference):
    """Per face, H = tr(S_h)/2 and K = det(S_h + ν⊗ν) are (κ1 + κ2)/2 and κ1 κ2."""
    f = reference["face"]
    np.testing.assert_allclose(f["mean"], 0.5 * (f["k1"] + f["k2"]), atol=1e-12)
    np.testing.assert_allclose(f["gauss"], f["k1"] * f["k2"], atol=1e-11)


def test_keyword_arguments_reach_the_underlying_functions(mesh):
    V, F = mesh
    np.testing.assert_array_equal(igl_hhj.curvature_of(V, F, kind="k1", radius=2),
                                  igl_hhj.principal_curvature(V, F, radius=2)[2])
    _, _, PV1, PV2 = igl_hhj.face_principal_curvature(V, F, smoothing=1)
    np.testing.assert_array_equal(igl_hhj.curvature_of(V, F, kind="mean", per="face", smoothing=1), 0.5 * (PV1 + PV2))
    np.testing.assert_array_equal(igl_hhj.curvature_of(V, F, kind="k2", per="face", smoothing=1), PV2)
    with pytest.raises(TypeError, match="smoothing"):
        igl_hhj.curvature_of(V, F, kind="mean", per="vertex", smoothing=1)


@pytest.mark.parametrize("bad", ["curv", "Mean", "gauss_curvature", "", None, 1])
def test_bad_kind_lists_the_choices(mesh, bad):
    V, F = mesh
    with pytest.raises(ValueError, match=r"kind must be one of 'mean', 'gauss', 'k1', 'k2', 'directions' "
                                         r"\(aliases: 'gaussian' = 'gauss'.*got " + re.escape(repr(bad))):
        igl_hhj.curvature_of(V, F, kind=bad)


@pytest.mark.parametrize("bad", ["faces", "vertices", "both", None])
def test_bad_per_lists_the_choices(mesh, bad):
    V, F = mesh
    with pytest.raises(ValueError, match=r"per must be one of 'vertex', 'face', got "):
        igl_hhj.curvature_of(V, F, per=bad)


def test_mesh_errors_pass_through():
    with pytest.raises(TypeError, match="F is required"):
        igl_hhj.curvature_of(np.zeros((3, 3)))


def test_the_curvature_module_is_not_shadowed():
    assert isinstance(igl_hhj.curvature, types.ModuleType)
    assert igl_hhj.curvature_of is igl_hhj.curvature.curvature_of
    assert "curvature_of" in dir(igl_hhj) and "curvature_of" in igl_hhj.__all__


def _check_object(obj, reference):
    for per in ("vertex", "face"):
        for kind in ("mean", "gauss", "k1", "directions"):
            _equal(igl_hhj.curvature_of(obj, kind=kind, per=per), reference[per][kind])


def test_trimesh_object(mesh, reference):
    trimesh = pytest.importorskip("trimesh")
    V, F = mesh
    _check_object(trimesh.Trimesh(V, F, process=False), reference)


def test_pyvista_object(mesh, reference):
    pyvista = pytest.importorskip("pyvista")
    V, F = mesh
    _check_object(pyvista.PolyData(V, np.column_stack([np.full(len(F), 3), F]).ravel()), reference)


def test_meshio_object(mesh, reference):
    meshio = pytest.importorskip("meshio")
    V, F = mesh
    _check_object(meshio.Mesh(V, [("triangle", F)]), reference)


def test_triangle_mesh_object(mesh, reference):
    V, F = mesh
    _check_object(igl_hhj.TriangleMesh(V, F), reference)


def test_quantity_is_keyword_only():
    """README's ``curvature_of(mesh, "mean")`` put "mean" into F: a TypeError naming the fix at
    run time, and positional quantities are refused (mypy rejects both: tests/app/test_typing.py)."""
    V, F = icosphere(1)
    mesh = TriangleMesh(V, F)
    with pytest.raises(TypeError, match="keyword-only: curvature_of\\(mesh, kind='mean'\\)"):
        igl_hhj.curvature_of(mesh, "mean")
    with pytest.raises(TypeError, match="positional"):
        igl_hhj.curvature_of(V, F, "mean")                     # type: ignore[misc]
    np.testing.assert_array_equal(igl_hhj.curvature_of(mesh, kind="mean"), igl_hhj.curvature_of(V, F))
