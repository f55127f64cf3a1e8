"""Speed of igl_hhj against ``igl.principal_curvature``, measured in the same run.

    python -m igl_hhj.benchmarks.speed [--max-faces 1400000] [--repeat 1] [--out DIR]

Meshes: a jittered ellipsoid refined uniformly (well-shaped triangles) and
Walker's torus from a perturbed grid with random diagonals (minimum angle ≈ 6°,
the hard case for the HHJ solver), from ~10k to ≥ 1M faces.  For each mesh it
times ``igl.principal_curvature`` (libigl's quadric fitting, default 5-ring),
``igl_hhj.shape_operator`` with the default solver ("auto"), with PCG and with
the sparse direct solver (up to 400k faces), and the drop-in ``igl_hhj.principal_curvature``;
prints seconds, µs/face and the ratio ``t_libigl / t_igl_hhj`` (> 1: igl_hhj
is faster).  Writes ``speed.md`` to ``--out`` (default ``./benchmark-results/``).
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from . import progress as progress_bar

SOLVERS = ("auto", "cg", "direct")
# splu's fill grows superlinearly: above this many faces the direct column is skipped
DIRECT_MAX_FACES = 400_000


def _meshes(max_faces):
    from ..surfaces import (Ellipsoid, WalkerTorus, ellipsoid_coarse, refine, torus_coarse)
    ell = Ellipsoid()
    V, F = ellipsoid_coarse(ell, subdivisions=3, amount=0.2)          # 1280 faces
    V, F = refine(V, F, ell, 2)                                        # 20k faces
    while len(F) <= max_faces:
        yield "ellipsoid", V, F
        V, F = refine(V, F, ell, 1)
    tor = WalkerTorus()
    V, F = torus_coarse(n_phi=32, n_t=16, amount=0.25)                 # 1024 faces
    V, F = refine(V, F, tor, 2)                                        # 16k faces
    while len(F) <= max_faces:
        yield "torus", V, F
        V, F = refine(V, F, tor, 1)


def _time(fn, repeat):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def run(max_faces=1_400_000, repeat=1, solvers=SOLVERS, progress=True):
    """Time libigl and igl_hhj on every mesh up to ``max_faces`` faces.

    Returns
    -------
    list of dict rows: ``surface, faces, libigl, hhj_<solver>..., dropin`` (seconds).
    """
    import igl

    import igl_hhj
    meshes = list(_meshes(max_faces))
    rows = []
    for name, V, F in progress_bar(meshes, "speed", "mesh", progress):
        row = {"surface": name, "faces": len(F)}
        row["libigl"] = _time(lambda: igl.principal_curvature(V, F), repeat)
        for s in solvers:
            if s == "direct" and len(F) > DIRECT_MAX_FACES:
                row[f"hhj_{s}"] = float("nan")
                continue
            row[f"hhj_{s}"] = _time(lambda: igl_hhj.shape_operator(V, F, solver=s), repeat)
        row["dropin"] = _time(lambda: igl_hhj.principal_curvature(V, F), repeat)
        rows.append(row)
    return rows


def markdown(rows, solvers=SOLVERS):
    head = ["surface", "faces", "libigl (s)"] + [f"S_h {s} (s)" for s in solvers] + \
        ["drop-in (s)", "drop-in µs/face", "ratio libigl/drop-in", "ratio libigl/S_h auto"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [r["surface"], f"{r['faces']:,}", f"{r['libigl']:.3f}"]
        cells += ["–" if np.isnan(r[f"hhj_{s}"]) else f"{r[f'hhj_{s}']:.3f}" for s in solvers]
        cells += [f"{r['dropin']:.3f}", f"{1e6 * r['dropin'] / r['faces']:.2f}",
                  f"{r['libigl'] / r['dropin']:.2f}×"]
        cells += [f"{r['libigl'] / r['hhj_auto']:.2f}×" if "hhj_auto" in r else "–"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--max-faces", type=int, default=1_400_000,
                   help="largest mesh timed, in faces (default 1400000; 100000 takes seconds)")
    p.add_argument("--repeat", type=int, default=1, help="best of N runs per timing")
    p.add_argument("--out", default="benchmark-results",
                   help="folder for speed.md (default ./benchmark-results/)")
    a = p.parse_args(argv)
    rows = run(a.max_faces, a.repeat)
    table = markdown(rows)
    import importlib.metadata
    import platform
    header = (f"# igl_hhj speed vs igl.principal_curvature (same run)\n\n"
              f"libigl {importlib.metadata.version('libigl')}, numpy {np.__version__}, "
              f"{platform.processor() or platform.machine()}, best of {a.repeat}.\n\n")
    print(table)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "speed.md").write_text(header + table + "\n")
    print(f"\nwrote {out / 'speed.md'}")


if __name__ == "__main__":
    main()
