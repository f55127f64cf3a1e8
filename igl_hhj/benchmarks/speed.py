"""Speed of the drop-in ``igl_hhj.principal_curvature`` against ``igl.principal_curvature``,
measured in the same run.

    python -m igl_hhj.benchmarks.speed [--quick] [--repeat 3] [--meshes DIR] [--out DIR] [--radii 2]
    python -m igl_hhj.benchmarks.speed --only-real --meshes libigl-tutorial-data --min-faces 5000
    python -m igl_hhj.benchmarks.speed --rtol-study | --sliver-study | --factor-study | --tiny | --features \
        | --profile 'icosphere(8)'

Meshes: icosphere(7) (328k faces) and icosphere(8) (1.31M), a jittered ellipsoid at
82k / 328k / 1.31M faces (linear-scaling check), Walker's torus from a perturbed grid
with random diagonals (6° slivers, 262k faces), every mesh in ``../shared/data/meshes``
(``--meshes``) plus the bunny refined twice by ``igl.upsample``, and an open scan-like
height field (jittered grid with random diagonals cropped to a disc, 5° slivers).

For each mesh it prints: the smallest angle; the best-of-``--repeat`` wall time of
``igl.principal_curvature`` (default 5-ring quadric fit) and of the drop-in; the ratio
``t_libigl / t_drop-in`` (> 1: igl_hhj is faster), also at radius 2 (``--radii``: both
called with ``radius=r``); µs per face; the time of
``igl_hhj.shape_operator`` with ``solver="direct"``, ``"cg"`` and ``"auto"`` (auto must
never be slower than both); what "auto" chose and its PCG iterations; the peak memory of
one drop-in call above the input (KB per face, in a fresh subprocess after warm-up calls
on three small meshes that take every solver path: the peak resident size ``VmHWM``, reset just before the call, minus the
resident size before it), how much slower
the first call in a fresh process is than the best later one, and the time of
``from igl_hhj import principal_curvature`` there (which imports what the call needs),
both as the median over ``--fresh`` fresh processes (default 3).  Writes ``speed.md`` to
``--out``.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from . import progress as progress_bar
from .speed_meshes import _best, _build, _default_mesh_dir, min_angle_degrees
from .speed_studies import (FACTOR_MESHES, FEATURE_MESHES, RTOLS, SLIVER_ANGLES, SLIVER_MESHES,  # noqa: F401
                            copy_bandwidth, factor_markdown, factor_study, feature_markdown, feature_study,
                            profile_stages, rtol_markdown, rtol_study, sliver_study, tiny_markdown, tiny_meshes,
                            tiny_study)


# the direct column is skipped above this many faces (fill, minutes of factorisation)
DIRECT_MAX_FACES = 400_000
QUICK = ("icosphere(4)", "ellipsoid 20k", "open scan 5k")
FULL = ("icosphere(7)", "icosphere(8)", "ellipsoid 82k", "ellipsoid 328k", "ellipsoid 1.31M",
        "torus 262k", "open scan 51k", "bunny upsampled ×2", "real")

_CHILD_TIME = r"""
import json, sys, time
import numpy as np
t = time.perf_counter(); import igl_hhj; from igl_hhj import principal_curvature; t_import = time.perf_counter() - t
d = np.load(sys.argv[1]); V, F = d["V"], d["F"]
t = time.perf_counter(); igl_hhj.principal_curvature(V, F); first = time.perf_counter() - t
later = float("inf")
for _ in range(int(sys.argv[2])):
    t = time.perf_counter(); igl_hhj.principal_curvature(V, F); later = min(later, time.perf_counter() - t)
print(json.dumps({"import": t_import, "first": first, "later": later}))
"""
# Peak RSS from /proc/self/status VmHWM, reset to the current RSS just before the call
# (writing 5 to /proc/self/clear_refs); ru_maxrss would include the parent's RSS at fork.
_CHILD_MEMORY = r"""
import json, sys
import numpy as np
import igl_hhj
from igl_hhj.benchmarks.speed_meshes import _open_scan
from igl_hhj.surfaces import Sphere, icosphere, jitter_tangentially
# imports and one-time set-up (library code paged in) of every path a call may take:
# plain PCG, the two-level sliver solve (a jittered icosphere(4)), boundary estimation
# and the direct solve (the 5k open scan)
igl_hhj.principal_curvature(*icosphere(2))
v, f = icosphere(4)
igl_hhj.principal_curvature(jitter_tangentially(v, f, Sphere(), 0.45, seed=7), f)
igl_hhj.principal_curvature(*_open_scan(36))
d = np.load(sys.argv[1]); V, F = d["V"], d["F"]
def status(key):
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(key):
                return int(line.split()[1]) * 1024
base = status("VmRSS:")
with open("/proc/self/clear_refs", "w") as fh:
    fh.write("5")
igl_hhj.principal_curvature(V, F)
print(json.dumps({"peak": status("VmHWM:") - base}))
"""


def _child_measure(V, F, repeat, fresh=3):
    """In ``fresh`` fresh processes: import time, first-call and best later time of the
    drop-in, summarised by the median over the processes of ``first / later`` and of the
    import time (one process alone scatters: 1.17-1.92 on fandisk in 8 runs); in one more,
    the peak resident memory of one call above the input (after warm-up calls on three
    small meshes covering every solver path, so that imports and library code paged in
    once are not counted)."""
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "mesh.npz")
        np.savez(path, V=np.ascontiguousarray(V, dtype=np.float64), F=np.ascontiguousarray(F, dtype=np.int64))

        def child(code):
            res = subprocess.run([sys.executable, "-c", code, path, str(max(1, repeat))],
                                 capture_output=True, text=True, check=True)
            return json.loads(res.stdout.strip().splitlines()[-1])
        runs = [child(_CHILD_TIME) for _ in range(max(1, fresh))]
        out = child(_CHILD_MEMORY)
    ratios = [r["first"] / r["later"] for r in runs]
    out.update(first_over_later=float(np.median(ratios)), first_over_later_runs=ratios,
               import_=float(np.median([r["import"] for r in runs])), fresh=len(runs))
    out["import"] = out.pop("import_")
    return out


def run(names=FULL, repeat=3, mesh_dir=None, progress=True, memory=True, fresh=3, radii=(2,),
        min_faces=0):
    """Time libigl and igl_hhj on the named meshes (entries of :data:`FULL` / :data:`QUICK`).

    Both at radius 5 (the defaults: ``libigl``, ``dropin``), and at every radius of
    ``radii`` (``libigl_r2``, ``dropin_r2``, ...: ``radius=r`` passed to both).

    Returns
    -------
    list of dict rows (seconds, counts, KB/face).
    """
    import igl

    import igl_hhj
    from igl_hhj.curvature import _shape_operator
    from igl_hhj.mesh import MeshDefectError, TriangleMesh
    mesh_dir = _default_mesh_dir() if mesh_dir is None else Path(mesh_dir)
    meshes = [m for n in names for m in _build(n, mesh_dir, min_faces)]
    rows = []
    for label, V, F in progress_bar(meshes, "speed", "mesh", progress):
        nF = len(F)
        rep = repeat if nF < 1_000_000 else max(1, repeat - 1)
        row = {"mesh": label, "faces": nF, "min_angle": min_angle_degrees(V, F)}
        row["libigl"], _ = _best(lambda: igl.principal_curvature(V, F), rep)
        row["dropin"], _ = _best(lambda: igl_hhj.principal_curvature(V, F), rep)
        for r in radii:
            row[f"libigl_r{r}"], _ = _best(lambda: igl.principal_curvature(V, F, r), rep)
            row[f"dropin_r{r}"], _ = _best(lambda: igl_hhj.principal_curvature(V, F, r), rep)
        for s in ("direct", "cg", "auto"):
            if s == "direct" and nF > DIRECT_MAX_FACES:
                row["S_direct"] = float("nan")
                continue
            try:
                row[f"S_{s}"], _ = _best(lambda: igl_hhj.shape_operator(V, F, solver=s), rep)
            except (igl_hhj.SolverError, MeshDefectError):
                # shape_operator takes manifold meshes only (the drop-in repairs the rest)
                row[f"S_{s}"] = float("nan")
        info = {}
        try:
            _shape_operator(TriangleMesh(V, F), None, None, None, "auto", info=info)
        except MeshDefectError:
            info = {"solver": "– (non-manifold: repaired by the drop-in)", "iterations": "–"}
        row["chosen"] = info["solver"] + (" (switched)" if info.get("switched") else "")
        row["iterations"] = info["iterations"]
        row["sliver_dofs"] = info.get("sliver_dofs", 0)
        if memory:
            child = _child_measure(V, F, min(rep, 2), fresh=fresh)
            row["kb_per_face"] = child["peak"] / 1024 / nF
            row["first_over_later"] = child["first_over_later"]
            row["first_over_later_runs"] = child["first_over_later_runs"]
            row["import"] = child["import"]
        rows.append(row)
    return rows


def _radii_of(rows):
    """The extra radii timed in ``rows`` (keys ``libigl_r<r>``), ascending."""
    return sorted({int(k[8:]) for r in rows for k in r if k.startswith("libigl_r")})


def markdown(rows):
    radii = _radii_of(rows)
    head = ["mesh", "faces", "min angle", "libigl (s)", "drop-in (s)", "ratio",
            *[f"ratio r{r} (libigl / drop-in s)" for r in radii], "µs/face",
            "S_h direct (s)", "S_h cg (s)", "S_h auto (s)", "auto chose", "PCG its",
            "peak KB/face", "1st call / later", "import (s)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    f3 = lambda x: "–" if not np.isfinite(x) else f"{x:.3f}"  # noqa: E731
    for r in rows:
        at = [f"**{r[f'libigl_r{q}'] / r[f'dropin_r{q}']:.2f}×** ({f3(r[f'libigl_r{q}'])} / "
              f"{f3(r[f'dropin_r{q}'])})" if f"libigl_r{q}" in r else "–" for q in radii]
        cells = [r["mesh"], f"{r['faces']:,}", f"{r['min_angle']:.2f}°", f3(r["libigl"]),
                 f3(r["dropin"]), f"**{r['libigl'] / r['dropin']:.2f}×**", *at,
                 f"{1e6 * r['dropin'] / r['faces']:.2f}", f3(r["S_direct"]), f3(r["S_cg"]),
                 f3(r["S_auto"]), r["chosen"], str(r["iterations"]),
                 f"{r['kb_per_face']:.2f}" if "kb_per_face" in r else "–",
                 f"{r['first_over_later']:.2f}" if "first_over_later" in r else "–",
                 f"{r['import']:.2f}" if "import" in r else "–"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="three small meshes (seconds)")
    p.add_argument("--repeat", type=int, default=3, help="best of N runs per timing")
    p.add_argument("--meshes", default=None, help="folder of real meshes (default ../shared/data/meshes)")
    p.add_argument("--min-faces", type=int, default=0,
                   help="real meshes: only those with at least this many faces (libigl's tutorial "
                        "data: 5000)")
    p.add_argument("--radii", type=int, nargs="*", default=[2],
                   help="radii timed besides 5 (both libigl and the drop-in; default: 2)")
    p.add_argument("--only-real", action="store_true", help="only the real meshes of --meshes")
    p.add_argument("--no-memory", action="store_true", help="skip the fresh-process columns")
    p.add_argument("--fresh", type=int, default=3,
                   help="fresh processes per mesh for the first-call and import columns (median)")
    p.add_argument("--out", default="benchmark-results",
                   help="folder for speed.md (default ./benchmark-results/)")
    p.add_argument("--sliver-study", action="store_true",
                   help="only PCG iterations / CPU time against the sliver threshold")
    p.add_argument("--factor-study", action="store_true",
                   help="only factorisation / solve times of the HHJ matrix: QDLDL, CHOLMOD, SuperLU")
    p.add_argument("--profile", default=None, metavar="MESH",
                   help="only the wall time, iterations and page faults of each stage of the default "
                        "drop-in on one mesh, e.g. 'icosphere(8)'")
    p.add_argument("--radius", type=int, default=5, help="--profile: the drop-in's radius")
    p.add_argument("--rtol-study", action="store_true",
                   help="only the tolerance study (PCG iterations and error vs rtol)")
    p.add_argument("--tiny", action="store_true",
                   help="only the fixed cost per call on meshes under 1,000 faces (median of interleaved calls)")
    p.add_argument("--features", action="store_true",
                   help="only the cost of feature_angle=40 against the plain drop-in (fandisk, screwdriver)")
    a = p.parse_args(argv)
    if a.features:
        print(feature_markdown(feature_study(mesh_dir=a.meshes)))
        return
    if a.tiny:
        print(tiny_markdown(tiny_study()))
        return
    if a.sliver_study:
        rows = sliver_study(mesh_dir=a.meshes)
        lines = ["| mesh | faces | sliver angle | sliver DOFs | PCG its | CPU s |", "|---|---|---|---|---|---|"]
        lines += [f"| {r['mesh']} | {r['faces']:,} | {r['angle']}° | {100 * r['fraction']:.0f} % | "
                  f"{r['iterations']} | {r['seconds']:.3f} |" for r in rows]
        print("\n".join(lines))
        return
    if a.factor_study:
        print(factor_markdown(factor_study(mesh_dir=a.meshes, repeat=a.repeat)))
        return
    if a.profile:
        V, F = _build(a.profile, _default_mesh_dir() if a.meshes is None else Path(a.meshes))[0][1:]
        prof = profile_stages(V, F, radius=a.radius)
        above = prof.pop("x above floor")
        for k, v in prof.items():
            extra = f"   ({above[k]:.1f}x above floor)" if k in above else ""
            print(f"{k}: {v:.4f}{extra}" if isinstance(v, float) else f"{k}: {v}")
        return
    if a.rtol_study:
        table = rtol_markdown(rtol_study())
        print(table)
        out = Path(a.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "speed_rtol.md").write_text(table + "\n")
        return
    names = QUICK if a.quick else ("real",) if a.only_real else FULL
    rows = run(names, a.repeat, a.meshes, memory=not a.no_memory, fresh=a.fresh,
               radii=tuple(r for r in a.radii if r != 5), min_faces=a.min_faces)
    table = markdown(rows)
    import importlib.metadata
    import platform

    from igl_hhj import kernels
    imp = f"import igl_hhj {rows[0]['import']:.2f} s (fresh process); " if rows and "import" in rows[0] else ""
    header = (f"# igl_hhj drop-in speed vs igl.principal_curvature (same run)\n\n"
              f"libigl {importlib.metadata.version('libigl')}, numpy {np.__version__}, "
              f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
              f"{kernels.max_threads()} OpenMP threads, best of {a.repeat}; {imp}"
              f"load average at the end {os.getloadavg()[0]:.1f}.\n\n")
    print(header + table)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "speed.md").write_text(header + table + "\n")
    (out / "speed.json").write_text(json.dumps(rows, indent=1))
    print(f"\nwrote {out / 'speed.md'}")


if __name__ == "__main__":
    main()
