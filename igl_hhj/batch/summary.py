"""The summary of a batch (``summary.csv``, ``summary.parquet``) and its progress display."""
from __future__ import annotations

import csv
import math
import os
import sys
from pathlib import Path

from .jobs import SUMMARY_COLUMNS, TMP_MARK


def _fmt(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if math.isnan(v) else repr(v)
    return str(v)


def write_summary(rows, outdir):
    """``OUTDIR/summary.csv`` (atomically) and ``summary.parquet`` if pyarrow is installed.

    Returns the list of files written.
    """
    outdir = Path(outdir)
    path = outdir / "summary.csv"
    tmp = outdir / f".summary.{os.getpid()}{TMP_MARK}.csv"
    with open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(SUMMARY_COLUMNS)
        for r in rows:
            w.writerow([_fmt(r.get(c)) for c in SUMMARY_COLUMNS])
    os.replace(tmp, path)
    written = [path]
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return written
    cols = {}
    for c in SUMMARY_COLUMNS:
        vals = [r.get(c) for r in rows]
        vals = [None if v in ("", None) else v for v in vals]
        if c in ("vertices", "faces", "peak_memory", "nan_values"):
            cols[c] = pa.array([None if v is None else int(v) for v in vals], pa.int64())
        elif c in ("path", "output", "status", "error", "warnings", "polygons"):
            cols[c] = pa.array([None if v is None else str(v) for v in vals], pa.string())
        else:
            cols[c] = pa.array([None if v is None else float(v) for v in vals], pa.float64())
    ptmp = outdir / f".summary.{os.getpid()}{TMP_MARK}.parquet"
    pq.write_table(pa.table(cols), ptmp)
    os.replace(ptmp, outdir / "summary.parquet")
    return written + [outdir / "summary.parquet"]


class _Progress:
    """tqdm bar (meshes done / failed, rate, ETA) on a terminal, one plain line per mesh otherwise."""

    def __init__(self, total, enabled=True, stream=None):
        self.stream = stream or sys.stderr
        self.total, self.done, self.failed = total, 0, 0
        self.bar = None
        self.enabled = enabled
        if enabled and getattr(self.stream, "isatty", lambda: False)():
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=total, unit="mesh", file=self.stream, dynamic_ncols=True)
            except ImportError:
                pass

    def update(self, row):
        self.done += 1
        self.failed += row["status"] in ("error", "timeout")
        if row.get("warnings") and row["status"] != "skipped":   # also with -q: warnings are news
            self._write(f"igl-hhj: warning: {row['path']}: {row['warnings']}")
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.set_postfix(failed=self.failed, refresh=False)
            self.bar.update(1)
            return
        faces = f"{row['faces']} faces" if row.get("faces") not in (None, "") else ""
        secs = f"{float(row['seconds']):.2f} s" if row.get("seconds") not in (None, "") else ""
        line = f"[{self.done}/{self.total}] {row['status']:<7} {row['path']}  {faces}  {secs}".rstrip()
        if row.get("error"):
            line += f"  ({row['error']})"
        print(line, file=self.stream, flush=True)

    def _write(self, line):
        if self.bar is not None:
            self.bar.write(line, file=self.stream)
        else:
            print(line, file=self.stream, flush=True)

    def close(self):
        if self.bar is not None:
            self.bar.close()
