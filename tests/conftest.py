"""Shared test helpers: the real-mesh folder and cached mesh sequences."""
from __future__ import annotations

import functools
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
"""The repository root (tests/ is one level below it)."""
MESH_DIR = ROOT.parent / "shared" / "data" / "meshes"


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
    if name not in su.STANDARD_SEQUENCES:
        raise KeyError(name)
    return su.standard_sequence(name, levels)


# --------------------------------------------------------------------------- defect meshes (issue 24)
def fin(V, F, f=0):
    """Glue a fin (one triangle sticking out radially) on the edge of corners 0, 1 of
    face ``f``: that edge gets three faces.  Returns ``(V, F, [a, b])``."""
    a, b = F[f][0], F[f][1]
    tip = 1.5 * 0.5 * (V[a] + V[b])
    return np.vstack([V, tip]), np.vstack([F, [[a, b, len(V)]]]), [a, b]


def fins(V, F, faces):
    """Glue one fin on the edge of corners 0, 1 of each face in ``faces``, its tip one edge
    length above the edge midpoint along the face normal (radially out, 1.5 × the
    midpoint, on a face without a normal; vectorised).  Returns ``(V, F)``."""
    faces = np.asarray(faces, dtype=np.int64)
    a, b, c = (F[faces, k] for k in range(3))
    n = np.cross(V[b] - V[a], V[c] - V[a])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    m = 0.5 * (V[a] + V[b])
    tip = np.where(norm > 0, m + np.linalg.norm(V[b] - V[a], axis=1, keepdims=True)
                   * n / np.where(norm > 0, norm, 1.0), 1.5 * m)
    new = len(V) + np.arange(len(faces))
    return np.vstack([V, tip]), np.vstack([F, np.stack([a, b, new], axis=1)])


def moebius(n=16, width=0.6, centre=(4.0, 0.0, 0.0)):
    """A Möbius band of ``2 n`` vertices and ``2 n`` faces (non-orientable)."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)

    def p(s):
        r = 1 + s * np.cos(t / 2)
        return np.stack([r * np.cos(t), r * np.sin(t), s * np.sin(t / 2)], axis=-1)

    V = np.vstack([p(-width / 2), p(width / 2)]) + np.asarray(centre)
    i = np.arange(n)
    j = (i + 1) % n
    top_j = np.where(i == n - 1, j, j + n)           # the half twist at the seam
    bot_j = np.where(i == n - 1, j + n, j)
    return V, np.vstack([np.stack([i, bot_j, top_j], 1), np.stack([i, top_j, i + n], 1)])


DEFECTS = ("duplicate", "reversed duplicate", "flip", "fin", "zero-area face", "repeated corner",
           "sliver", "hole", "moebius")
"""The defect kinds of :func:`defect_mesh`."""


@functools.cache
def _small_meshes():
    from igl_hhj import surfaces as su
    return (su.icosphere(1), su.icosphere(2), su.torus_coarse(n_phi=12, n_t=6, amount=0.2))


def defect_mesh(seed):
    """A small sphere or torus with 1-3 seeded defects of :data:`DEFECTS` (each may
    repeat). Returns ``(V, F, kinds)``."""
    rng = np.random.default_rng(seed)
    V, F = _small_meshes()[int(rng.integers(3))]
    V, F = V.copy(), F.copy()
    kinds = [str(k) for k in rng.choice(DEFECTS, int(rng.integers(1, 4)))]
    for kind in kinds:
        f = int(rng.integers(len(F)))
        if kind == "duplicate":
            F = np.vstack([F, F[f:f + 1]])
        elif kind == "reversed duplicate":
            F = np.vstack([F, F[f:f + 1, ::-1]])
        elif kind == "flip":
            F[f] = F[f, ::-1]
        elif kind == "fin":
            V, F = fins(V, F, [f])
        elif kind == "zero-area face":
            a, b = F[f][0], F[f][1]
            V = np.vstack([V, 0.5 * (V[a] + V[b])])
            F = np.vstack([F, [[a, b, len(V) - 1]]])
        elif kind == "repeated corner":
            F = np.vstack([F, [[F[f][0], F[f][0], F[f][1]]]])
        elif kind == "sliver":
            a, b, c = F[f]
            m = 0.5 * (V[b] + V[c])
            V[a] = m + 10.0 ** -rng.uniform(8, 16) * (V[a] - m)
        elif kind == "hole":
            F = np.delete(F, f, axis=0)
        else:
            Vm, Fm = moebius(int(rng.integers(8, 16)))
            F = np.vstack([F, Fm + len(V)])
            V = np.vstack([V, Vm])
    return V, F, kinds


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


def require_test_extra(name):
    """Import ``name``, a package of the ``[test]`` extra (e.g. pyvista): skip when it is
    missing and $CI is unset; in CI (which installs the extra) a missing one is a failure,
    so the round trips it checks cannot pass by being skipped."""
    import importlib
    import os
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        if os.environ.get("CI"):
            pytest.fail(f"CI is set but {name} (in the [test] extra) cannot be imported: {exc}")
        pytest.skip(f"{name} is not installed (pip install \".[test]\")")


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


# --------------------------------------------------------------------------- loopback Dask cluster
# (tests/app/test_batch.py, tests/tiled/: 127.0.0.1 only; every process in its own session, killed in teardown)
def _wait_for(pred, timeout, what):
    t = time.monotonic()
    while not pred():
        if time.monotonic() - t > timeout:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.05)


def _spawn(args, log, env=None):
    return subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
                            env=env)


def _kill(proc):
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    proc.wait(timeout=30)


@pytest.fixture(scope="module")
def loopback_cluster(tmp_path_factory):
    """``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1 (killed in teardown)."""
    dask_cli = shutil.which("dask", path=os.path.dirname(sys.executable)) or shutil.which("dask")
    if dask_cli is None:
        pytest.fail("the 'dask' command of dask[distributed] is not installed")
    d = tmp_path_factory.mktemp("cluster")
    sched_file = d / "scheduler.json"
    log = open(d / "cluster.log", "w")
    procs = []
    try:
        procs.append(_spawn([dask_cli, "scheduler", "--host", "127.0.0.1", "--port", "0",
                             "--no-dashboard", "--scheduler-file", str(sched_file)], log))
        _wait_for(sched_file.exists, 60, "the scheduler")
        time.sleep(0.2)
        import json
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        # the worker configuration igl_hhj/docs/batch.md ("Starting a cluster") recommends
        (d / "dask").mkdir()
        (d / "dask" / "igl-hhj.yaml").write_text(
            "distributed:\n  nanny:\n    pre-spawn-environ:\n      MALLOC_TRIM_THRESHOLD_: null\n")
        env = {**os.environ, "DASK_CONFIG": str(d / "dask")}
        workers = [_spawn([dask_cli, "worker", address, "--host", "127.0.0.1", "--nthreads", "1",
                           "--nworkers", "1", "--no-dashboard", "--name", f"w{i}"], log, env)
                   for i in range(2)]
        procs += workers
        from distributed import Client
        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=90)
            trim = client.run(lambda: os.environ.get("MALLOC_TRIM_THRESHOLD_"))
            assert list(trim.values()) == [None, None], trim
        yield address, workers
    finally:
        for p in reversed(procs):
            _kill(p)
        log.close()


