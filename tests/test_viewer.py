"""igl_hhj.viewer: registration only (polyscope's mock backend, no display)."""
import numpy as np
import pytest

from igl_hhj.surfaces.meshing import ellipsoid_coarse

ps = pytest.importorskip("polyscope")

from igl_hhj import viewer  # noqa: E402


@pytest.fixture(scope="module")
def mock():
    if not ps.is_initialized():
        ps.init("openGL_mock")
    yield ps
    ps.remove_all_structures()


def test_register_comparison(mock):
    V, F = ellipsoid_coarse(subdivisions=2)
    reg = viewer.register_comparison(V, F, name="ell", enabled="k2")
    assert ps.has_surface_mesh("ell HHJ") and ps.has_surface_mesh("ell libigl")
    assert set(reg["ranges"]) == {"k1", "k2", "H", "K"}
    for lo, hi in reg["ranges"].values():
        assert lo < hi
    # the libigl copy is shifted so the two do not overlap
    lo, hi = reg["ranges"]["K"]
    assert lo < 0 or lo > 0  # a real range, not the fallback


def test_shared_range():
    assert viewer.shared_range(np.array([1.0, 2.0]), np.array([3.0]), percentile=0) == (1.0, 3.0)
    assert viewer.shared_range(np.array([-1.0, 2.0]), percentile=0) == (-2.0, 2.0)
    assert viewer.shared_range(np.array([np.nan])) == (-1.0, 1.0)


def test_bad_input(mock):
    V, F = ellipsoid_coarse(subdivisions=1)
    with pytest.raises(ValueError, match="enabled must be one of"):
        viewer.register_comparison(V, F, enabled="k3")
    with pytest.raises(ValueError, match="quantity must be one of"):
        viewer.screenshot(V, F, "x.png", quantity="k3")
    Fb = F.copy()
    Fb[0, 0] = -1
    with pytest.raises(ValueError, match="negative vertex indices"):
        viewer.register_comparison(V, Fb)
