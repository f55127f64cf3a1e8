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


def rng(seed=0):
    return np.random.default_rng(seed)
