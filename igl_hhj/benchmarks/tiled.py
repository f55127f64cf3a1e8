"""Tiled curvature (:mod:`igl_hhj.tiled`) against the whole-mesh drop-in.

``python -m igl_hhj.benchmarks.tiled`` prints the table of ``igl_hhj/docs/tiled.md``:
per mesh the faces, tiles, overlap (rings), the tiled run's wall time on an embedded
cluster of 2 single-threaded workers and the whole-mesh call's (2 threads), faces
computed / faces in the mesh, peak resident memory, and the largest difference to the
whole-mesh values relative to max |κ| (absolute on a flat mesh, max |κ| = 0), at ``rtol=1e-12`` (the cut's effect, which the
overlap rule bounds by 1e-6) and at the default ``rtol`` (the solvers' tolerance).

Options
-------
``--big N``       a jittered torus of ≥ N faces written to binary PLY block by block,
                  then ``curvature_file`` on it in a child process under
                  ``prlimit --as`` (``--cap``, default 4 GB, each process), niced.
``--scale N``     tiled (2 workers) against whole-mesh wall time per face on a jittered
                  torus of about N faces.
``--meshes DIR``  the libigl tutorial meshes (default ``/work/tutdata`` when present).

The cut's effect against the ring distance (half-space cuts, direct solves) is
``python -m igl_hhj.benchmarks.tiled_decay``.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

# --------------------------------------------------------------------------- meshes
TORUS_R, TORUS_r = 1.0, 0.4


def torus_grid(n_faces):
    """(n_u, n_v) of a torus grid with at least ``n_faces`` triangles, cells about square."""
    n_v = int(np.ceil(np.sqrt(n_faces / 2 * TORUS_r / TORUS_R)))
    n_u = int(np.ceil(n_faces / (2 * n_v)))
    return n_u, n_v


def torus_blocks(n_u, n_v, *, amount=0.25, seed=0, rows=256):
    """Vertex and face blocks of a jittered torus (R = 1, r = 0.4), ``rows`` rings of the
    grid at a time: vertex (i, j) at angles ``2π (i + a, j + b) / (n_u, n_v)``, a, b
    uniform in ±``amount``; each cell split along a random diagonal; outward normals.

    Returns two generator functions (vertex blocks (m, 3) float64, face blocks (m, 3)
    int64), each block drawn from its own seeded generator: the same mesh on every call,
    holding one block at a time."""
    def vertices():
        for i0 in range(0, n_u, rows):
            i = np.arange(i0, min(i0 + rows, n_u))
            rng = np.random.default_rng([seed, i0])
            a = rng.uniform(-amount, amount, (len(i), n_v))
            b = rng.uniform(-amount, amount, (len(i), n_v))
            u = 2 * np.pi * (i[:, None] + a) / n_u
            v = 2 * np.pi * (np.arange(n_v)[None, :] + b) / n_v
            rho = TORUS_R + TORUS_r * np.cos(v)
            yield np.stack([rho * np.cos(u), rho * np.sin(u), TORUS_r * np.sin(v)], axis=-1).reshape(-1, 3)

    def faces():
        for i0 in range(0, n_u, rows):
            i = np.arange(i0, min(i0 + rows, n_u))[:, None]
            j = np.arange(n_v)[None, :]
            p, q = i * n_v + j, ((i + 1) % n_u) * n_v + j
            pr, qr = i * n_v + (j + 1) % n_v, ((i + 1) % n_u) * n_v + (j + 1) % n_v
            flip = np.random.default_rng([seed, i0, 1]).random(p.shape) < 0.5
            t1 = np.where(flip[..., None], np.stack([p, q, qr], -1), np.stack([p, q, pr], -1))
            t2 = np.where(flip[..., None], np.stack([p, qr, pr], -1), np.stack([q, qr, pr], -1))
            yield np.stack([t1, t2], axis=2).reshape(-1, 3)

    return vertices, faces


def write_torus(path, n_faces, **kw):
    """Write the jittered torus of :func:`torus_blocks` with ≥ ``n_faces`` faces as binary PLY."""
    from ..tiled.ply import write_binary_ply
    n_u, n_v = torus_grid(n_faces)
    vb, fb = torus_blocks(n_u, n_v, **kw)
    write_binary_ply(path, n_u * n_v, 2 * n_u * n_v, vb(), fb())
    return n_u * n_v, 2 * n_u * n_v


def torus(n_faces, **kw):
    """The jittered torus in memory: (V, F)."""
    n_u, n_v = torus_grid(n_faces)
    vb, fb = torus_blocks(n_u, n_v, **kw)
    return np.concatenate(list(vb())), np.concatenate(list(fb()))


def _ellipsoid(faces):
    from .speed_meshes import _ellipsoid as ell
    return ell(faces)


def _default_mesh_dir():
    d = Path("/work/tutdata")
    return d if d.is_dir() else None


# --------------------------------------------------------------------------- measuring
def _relative_difference(T, W):
    """max |ΔPV1|, |ΔPV2| over the vertices / max |κ| (1 on a flat mesh: the absolute difference)."""
    kmax = np.nanmax(np.abs(np.r_[W[2], W[3]]))
    with np.errstate(invalid="ignore"):
        return float(max(np.nanmax(np.abs(T[2] - W[2])), np.nanmax(np.abs(T[3] - W[3]))) / (kmax or 1.0))


def _peak_children():
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024


def compare(name, V, F, client, tile_faces, *, tight=True):
    """One row of the table: the whole-mesh call and the tiled run on ``client``."""
    import igl_hhj
    import igl_hhj.tiled as tiled
    row = dict(mesh=name, faces=len(F))
    t = time.perf_counter()
    W = igl_hhj.principal_curvature(V, F)
    row["whole_s"] = time.perf_counter() - t
    info = {}
    t = time.perf_counter()
    T = tiled.principal_curvature(V, F, tile_faces=tile_faces, client=client, info=info)
    stats = info["tiles"]
    row["tiled_s"] = time.perf_counter() - t
    row["diff_default"] = _relative_difference(T, W)
    row["same_bad"] = T[4] == W[4]
    row["tiles"] = len(stats)
    rings = [s["rings"] for s in stats.values()]
    row["rings"] = f"{min(rings)}–{max(rings)}" if min(rings) != max(rings) else str(rings[0])
    row["computed_ratio"] = sum(s["faces"] for s in stats.values()) / len(F)
    row["regrown"] = sum(s["rounds"] > 1 for s in stats.values())
    row["worker_peak_mb"] = max(s["peak_rss"] for s in stats.values()) / 2**20
    if tight:
        W = igl_hhj.principal_curvature(V, F, rtol=1e-12)
        T = tiled.principal_curvature(V, F, tile_faces=tile_faces, client=client, rtol=1e-12)
        row["diff_tight"] = _relative_difference(T, W)
    return row


def table(client, mesh_dir=None, *, big=True, tight=True, progress=True):
    rows = []
    cases = []
    if big:
        from ..surfaces import icosphere
        cases += [("icosphere(8)", lambda: icosphere(8), 160_000),
                  ("jittered ellipsoid", lambda: _ellipsoid(1_300_000), 160_000)]
    if mesh_dir is not None:
        import igl
        for p in sorted([*Path(mesh_dir).glob("*.off"), *Path(mesh_dir).glob("*.obj")]):
            def load(p=p):
                V, F = igl.read_triangle_mesh(str(p))
                return V, F
            cases.append((p.name, load, None))
    for name, load, tile_faces in cases:
        V, F = load()
        if F.ndim != 2 or F.shape[1] != 3 or len(F) < 64:
            continue
        try:
            row = compare(name, V, F, client, tile_faces or max(8, len(F) // 8), tight=tight)
        except Exception as exc:            # a mesh the drop-in refuses is refused tiled too
            row = dict(mesh=name, faces=len(F), error=f"{type(exc).__name__}: {exc}"[:120])
        rows.append(row)
        if progress:
            print(json.dumps(row), file=sys.stderr, flush=True)
    return rows


def markdown(rows):
    out = ["| mesh | faces | tiles | overlap (rings) | regrown | computed / faces | worker peak MB | "
           "tiled s (2 workers) | whole s (2 threads) | max diff, rtol 1e-12 | max diff, rtol 1e-6 |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            out.append(f"| {r['mesh']} | {r['faces']} | – | – | – | – | – | – | – | {r['error']} | |")
            continue
        out.append(f"| {r['mesh']} | {r['faces']:,} | {r['tiles']} | {r['rings']} | {r['regrown']} | "
                   f"{r['computed_ratio']:.2f} | {r['worker_peak_mb']:.0f} | {r['tiled_s']:.2f} | "
                   f"{r['whole_s']:.2f} | {r.get('diff_tight', float('nan')):.1e} | {r['diff_default']:.1e} |")
    return "\n".join(out)


# --------------------------------------------------------------------------- the big run
def run_file(mesh, out, workers, tile_faces):
    """``curvature_file`` in this process (the child of :func:`big`); prints a JSON line."""
    import igl_hhj.tiled as tiled
    t = time.perf_counter()
    res = tiled.curvature_file(mesh, out, workers=workers, tile_faces=tile_faces, progress=False)
    from ..batch.jobs import _proc_status_bytes
    stats = res.stats.values()
    print(json.dumps(dict(
        faces=res.n_faces, vertices=res.n_vertices, tiles=len(res.stats), seconds=time.perf_counter() - t,
        read=res.read, computed_ratio=res.faces_computed / res.n_faces, bad=res.n_bad,
        rings=[min(s["rings"] for s in stats), max(s["rings"] for s in stats)],
        regrown=sum(s["rounds"] > 1 for s in stats),
        client_peak_rss=_proc_status_bytes("VmHWM"), worker_peak_rss=max(s["peak_rss"] for s in stats),
        children_peak_rss=_peak_children())), flush=True)


def big(n_faces, cap_bytes, workdir, *, workers=2, tile_faces=None, keep=False):
    """Write the jittered torus, then run :func:`run_file` under ``prlimit --as=cap`` niced."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    mesh = workdir / f"torus_{n_faces}.ply"
    if not mesh.exists():
        t = time.perf_counter()
        nv, nf = write_torus(mesh, n_faces)
        print(f"wrote {mesh} ({nv} vertices, {nf} faces, {mesh.stat().st_size / 2**30:.2f} GiB) in "
              f"{time.perf_counter() - t:.0f} s, peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20:.2f} GiB",
              file=sys.stderr, flush=True)
    from ..tiled import DEFAULT_TILE_FACES
    cmd = ["prlimit", f"--as={int(cap_bytes)}", "nice", "-n", "10", sys.executable, "-m",
           "igl_hhj.benchmarks.tiled", "--run-file", str(mesh), str(workdir / "out"),
           str(workers), str(tile_faces or DEFAULT_TILE_FACES)]
    t = time.perf_counter()
    run = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if run.returncode != 0:
        raise RuntimeError(f"the capped run failed ({run.returncode}): {run.stderr[-2000:]}")
    res = json.loads(run.stdout.strip().splitlines()[-1])
    res.update(cap=int(cap_bytes), wall=wall)
    if not keep:
        import shutil
        shutil.rmtree(workdir / "out", ignore_errors=True)
    return res


# --------------------------------------------------------------------------- scale
def scale(n_faces, client, tile_faces=None):
    """Wall time per face: tiled on ``client`` against the whole-mesh call (2 threads)."""
    import igl_hhj
    import igl_hhj.tiled as tiled
    from ..tiled import DEFAULT_TILE_FACES
    V, F = torus(n_faces)
    t = time.perf_counter()
    W = igl_hhj.principal_curvature(V, F)
    whole = time.perf_counter() - t
    del W
    info = {}
    t = time.perf_counter()
    tiled.principal_curvature(V, F, tile_faces=tile_faces or DEFAULT_TILE_FACES, client=client, info=info)
    stats = info["tiles"]
    tl = time.perf_counter() - t
    return dict(faces=len(F), whole_s=whole, tiled_s=tl, ratio=tl / whole, tiles=len(stats),
                computed_ratio=sum(s["faces"] for s in stats.values()) / len(F),
                rings=sorted({s["rings"] for s in stats.values()}))


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m igl_hhj.benchmarks.tiled", description=__doc__.split("\n")[0])
    ap.add_argument("--meshes", type=Path, default=_default_mesh_dir())
    ap.add_argument("--no-big-meshes", action="store_true", help="skip icosphere(8) and the 1.31M ellipsoid")
    ap.add_argument("--no-tight", action="store_true", help="skip the rtol=1e-12 runs")
    ap.add_argument("--big", type=float, default=None, metavar="FACES")
    ap.add_argument("--cap", type=float, default=4 * 2**30)
    ap.add_argument("--workdir", type=Path, default=Path(tempfile.gettempdir()) / "igl_hhj_tiled_big")
    ap.add_argument("--scale", type=float, default=None, metavar="FACES")
    ap.add_argument("--tile-faces", type=int, default=None)
    ap.add_argument("--run-file", nargs=4, default=None, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.run_file:
        mesh, out, workers, tf = a.run_file
        return run_file(mesh, out, int(workers), int(tf))
    if a.big:
        print(json.dumps(big(int(a.big), a.cap, a.workdir, tile_faces=a.tile_faces)))
        return
    from ..tiled.runner import open_client
    client, owned = open_client(workers=2)
    try:
        if a.scale:
            print(json.dumps(scale(int(a.scale), client, a.tile_faces)))
            return
        rows = table(client, a.meshes, big=not a.no_big_meshes, tight=not a.no_tight)
        print(markdown(rows))
    finally:
        for o in owned:
            o.close()


if __name__ == "__main__":
    main()
