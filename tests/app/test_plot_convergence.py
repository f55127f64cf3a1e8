"""igl_hhj.convergence.plot_convergence, the log-log plot the benchmarks share (issue 14)."""
import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

from igl_hhj.convergence import plot_convergence  # noqa: E402


def test_lines_guides_and_labels(tmp_path):
    h = np.array([0.4, 0.2, 0.1, 0.05])
    ax = plot_convergence(h, {"a": 3 * h, "b": h ** 2, "nan": [np.nan, 1, np.nan, np.nan]}, rates=(1, 2),
                          eoc_labels=True, title="t", ylabel="err")
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    assert set(lines) == {"a (EOC 1.00)", "b (EOC 2.00)", "O(h)", "O(h^2)"}   # "nan" has < 2 finite values
    for label, p in (("O(h)", 1), ("O(h^2)", 2)):
        x, y = (np.asarray(v, dtype=float) for v in lines[label].get_data())
        slope = np.diff(np.log(y)) / np.diff(np.log(x))
        np.testing.assert_allclose(slope, p)
        assert y[np.argmin(x)] == pytest.approx(0.5 * 3 * 0.05)   # through half the first series' finest error
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log" and ax.get_title() == "t"
    out = tmp_path / "c.png"
    plot_convergence([h, h[:3]], [h, h[:3] ** 2], ["x", "y"], path=out)        # one h per series
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_bad_arguments():
    h = np.array([0.4, 0.2])
    with pytest.raises(ValueError, match="labels for"):
        plot_convergence(h, [h, h], ["only one"])
    with pytest.raises(ValueError, match="hs must match"):
        plot_convergence(h, [np.ones(3)], ["x"])
