"""The compiled small-mesh path of the drop-in (`igl_hhj.small_mesh`, issue 24: fixed cost)
returns the general path's values bit for bit, closed or open, and hands every other mesh to it."""
import warnings

import numpy as np
import pytest
from conftest import DEFECTS, defect_mesh, fin

import igl_hhj
from igl_hhj import curvature, small_mesh
from igl_hhj.benchmarks.speed import tiny_meshes
from igl_hhj.mesh import MeshDefectError, MeshWarning, as_mesh
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially, square_grid, torus_coarse


def general(V, F, radius=5, rtol=1e-6, boundary="estimate"):
    """The drop-in without the small-mesh path."""
    return curvature.dropin_on_mesh(as_mesh(V, F), radius, boundary, None, None, None, "auto", rtol)


def assert_identical(a, b):
    for x, y in zip(a[:4], b[:4]):
        assert x.dtype == y.dtype == np.float64 and x.shape == y.shape and x.flags.c_contiguous
        assert np.array_equal(x, y, equal_nan=True)
    assert a[4] == b[4] and all(type(i) is int for i in a[4])


def _two_parts():
    V1, F1 = icosphere(1)
    V2, F2 = torus_coarse(n_phi=8, n_t=6)
    return np.vstack([V1, 0.5 * V2 + 3.0]), np.vstack([F1, F2 + len(V1)])


def _unreferenced():
    V, F = icosphere(1)
    return np.vstack([V[:5], [[9.0, 9.0, 9.0]], V[5:]]), np.where(F >= 5, F + 1, F)


def _pillow():
    """A flat closed disc of two fans: its rim vertices have no tangent plane (folded)."""
    t = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    V = np.vstack([[0, 0, 0], [0, 0, 0], np.c_[np.cos(t), np.sin(t), 0 * t]])
    rim = 2 + np.arange(8)
    nxt = 2 + (np.arange(8) + 1) % 8
    return V + [0, 0, 0], np.vstack([np.c_[0 * rim, rim, nxt], np.c_[0 * rim + 1, nxt, rim]])


def _jittered_sphere():
    V, F = icosphere(2)
    return jitter_tangentially(V, F, Sphere(), 0.3, seed=4) * [1.0, 0.8, 0.6], F


def _open_meshes():
    P, F = square_grid(2, amount=0.3, seed=1)
    V, Fs = icosphere(2)
    cap = Fs[V[Fs].mean(axis=1)[:, 2] < 0.5]                    # a sphere with a round hole
    Vt, Ft = torus_coarse(n_phi=8, n_t=6)
    return {"open grid 8": (np.c_[P, P[:, 0] ** 2 - P[:, 1] ** 2], F), "sphere cap": (V, cap),
            "sphere minus one face": (icosphere(1)[0], icosphere(1)[1][1:]), "open torus": (Vt, Ft[4:])}


CLEAN = {name: (V, F) for name, V, F in tiny_meshes() if as_mesh(V, F).n_edges <= small_mesh.MAX_EDGES}
CLEAN.update({"two parts": _two_parts(), "unreferenced vertex": _unreferenced(), "pillow": _pillow(),
              "jittered ellipsoid": _jittered_sphere(), **_open_meshes()})


@pytest.mark.parametrize("name", sorted(CLEAN))
@pytest.mark.parametrize("radius,rtol", [(5, 1e-6), (2, 1e-6), (1, 1e-10)])
def test_same_bits_as_the_general_path(name, radius, rtol):
    V, F = CLEAN[name]
    out = small_mesh.try_dropin(V, F, radius, rtol)
    assert out is not None, "a small clean closed mesh takes the compiled path"
    assert_identical(out, general(V, F, radius, rtol))
    assert_identical(igl_hhj.principal_curvature(V, F, radius, rtol=rtol), out)


def test_the_benchmarks_closed_meshes_are_covered():
    assert {"octahedron", "cube", "icosphere(0)", "icosphere(1)", "icosphere(2)", "torus 96", "open grid 18",
            "open grid 128"} <= set(CLEAN)
    assert sum(as_mesh(*m).has_boundary for m in CLEAN.values()) >= 6


def test_open_meshes_plain_and_unwelded_take_the_general_path():
    """boundary="plain" on an open mesh, and an unwelded mesh (the general path warns)."""
    V, F = _open_meshes()["sphere cap"]
    assert small_mesh.try_dropin(V, F, 5, 1e-6, "plain") is None
    assert_identical(igl_hhj.principal_curvature(V, F, boundary="plain"), general(V, F, boundary="plain"))
    assert small_mesh.try_dropin(*icosphere(1), 5, 1e-6, "plain") is not None     # closed: no boundary
    P, Fg = square_grid(3, amount=0.0)
    Vg = np.c_[P, 0 * P[:, 0]]
    Vu = np.vstack([Vg, Vg])                                    # two copies, one seam apart: unwelded
    Fu = np.vstack([Fg[: len(Fg) // 2], Fg[len(Fg) // 2:] + len(Vg)])
    assert small_mesh.try_dropin(Vu, Fu, 5, 1e-6) is None
    with pytest.warns(MeshWarning, match="unwelded"):
        igl_hhj.principal_curvature(Vu, Fu)


def test_bad_vertices_are_the_general_paths():
    V, F = _unreferenced()
    out = small_mesh.try_dropin(V, F, 5, 1e-6)
    assert out[4] == [5] and np.isnan(out[2][5])
    V, F = _pillow()
    out = small_mesh.try_dropin(V, F, 5, 1e-6)
    assert out[4] == list(range(2, 10))          # the rim: normals cancel


def test_int32_float32_inputs():
    V, F = icosphere(1)
    out = small_mesh.try_dropin(V.astype(np.float32), F.astype(np.int32), 5, 1e-6)
    assert_identical(out, general(V.astype(np.float32).astype(np.float64), F))


@pytest.mark.parametrize("seed", range(120))
def test_defects_take_the_general_path(seed):
    """Whatever the strict validation refuses (every defect class of conftest.DEFECTS, open
    boundaries) or warns about is left to the general path, which repairs or raises."""
    V, F, kinds = defect_mesh(seed)
    out = small_mesh.try_dropin(V, F, 5, 1e-6)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            mesh = as_mesh(V, F)
        except (MeshDefectError, Warning):
            assert out is None, kinds
            return
    if mesh.n_edges > small_mesh.MAX_EDGES:
        assert out is None, kinds
    else:
        assert_identical(out, general(V, F))


def test_every_defect_class_is_refused():
    V, F = icosphere(1)
    cases = {"fin": fin(V, F)[:2], "flip": (V, np.vstack([F[:1, ::-1], F[1:]])),
             "duplicate": (V, np.vstack([F, F[:1]])), "repeated corner": (V, np.vstack([F, [[0, 0, 1]]])),
             "too large": icosphere(3)}
    Vz = V.copy()
    a, b, c = F[0]
    Vz[a] = 0.5 * (V[b] + V[c])                  # zero-area face
    cases["zero-area face"] = (Vz, F)
    assert len(DEFECTS) >= 9
    for name, (Vc, Fc) in cases.items():
        assert small_mesh.try_dropin(Vc, Fc, 5, 1e-6) is None, name


@pytest.mark.parametrize("bad", ["nan", "inf", "huge", "negative index", "index out of range", "list",
                                 "masked", "object", "shape"])
def test_bad_input_keeps_the_general_paths_errors(bad):
    V, F = icosphere(0)
    V = V.copy()
    F = F.copy()
    if bad == "nan":
        V[3, 1] = np.nan
    elif bad == "inf":
        V[3, 1] = np.inf
    elif bad == "huge":
        V[3, 1] = 1e80
    elif bad == "negative index":
        F[2, 1] = -1
    elif bad == "index out of range":
        F[2, 1] = len(V)
    elif bad == "masked":
        V = np.ma.masked_array(V, mask=np.zeros_like(V, dtype=bool))
        V.mask[0, 0] = True
    elif bad == "object":
        V = V.astype(object)
    elif bad == "shape":
        V = V[:, :2]
    if bad == "list":
        assert small_mesh.try_dropin(V.tolist(), F.tolist(), 5, 1e-6) is None
        assert_identical(igl_hhj.principal_curvature(V.tolist(), F.tolist()), general(V, F))
        return
    assert small_mesh.try_dropin(V, F, 5, 1e-6) is None
    with pytest.raises((ValueError, TypeError)) as fast:
        igl_hhj.principal_curvature(V, F)
    with pytest.raises((ValueError, TypeError)) as slow:
        general(V, F)
    assert str(fast.value) == str(slow.value)


def test_options_the_small_path_does_not_cover():
    """solver="cg", feature_angle and boundary data run the general path (a different
    computation), bad option values raise as before."""
    V, F = icosphere(1)
    cg = igl_hhj.principal_curvature(V, F, solver="cg")
    ref = curvature.dropin_on_mesh(as_mesh(V, F), 5, "estimate", None, None, None, "cg", 1e-6)
    assert_identical(cg, ref)
    with pytest.raises(ValueError, match="boundary"):
        igl_hhj.principal_curvature(V, F, boundary="nope")
    with pytest.raises(ValueError, match="rtol"):
        igl_hhj.principal_curvature(V, F, rtol=2.0)
    with pytest.raises(ValueError, match="solver"):
        igl_hhj.principal_curvature(V, F, solver="nope")


def test_fuzz_scaled_perturbed_subsets():
    """400 generated meshes: face subsets (open, with corners and bow-ties), normal jitter,
    coordinate scales 1e-30-1e30, radii 1-8: wherever the compiled path answers it gives the
    general path's bits, and it answers for most of them."""
    rng = np.random.default_rng(7)
    P, Fg = square_grid(5, amount=0.3)
    base = [icosphere(1), icosphere(2), torus_coarse(n_phi=8, n_t=6), (np.c_[P, P[:, 0] * P[:, 1]], Fg),
            (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]), np.array([[0, 1, 2]])),
            (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0.2], [0, -1, 0.1]]),
             np.array([[0, 1, 2], [0, 3, 4]]))]                        # a bow-tie
    answered = 0
    for _ in range(400):
        V, F = base[rng.integers(len(base))]
        if rng.random() < 0.5 and len(F) > 3:
            F = F[rng.random(len(F)) < rng.uniform(0.3, 1.0)]
            if len(F) == 0:
                continue
        V = (V + rng.normal(scale=rng.choice([0, 1e-3, 0.05]), size=V.shape)) * 10.0 ** rng.uniform(-30, 30)
        radius = int(rng.choice([1, 2, 5, 8]))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out = small_mesh.try_dropin(V, F, radius, 1e-6)
            if out is not None:
                answered += 1
                assert_identical(out, general(V, F, radius))
    assert answered >= 300
