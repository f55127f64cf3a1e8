"""Planning a batch: the input files (files, folders, patterns), their output paths, and
the groups of small files that share one task."""
from __future__ import annotations

import glob
import os
from pathlib import Path

from ..mesh_io import READ_EXTENSIONS
from .jobs import TMP_MARK, Job


FORMATS = ("npz", "ply", "vtp", "vtu")
"""Output formats of ``igl-hhj batch`` (as ``igl-hhj curvature -o``)."""
GROUP_BYTES = 400_000
"""Consecutive input files are grouped into one Dask task until their sizes add up to
this many bytes (about 8k faces of ascii OFF); larger files are one task each.
``python -m igl_hhj.benchmarks.batch`` compares it with one mesh per task (igl_hhj/docs/batch.md, "Throughput")."""
GROUP_MAX = 16
"""At most this many meshes per task."""


def _is_mesh(p):
    """A file the readers read (:data:`igl_hhj.mesh_io.READ_EXTENSIONS`: libigl's formats and
    those of the optional packages; a file whose package is missing becomes an error row
    naming the install, never a silent skip)."""
    return p.is_file() and p.suffix.lower() in READ_EXTENSIONS


def collect_inputs(inputs):
    """Expand files, folders (recursively, :data:`igl_hhj.mesh_io.READ_EXTENSIONS` only) and glob patterns.

    Returns a list of ``(path, root)``: ``root`` is the folder the output path is made
    relative to (the folder given, or the file's own folder).  A path that does not exist
    and is not a pattern is kept (it becomes an ``error`` row).  Raises ``ValueError``
    for a pattern or folder without mesh files.
    """
    found = []
    for item in inputs:
        item = str(item)
        p = Path(item)
        if p.is_dir():
            files = sorted(q for q in p.rglob("*") if _is_mesh(q) and TMP_MARK not in q.name)
            if not files:
                raise ValueError(f"{item}: no mesh files ({', '.join(READ_EXTENSIONS)}) in this folder")
            found += [(q, p) for q in files]
        elif p.exists() or not glob.has_magic(item):
            found.append((p, p.parent))
        else:
            matches = sorted(Path(m) for m in glob.glob(item, recursive=True))
            files = [m for m in matches if _is_mesh(m)]
            for m in matches:
                if m.is_dir():
                    files += sorted(q for q in m.rglob("*") if _is_mesh(q))
            if not files:
                raise ValueError(f"{item}: no mesh files match this pattern")
            found += [(q, q.parent) for q in files]
    seen, unique = set(), []
    for q, root in found:
        key = os.path.abspath(q)
        if key not in seen:
            seen.add(key)
            unique.append((q, root))
    return unique


def plan_jobs(inputs, outdir, fmt="npz"):
    """One :class:`Job` per input mesh: ``OUTDIR/<path relative to the inputs' common
    folder, extension replaced by .fmt>`` (``a/b.off`` → ``OUTDIR/a/b.npz``; two inputs
    that differ only in extension keep it: ``a/b.off.npz``)."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown format {fmt!r} (use {', '.join(FORMATS)})")
    out_abs = os.path.realpath(outdir) + os.sep            # realpath: also through symlinks
    found = [(q, r) for q, r in collect_inputs(inputs)       # outputs are never inputs
             if not os.path.realpath(q).startswith(out_abs)]
    if not found:
        return []
    roots = [os.path.abspath(r) for _, r in found]
    common = Path(os.path.commonpath(roots))
    rels = [Path(os.path.abspath(q)).relative_to(common) for q, _ in found]
    targets = [r.with_suffix("." + fmt) for r in rels]
    count = {}
    for t in targets:
        count[t] = count.get(t, 0) + 1
    jobs = []
    outdir = Path(outdir)
    for (q, _), rel, t in zip(found, rels, targets):
        if count[t] > 1:
            t = rel.with_name(rel.name + "." + fmt)
        try:
            size = q.stat().st_size
        except OSError:
            size = 0
        jobs.append(Job(str(q), str(outdir / t), size))
    return jobs


def group_jobs(jobs, group_bytes=GROUP_BYTES, group_max=GROUP_MAX):
    """Consecutive jobs in groups of total input size ≤ ``group_bytes`` (≤ ``group_max``)."""
    groups, cur, cur_bytes = [], [], 0
    for job in jobs:
        if cur and (cur_bytes + job.size > group_bytes or len(cur) >= group_max):
            groups.append(cur)
            cur, cur_bytes = [], 0
        cur.append(job)
        cur_bytes += job.size
    if cur:
        groups.append(cur)
    return groups
