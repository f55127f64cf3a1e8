"""Shared test helpers: the real-mesh folder and cached mesh sequences."""
from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest

MESH_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "meshes"


def real_mesh_paths():
    """The .off/.obj meshes of shared/data/meshes (empty when the folder is absent)."""
    if not MESH_DIR.is_dir():
        return []
    return sorted(p for p in MESH_DIR.iterdir() if p.suffix in (".off", ".obj", ".ply", ".stl"))


def real_mesh_params():
    paths = real_mesh_paths()
    if not paths:
        return [pytest.param(None, marks=pytest.mark.skip(reason=f"no real meshes in {MESH_DIR}"))]
    return [pytest.param(p, id=p.stem) for p in paths]


@functools.cache
def sequence(name, levels):
    """Cached non-uniform mesh sequences shared by several test modules
    (building them is the expensive part of the rate tests)."""
    from igl_hhj import surfaces as su
    if name == "ellipsoid":
        s = su.Ellipsoid()
        return s, su.mesh_sequence(*su.ellipsoid_coarse(s, subdivisions=2, amount=0.2), s, levels)
    if name == "torus":
        s = su.WalkerTorus()
        return s, su.mesh_sequence(*su.torus_coarse(n_phi=16, n_t=8, amount=0.2), s, levels)
    if name == "saddle":
        s = su.WalkerSaddle()
        return s, su.mesh_sequence(*su.graph_coarse(s, n=6, amount=0.2), s, levels)
    if name == "sphere":
        s = su.Sphere()
        V, F = su.icosphere(1)
        V = su.jitter_tangentially(V, F, s, 0.3, seed=1)
        return s, su.mesh_sequence(V, F, s, levels)
    raise KeyError(name)


def write_off(path, V, F):
    """Write (V, F) as an ascii OFF file with full float precision; returns ``path``."""
    lines = ["OFF", f"{len(V)} {len(F)} 0"] + [" ".join(map(repr, map(float, v))) for v in V]
    lines += ["3 " + " ".join(map(str, f)) for f in F]
    path.write_text("\n".join(lines) + "\n")
    return path


def rng(seed=0):
    return np.random.default_rng(seed)


@functools.cache
def _egl_probe():
    """(ok, message): can polyscope open its headless EGL backend?  Probed in a
    subprocess, because a failed init can leave polyscope unusable in-process."""
    import subprocess
    import sys
    code = "import polyscope as ps; ps.init('openGL3_egl')"
    try:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        return False, "EGL probe timed out"
    return out.returncode == 0, (out.stderr.strip().splitlines() or ["?"])[-1]


def require_egl():
    """Skip when EGL is missing and $CI is unset; in CI a missing EGL is a failure."""
    import os
    ok, msg = _egl_probe()
    if ok:
        return
    if os.environ.get("CI"):
        pytest.fail(f"CI is set but polyscope cannot open EGL (install libegl1 libegl-mesa0 "
                    f"libgl1-mesa-dri): {msg}")
    pytest.skip(f"no EGL for headless rendering: {msg}")


def png_stats(path):
    """(height, width, std of RGB, fraction of non-white pixels, fraction of reddish,
    fraction of bluish pixels) of a PNG screenshot."""
    import matplotlib.image as mpimg
    im = mpimg.imread(str(path))[..., :3].astype(np.float64)
    r, g, b = im[..., 0], im[..., 1], im[..., 2]
    fg = im.min(axis=2) < 0.97
    return {"height": im.shape[0], "width": im.shape[1], "std": float(im.std()), "foreground": float(fg.mean()),
            "red": float(((r > b + 0.15) & fg).mean()), "blue": float(((b > r + 0.15) & fg).mean())}


def pytest_terminal_summary(terminalreporter):
    """Print how many inputs the fuzzers tried (issue 12 asks for the count)."""
    import sys
    fuzz = sys.modules.get("test_fuzz")
    counts = getattr(fuzz, "FUZZ_COUNTS", None)
    if counts:
        total = sum(counts.values())
        detail = ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
        terminalreporter.write_line(f"fuzz inputs tried: {total} ({detail})")
