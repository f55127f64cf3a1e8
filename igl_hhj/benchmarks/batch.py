"""Throughput of ``igl-hhj batch`` (:mod:`igl_hhj.batch`) against a plain Python loop.

    python -m igl_hhj.benchmarks.batch [--meshes 200] [--seed 0] [--out DIR] [--mesh-dir DIR]

Collection (generated on the fly in a temporary folder, not kept): ``--meshes``
meshes of mixed sizes, each under a random rigid motion: 40 % small ellipsoids
(icosphere subdivisions, 320–5120 faces), 45 % the real meshes of ``--mesh-dir``
(default ``../shared/data/meshes`` next to the repository; ellipsoids of 5120
faces if absent) as they are, 15 % those subdivided once (``igl.upsample``, ×4
faces) when that gives at most :data:`MAX_FACES` faces (else as they are),
written as ascii ``.off``.  The cap keeps the collection in the range where
``solver="auto"`` factorises directly: above it the current PCG path takes
4.6 s / 8.9 s of CPU for the subdivided cheburashka / camelhead (53k / 91k faces)
and would dominate both the collection and the run time.

Measured on the same collection:

* **loop**: ``read_mesh`` → ``TriangleMesh`` → :func:`igl_hhj.batch.compute_curvature`
  → ``write_curvature`` for every file in a plain ``for`` loop (what one would write
  without ``igl-hhj batch``);
* **in-process**: ``run_batch(workers=0)``;
* **1 worker**, **2 workers**: ``run_batch`` on an embedded ``LocalCluster``
  (started before the timing; its start-up is reported separately);
* **overhead**: 20 meshes with ≥ 20k faces, one per task on 1 worker, against the loop
  on the same meshes: ``(t_worker − t_loop) / t_loop``, and per task
  ``(wall − Σ in-task seconds) / tasks`` (the time outside the meshes' own work);
* **grouping**: the small meshes alone on 2 workers, one mesh per task
  (``group_bytes=0``) and grouped (default :data:`igl_hhj.batch.GROUP_BYTES`).

The load of a shared machine drifts over minutes, so every configuration runs every
part of the collection in turn (see :func:`run`).

Prints a markdown table and writes it to ``DIR/batch.md`` (default
``./benchmark-results/``).  The speed-up of 2 workers over the loop is bounded by
the cores actually free: on a shared machine, note the load average printed with it.
"""
from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

LARGE_FACES = 20_000
MAX_FACES = 40_000


def _rotation(rng):
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    return Q if np.linalg.det(Q) > 0 else -Q


def _default_mesh_dir():
    return Path(__file__).resolve().parents[2].parent / "shared" / "data" / "meshes"


def make_collection(folder, n=200, seed=0, mesh_dir=None):
    """Write ``n`` meshes of mixed sizes to ``folder``; returns [(path, #faces)]."""
    import igl

    from ..mesh_io import read_mesh
    rng = np.random.default_rng(seed)
    mesh_dir = Path(mesh_dir) if mesh_dir is not None else _default_mesh_dir()
    real = []
    if mesh_dir.is_dir():
        for p in sorted(mesh_dir.iterdir()):
            if p.suffix.lower() in (".off", ".obj"):
                V, F, _ = read_mesh(p)
                real.append((p.stem, V, F))
    sphere = {0: igl.icosahedron()}
    for k in range(1, 6):
        V, F = igl.upsample(*sphere[k - 1])
        sphere[k] = (V / np.linalg.norm(V, axis=1, keepdims=True), F)
    if not real:
        real = [(f"ellipsoid{i}", sphere[4][0] * (1, 0.5 + 0.2 * i, 0.7), sphere[4][1]) for i in range(3)]
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for i in range(n):
        u = rng.uniform()
        if u < 0.40:
            V, F = sphere[int(rng.integers(2, 5))]
            V, name = V * rng.uniform(0.5, 2.0, size=3), "ellipsoid"
        else:
            name, V, F = real[int(rng.integers(len(real)))]
            if u > 0.85 and 4 * len(F) <= MAX_FACES:
                V, F = igl.upsample(V, F)
                name += "_x4"
        V = V @ _rotation(rng).T + rng.normal(size=3)
        path = folder / f"{i:03d}_{name}.off"
        igl.write_triangle_mesh(str(path), np.ascontiguousarray(V), F)
        out.append((path, len(F)))
    return out


def plain_loop(paths, outdir):
    """The loop without igl_hhj.batch; returns (wall seconds, CPU seconds of all threads)."""
    from ..batch import compute_curvature
    from ..mesh import TriangleMesh
    from ..mesh_io import read_mesh, write_curvature
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t, c = time.perf_counter(), time.process_time()
    for p in paths:
        V, F, _ = read_mesh(p)
        mesh = TriangleMesh(V, F)
        est, S = compute_curvature(mesh.V, mesh.F, keep_shape_operator=True)
        write_curvature(outdir / (Path(p).stem + ".npz"), mesh.V, mesh.F, est, method="hhj", S=S)
    return time.perf_counter() - t, time.process_time() - c


def _timed_batch(paths, outdir, **kw):
    """(wall seconds, Σ in-task seconds, Σ in-task CPU seconds) of one ``run_batch``."""
    from ..batch import run_batch
    t = time.perf_counter()
    res = run_batch([str(p) for p in paths], outdir, resume=False, progress=False, **kw)
    wall = time.perf_counter() - t
    bad = [r for r in res.rows if r["status"] != "ok"]
    if bad:
        raise RuntimeError(f"benchmark meshes failed: {bad[:2]}")
    return (wall, sum(float(r["seconds"]) for r in res.rows),
            sum(float(r["cpu_seconds"]) for r in res.rows))


def _label(name):
    return name if name in ("loop", "in-process") else f"{name} worker{'s' if int(name) > 1 else ''}"


def _rotated(items, k):
    k %= len(items)
    return items[k:] + items[:k]


def run(n=200, seed=0, mesh_dir=None, workers=(1, 2), chunks=4, workdir=None, progress=True):
    """Run every measurement; returns a dict of results (seconds, counts, ratios).

    The machine is shared, and its load drifts over minutes: the collection is cut into
    ``chunks`` similar parts (every ``chunks``-th mesh), and each part is run by every
    configuration in turn, starting with a different one each time; the times are sums
    over the parts.  The clusters are started once, before the timing.
    """
    from distributed import Client

    from ..batch.run import _local_cluster, _machine_cores
    say = print if progress else (lambda *a, **k: None)
    tmp = Path(workdir) if workdir is not None else Path(tempfile.mkdtemp(prefix="igl_hhj_batch_"))
    clients = {}
    try:
        coll = make_collection(tmp / "in", n, seed, mesh_dir)
        paths = [p for p, _ in coll]
        faces = np.array([f for _, f in coll])
        small = [p for p, f in coll if f <= 5120]
        large = [p for p, f in coll if f >= LARGE_FACES][:20]
        load = os.getloadavg()[0]
        say(f"{n} meshes, {faces.sum()} faces ({faces.min()}–{faces.max()}); {len(small)} small "
            f"(≤ 5120 faces), {len(large)} of those with ≥ {LARGE_FACES} faces for the overhead; "
            f"load average {load:.1f} on {_machine_cores()} cores")
        res = {"meshes": n, "faces": int(faces.sum()), "cores": _machine_cores(),
               "load_before": load, "chunks": chunks}
        for w in workers:
            t = time.perf_counter()
            cluster = _local_cluster(w, 2)
            clients[w] = (Client(cluster), cluster)
            res[f"startup_{w}"] = time.perf_counter() - t

        def measure(name, part, out):
            if name == "loop":
                wall, cpu = plain_loop(part, out)
                return wall, None, cpu
            if name == "in-process":
                return _timed_batch(part, out, workers=0)
            w, _, grouping = name.partition(" ")
            kw = {"group_bytes": 0} if grouping == "single" else {}
            return _timed_batch(part, out, client=clients[int(w)][0], **kw)

        def interleaved(names, subset, parts, tag):
            wall, inside, cpu = (dict.fromkeys(names, 0.0) for _ in range(3))
            for c in range(parts):
                part = subset[c::parts]
                for name in _rotated(list(names), c):
                    t, t_in, t_cpu = measure(name, part, tmp / f"{tag}_{name.replace(' ', '_')}")
                    wall[name] += t
                    inside[name] += t_in or 0.0
                    cpu[name] += t_cpu
                say(f"  [{tag} {c + 1}/{parts}] " + ", ".join(f"{k} {v:.1f} s" for k, v in wall.items()))
            return wall, inside, cpu

        names = ["loop", "in-process"] + [str(w) for w in workers]
        wall, _, cpu = interleaved(names, paths, chunks, "all")
        res["cpu"] = cpu
        res["configs"] = {_label(k): v for k, v in wall.items()}
        if 1 in clients and large:
            wall, inside, _ = interleaved(["loop", "1 single"], large, 2, "large")
            res["overhead"] = {"meshes": len(large), "loop": wall["loop"], "worker": wall["1 single"],
                               "inside": inside["1 single"]}
        wmax = max(workers)
        if small:
            wall, _, _ = interleaved([f"{wmax} single", str(wmax)], small, 2, "small")
            res["grouping"] = {"meshes": len(small), "workers": wmax,
                               "single": wall[f"{wmax} single"], "grouped": wall[str(wmax)]}
        res["load_after"] = os.getloadavg()[0]
        return res
    finally:
        for client, cluster in reversed(list(clients.values())):   # LIFO: log levels restored last
            client.close()
            cluster.close()
        if workdir is None:
            shutil.rmtree(tmp, ignore_errors=True)


def markdown(res):
    """The throughput table (igl_hhj/docs/batch.md) of :func:`run`'s result."""
    n, nf, loop = res["meshes"], res["faces"], res["configs"]["loop"]
    lines = ["| configuration | wall time | meshes/s | faces/s | speed-up over the loop |",
             "|---|---:|---:|---:|---:|"]
    for name, t in res["configs"].items():
        lines.append(f"| {name} | {t:.1f} s | {n / t:.1f} | {nf / t / 1e3:.0f}k | {loop / t:.2f}× |")
    notes = [f"times summed over {res['chunks']} interleaved parts of the collection (each part "
             "run by every configuration in turn, rotating the order)",
             "CPU seconds for the whole collection (loop: the process, all threads; the others: "
             "the sum of the meshes' cpu_seconds): "
             + ", ".join(f"{_label(k)} {v:.1f} s" for k, v in res["cpu"].items()),
             f"{n} meshes, {nf / 1e6:.2f}M faces, {res['cores']} cores, load average "
             f"{res['load_before']:.1f} before / {res['load_after']:.1f} after (other jobs on the "
             "machine); cluster start-up (not in the times): "
             + ", ".join(f"{k.split('_')[1]} worker(s) {v:.1f} s" for k, v in res.items()
                         if k.startswith("startup_"))]
    if "overhead" in res:
        o = res["overhead"]
        per_task = (o["worker"] - o["inside"]) / o["meshes"]
        notes.append(f"overhead for meshes ≥ {LARGE_FACES} faces ({o['meshes']} meshes, one per "
                     f"task, 1 worker): {100 * (o['worker'] - o['loop']) / o['loop']:+.1f} % against "
                     f"the loop; {1e3 * per_task:.1f} ms per task outside the mesh's own work "
                     f"({100 * (o['worker'] - o['inside']) / o['inside']:.1f} %)")
    if "grouping" in res:
        g = res["grouping"]
        notes.append(f"{g['meshes']} small meshes (≤ 5120 faces) on {g['workers']} workers: one mesh per task "
                     f"{g['meshes'] / g['single']:.0f} meshes/s, grouped "
                     f"{g['meshes'] / g['grouped']:.0f} meshes/s")
    return "\n".join(lines) + "\n\n" + "\n".join(f"- {s}" for s in notes) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--meshes", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--mesh-dir", default=None, help="real meshes (default ../shared/data/meshes)")
    ap.add_argument("--out", default="benchmark-results")
    args = ap.parse_args(argv)
    res = run(args.meshes, args.seed, args.mesh_dir)
    table = markdown(res)
    print("\n" + table)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "batch.md").write_text(table)
    print(f"wrote {out / 'batch.md'}")


if __name__ == "__main__":
    main()
