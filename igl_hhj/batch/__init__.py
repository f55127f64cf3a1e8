"""Curvature of whole mesh collections, in-process or on a Dask cluster (``igl-hhj batch``).

One output file per input mesh, with exactly the content ``igl-hhj curvature
-o`` writes for that mesh (both go through :func:`compute_curvature` and
:func:`igl_hhj.mesh_io.write_curvature`), plus ``OUTDIR/summary.csv`` (and
``summary.parquet`` when pyarrow is installed) with one row per input.

Execution
---------
* no ``scheduler``: a handful of files (≤ :data:`IN_PROCESS_MAX_FILES`, or
  ``workers=0``) run in this process; more run on an embedded
  ``distributed.LocalCluster`` of worker *processes* (one thread each), sized
  to the machine;
* ``scheduler="tcp://host:port"``: the meshes are submitted to that Dask
  cluster (``dask scheduler`` + ``dask worker``, dask-jobqueue, Kubernetes,
  ...).  Workers need only ``igl_hhj`` installed and must see the input and
  output paths (shared file system).

Dask does the scheduling, data transfer and worker supervision; this module
only plans the files, groups small meshes into one task (to amortise the
per-task overhead, see :data:`GROUP_BYTES`), and turns every outcome into a
summary row.

Failure isolation
-----------------
Every mesh ends with exactly one row whose ``status`` is ``ok``, ``error``,
``skipped`` or ``timeout``:

* unreadable, corrupt, empty, non-manifold, ... meshes: ``error`` with the
  one-line message of :func:`igl_hhj.mesh_io.read_mesh` /
  :class:`igl_hhj.mesh.TriangleMesh`;
* a worker process that dies (segfault, killed by the OS or by Dask's memory
  monitor) has its tasks re-run by Dask; a task whose workers died more than
  ``distributed.scheduler.allowed-failures`` times (embedded cluster:
  ``retries``) is split into single meshes and re-submitted once more; a
  single mesh that still kills its worker is an ``error`` row;
* ``timeout`` / ``memory_limit``: each mesh runs in a *sandbox* child process
  (one persistent child per worker thread, restarted after a kill) that is
  killed when the mesh takes longer than ``timeout`` seconds (status
  ``timeout``) or its resident memory exceeds ``memory_limit`` bytes
  (``error``, "exceeds the memory limit").

Outputs are written to a temporary file next to the target and renamed
(``os.replace``), so an output either is complete or does not exist;
temporaries left by killed workers (``*.igl-hhj-tmp.*``) are removed at the
end of every run, including an interrupted one.

Resume
------
With ``resume=True`` (default) an input whose output exists and is newer than
the input is not recomputed (status ``skipped``; its statistics are copied
from the previous ``summary.csv`` when it has them) -- provided it was computed
with the same ``method``, ``per`` and ``radius``: ``OUTDIR/.igl-hhj-options.json``
records the options of every output (see :data:`OPTIONS_FILE`); an output
computed with other options, or of unknown options, is recomputed and
:attr:`BatchResult.recomputed` says so.

Modules
-------
:mod:`.compute` (one mesh as ``igl-hhj curvature`` computes it), :mod:`.jobs` (one mesh
as a batch task, its summary row), :mod:`.sandbox` (timeout / memory limits, the Dask
task), :mod:`.plan` (inputs, outputs, groups), :mod:`.resume` (up-to-date outputs and
their options), :mod:`.summary` (``summary.csv``, progress), :mod:`.run`
(:func:`run_batch`).  Every name of ``__all__`` is importable from here.
"""
from __future__ import annotations

from .compute import (ESTIMATORS, MAX_RADIUS, METHOD_LABELS, check_curvature_options, compute_curvature,
                      default_radius)
from .jobs import PERCENTILES, QUANTITIES, SUMMARY_COLUMNS, TMP_MARK, Job, Options, process_mesh
from .plan import FORMATS, GROUP_BYTES, GROUP_MAX, collect_inputs, group_jobs, plan_jobs
from .resume import OPTIONS_FILE, describe_options, options_key, sweep_temporaries
from .run import IN_PROCESS_MAX_FILES, MAX_WORKERS, BatchResult, run_batch
from .sandbox import run_group
from .summary import write_summary

__all__ = ["compute_curvature", "check_curvature_options", "Job", "plan_jobs", "process_mesh",
           "run_batch", "BatchResult", "SUMMARY_COLUMNS", "FORMATS", "IN_PROCESS_MAX_FILES",
           "GROUP_BYTES", "default_radius", "options_key", "describe_options", "OPTIONS_FILE", "MAX_WORKERS",
           "MAX_RADIUS", "ESTIMATORS", "METHOD_LABELS", "GROUP_MAX", "Options", "collect_inputs", "group_jobs",
           "run_group", "write_summary", "sweep_temporaries", "TMP_MARK", "PERCENTILES", "QUANTITIES"]
