"""The meshes of :mod:`.speed` and its studies (exact surfaces at given sizes, an open
scan-like height field, the real meshes of ``--meshes``), and the best-of timer."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

def _default_mesh_dir():
    for base in (Path.cwd(), Path(__file__).resolve().parents[2]):
        d = base.parent / "shared" / "data" / "meshes"
        if d.is_dir():
            return d
    return None


def _open_scan(n):
    """Open scan-like height field: WalkerSaddle over a jittered grid with random
    diagonals, cropped to a disc (irregular boundary, 5° slivers)."""
    from ..surfaces import WalkerSaddle, square_grid
    P, F = square_grid(n, amount=0.42, seed=7)
    c = P[F].mean(axis=1) - 0.5
    F = F[(c ** 2).sum(axis=1) < 0.24]
    used = np.unique(F)
    remap = -np.ones(len(P), dtype=np.int64)
    remap[used] = np.arange(len(used))
    return WalkerSaddle().lift(P[used]), remap[F]


def _ellipsoid(faces):
    from ..surfaces import Ellipsoid, ellipsoid_coarse, refine
    ell = Ellipsoid()
    V, F = ellipsoid_coarse(ell, subdivisions=3, amount=0.2)          # 1280 faces
    while len(F) < faces:
        V, F = refine(V, F, ell, 1)
    return V, F


def _build(name, mesh_dir, min_faces=0):
    """[(label, V, F)] for one entry of QUICK / FULL ("real": every ``*.off`` and ``*.obj``
    of ``mesh_dir`` with at least ``min_faces`` faces, e.g. libigl's tutorial data)."""
    import igl
    from ..surfaces import WalkerTorus, icosphere, refine, torus_coarse
    if name.startswith("icosphere("):
        V, F = icosphere(int(name[10:-1]))
        return [(name, V, F)]
    if name.startswith("ellipsoid"):
        target = {"20k": 20_000, "82k": 80_000, "328k": 320_000, "1.31M": 1_300_000}[name.split()[1]]
        return [(f"jittered ellipsoid", *_ellipsoid(target))]
    if name == "torus 262k":
        V, F = torus_coarse(n_phi=32, n_t=16, amount=0.25)
        return [("Walker torus (sliver grid)", *refine(V, F, WalkerTorus(), 4))]
    if name.startswith("open scan"):
        n = 36 if name.endswith("5k") else 160
        return [("open scan-like height field", *_open_scan(n))]
    if mesh_dir is None:
        return []
    if name == "bunny upsampled ×2":
        p = mesh_dir / "bunny.off"
        if not p.exists():
            return []
        V, F = igl.read_triangle_mesh(str(p))
        return [(name, *igl.upsample(V, F, 2))]
    if (mesh_dir / name).is_file():              # one mesh of the folder, e.g. camelhead.off
        V, F = igl.read_triangle_mesh(str(mesh_dir / name))
        return [(name, V, F)]
    if name == "real":
        out = []
        for p in sorted([*mesh_dir.glob("*.off"), *mesh_dir.glob("*.obj")]):
            V, F = igl.read_triangle_mesh(str(p))
            if len(F) >= min_faces:
                out.append((p.name, V, F))
        return out
    raise KeyError(name)


def min_angle_degrees(V, F):
    """Smallest interior angle of the mesh in degrees."""
    X = V[F]
    l = np.linalg.norm(X[:, [2, 0, 1]] - X[:, [1, 2, 0]], axis=2)
    dbl = np.linalg.norm(np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]), axis=1)
    s = dbl * l.min(axis=1) / l.prod(axis=1)
    return float(np.degrees(np.arcsin(np.clip(s.min(), 0, 1))))


def _best(fn, repeat):
    best = np.inf
    out = None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out
