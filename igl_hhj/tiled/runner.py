"""Running the tiles: in this process, or as Dask tasks (an embedded ``LocalCluster`` by
default, a running cluster by address), with retries, a progress bar and resume.

Order of work
-------------
1. the plan (:func:`igl_hhj.tiled.partition.plan_tiles`), kept in ``OUT/.work``;
2. the **pilots**: tiles 0 and 1 (:data:`PILOTS`) with the overlap of the largest
   radius the vertex stage can choose (:func:`igl_hhj.tiled.reach.radius_bound`; starting
   them at the caller's radius and regrowing cost 2.6 instead of 1.6 times a tile's
   faces on a jittered torus, where the stage chose 17–21, as on most real meshes of
   the decay table); the largest radius they chose on their grown tiles sets the first
   overlap of every other tile (:func:`igl_hhj.tiled.tile.rings_for`);
3. the other tiles, each regrown by :func:`igl_hhj.tiled.tile.compute_tile` if the
   radius its vertex stage chose needs more rings.

Every tile's overlap is thus a function of the mesh and the options only (not of
which worker finished first), so the results are the same bits on every run, with
any number of workers.  A two-pass mode (global parameters reduced from the cores,
e.g. a scale per connected component) is one more :func:`run_tiles` round: a task
that returns statistics instead of writing, a reduction, and ``params`` with the
reduced values for the second round.
"""
from __future__ import annotations

import os
import sys
import time

from . import reach
from .partition import Plan
from .store import FileStore
from .tile import compute_tile, rings_for

PILOTS = 2
"""Tiles computed first; the largest radius their vertex stage chose sets the other
tiles' first overlap.  Two, so
that the two workers of a small machine both work meanwhile; a constant, so that every
tile's overlap (and so its bits) does not depend on the number of workers."""

__all__ = ["run_tiles", "Progress", "open_client"]


class Progress:
    """tqdm bar over the core faces on a terminal (``enabled`` None: when stderr is one),
    one line per tile when asked for explicitly on a non-terminal stream."""

    def __init__(self, total, enabled=None, stream=None, unit="face"):
        self.stream = stream or sys.stderr
        tty = getattr(self.stream, "isatty", lambda: False)()
        self.enabled = tty if enabled is None else bool(enabled)
        self.bar, self.done, self.total = None, 0, total
        if self.enabled and tty:
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=total, unit=unit, unit_scale=True, file=self.stream,
                                dynamic_ncols=True, desc="tiles")
            except ImportError:
                pass

    def update(self, stats):
        self.done += stats["core_faces"]
        if self.bar is not None:
            self.bar.update(stats["core_faces"])
        elif self.enabled:
            print(f"tile {stats['tile']}: {stats['faces']} faces computed for {stats['core_faces']} "
                  f"({stats['rings']} rings), {stats['seconds']:.1f} s  [{self.done}/{self.total}]",
                  file=self.stream, flush=True)

    def close(self):
        if self.bar is not None:
            self.bar.close()


_PLANS: dict = {}


def _tile_task(source, plan_dir, out_dir, t, params):
    """The Dask task: compute tile t, write its rows and its marker, return its stats."""
    plan = _PLANS.get(plan_dir)
    if plan is None:
        plan = _PLANS[plan_dir] = Plan.load(plan_dir)
    rows, values, stats = compute_tile(source, plan, t, params)
    FileStore(out_dir).write(rows, values, stats)
    return stats


def open_client(client=None, scheduler=None, workers=None, retries=2, n_tasks=None):
    """``(client, owned)``: the given client, one connected to ``scheduler``, or an embedded
    ``LocalCluster`` of ``workers`` single-threaded processes (default: the machine's
    cores); ``owned`` lists what to close afterwards."""
    if client is not None:
        return client, []
    try:
        from distributed import Client
    except ImportError:
        from ..errors import install_hint
        raise ImportError(f"tiled curvature on Dask needs dask.distributed: {install_hint('distributed')} "
                          f"(or workers=0: in this process)") from None
    if scheduler is not None:
        try:
            c = Client(scheduler)
        except (OSError, TimeoutError, ValueError) as exc:
            raise ValueError(f"cannot connect to the Dask scheduler at {scheduler}: "
                             f"{' '.join(str(exc).split())[:200]}") from None
        return c, [c]
    from ..batch.run import _local_cluster, _machine_cores
    n = workers or _machine_cores()
    if n_tasks:
        n = max(1, min(n, n_tasks))
    cluster = _local_cluster(n, retries)
    c = Client(cluster)
    return c, [c, cluster]


def _run_in_process(todo, source, plan, store, params, on_done):
    for t in todo:
        rows, values, stats = compute_tile(source, plan, t, params)
        store.write(rows, values, stats)
        on_done(stats)


def _run_on_dask(client, todo, source, plan, store, params, on_done, retries):
    from distributed import as_completed
    token = time.perf_counter_ns()
    futures = [client.submit(_tile_task, source, plan.directory, str(store.directory), t, params,
                             key=f"igl-hhj-tile-{t}-{token}", retries=retries, pure=False)
               for t in todo]
    try:
        for fut in as_completed(futures):
            on_done(fut.result())
    finally:
        client.cancel([f for f in futures if not f.done()])


def run_tiles(source, plan, store, params, *, client=None, retries=2, progress=None):
    """Compute every tile of ``plan`` that ``store`` has no marker for.

    Parameters
    ----------
    source : :class:`igl_hhj.tiled.source.MeshSource`
    plan : :class:`igl_hhj.tiled.partition.Plan`
    store : :class:`igl_hhj.tiled.store.FileStore` (required with ``client``) or ``ArrayStore``
    params : dict, those of :func:`igl_hhj.tiled.tile.compute_tile` but ``rings``; with
        ``overlap`` (None: the rule, regrown per tile; an int: that many rings, fixed)
    client : distributed.Client, optional (None: in this process)

    Returns
    -------
    stats : dict {tile: stats} of every tile (finished earlier or now)
    computed : list of the tiles computed by this call, in the order they finished
    """
    stats = {t: s for t in range(plan.n_tiles) if (s := store.done(t)) is not None}
    bar = Progress(plan.n_faces, progress)
    for s in stats.values():
        bar.update(s)

    computed = []

    def on_done(s):
        stats[s["tile"]] = s
        computed.append(s["tile"])
        bar.update(s)

    def run(todo, p):
        if not todo:
            return
        if client is None:
            _run_in_process(todo, source, plan, store, p, on_done)
        else:
            _run_on_dask(client, todo, source, plan, store, p, on_done, retries)

    try:
        if params.get("overlap") is not None:
            p = dict(params, rings=int(params["overlap"]), fixed=True)
            run([t for t in range(plan.n_tiles) if t not in stats], p)
        else:
            bound = reach.overlap_rings(reach.radius_bound(params["radius"]), params["eps"])
            p = dict(params, rings=bound, rings_bound=bound, fixed=False)
            pilots = list(range(min(PILOTS, plan.n_tiles)))
            run([t for t in pilots if t not in stats], p)
            first = rings_for(max(stats[t]["radius_tile_max"] for t in pilots), p)
            run([t for t in range(len(pilots), plan.n_tiles) if t not in stats], dict(p, rings=first))
    finally:
        bar.close()
    return stats, computed


def source_key(path):
    """Identity of an input file for resume: path, size, modification time."""
    st = os.stat(path)
    return [os.path.abspath(path), st.st_size, st.st_mtime_ns]
