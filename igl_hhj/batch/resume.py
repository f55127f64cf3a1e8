"""Resuming a batch: which outputs are up to date and computed with the same options
(:data:`OPTIONS_FILE`), their rows from the previous summary, and the temporaries that
killed workers left behind."""
from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np

from ..results import CurvatureEstimate
from .compute import default_radius
from .jobs import SUMMARY_COLUMNS, TMP_MARK, _percentile_stats, _row


OPTIONS_FILE = ".igl-hhj-options.json"
"""``OUTDIR/OPTIONS_FILE``: ``{output relative to OUTDIR: {"options": {method, per, radius},
"done": bool, "t": ns}}``.  ``done`` False: the output was being recomputed with ``options``
from time ``t`` on (an output newer than ``t`` has them, e.g. one finished by a worker
after an interrupt; an older one still has its previous, unknown options)."""


def options_key(method, per, radius, feature_angle=None):
    """The options an output depends on (radius None → :func:`default_radius`;
    ``feature_angle`` only when given, so that older outputs keep their key)."""
    key = {"method": method, "per": per,
           "radius": default_radius(method, per) if radius is None else int(radius)}
    if feature_angle is not None:
        key["feature_angle"] = float(feature_angle)
    return key


def describe_options(key):
    if key is None:
        return "unknown options"
    text = f"--method {key['method']} --per {key['per']}"
    text += f" --radius {key['radius']}" if key.get("radius") is not None else ""
    return text + (f" --feature-angle {key['feature_angle']:g}" if key.get("feature_angle") is not None else "")


def _read_options_file(outdir):
    """The entries of ``OUTDIR/OPTIONS_FILE`` ({} when there is none).  A file that is not one
    (not JSON, nested beyond the parser's recursion limit, not an object) is a ``ValueError``
    naming it: a usage error of ``igl-hhj batch``, not a failed computation."""
    import json
    path = Path(outdir) / OPTIONS_FILE
    try:
        with open(path) as fh:
            data = json.load(fh)
    except FileNotFoundError:
        return {}
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the options file: {exc.strerror or exc}") from None
    except (ValueError, RecursionError) as exc:
        why = "nested too deeply" if isinstance(exc, RecursionError) else f"not JSON: {exc}"
        raise ValueError(f"{path}: not an igl-hhj options file ({why}); delete it to recompute "
                         f"every output, or choose another output folder") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path}: not an igl-hhj options file (a JSON {type(data).__name__}, not an "
                         f"object); delete it to recompute every output, or choose another output folder")
    return data


def _write_options_file(outdir, entries):
    import json
    path = Path(outdir) / OPTIONS_FILE
    tmp = Path(outdir) / f".igl-hhj-options.{os.getpid()}.json.new"
    with open(tmp, "w") as fh:
        json.dump(entries, fh, indent=0, sort_keys=True)
    os.replace(tmp, path)


def _made_with(entry, output):
    """The options ``output`` was computed with according to its entry, or None."""
    if not isinstance(entry, dict) or not isinstance(entry.get("options"), dict):
        return None
    opts = entry["options"]        # only a key options_key could have written (else: unknown, recomputed)
    if not {"method", "per", "radius"} <= set(opts) <= {"method", "per", "radius", "feature_angle"} \
            or not all(v is None or isinstance(v, (str, int, float)) for v in opts.values()):
        return None
    if entry.get("done"):
        return entry["options"]
    try:
        return entry["options"] if os.stat(output).st_mtime_ns > int(entry.get("t", 0)) else None
    except (OSError, TypeError, ValueError):
        return None


def _previous_rows(summary):
    try:
        with open(summary, newline="") as fh:
            return {r["path"]: r for r in csv.DictReader(fh)}
    except (OSError, csv.Error, KeyError):
        return {}


def _up_to_date(job):
    try:
        return os.stat(job.output).st_mtime_ns > os.stat(job.path).st_mtime_ns
    except OSError:
        return False


def _skipped_row(job, previous):
    """Status ``skipped``, statistics from the previous summary or else from the ``.npz``."""
    old = previous.get(job.path)
    row = _row(job, "skipped")
    if old is not None and old.get("status") in ("ok", "skipped") and old.get("faces"):
        for c in SUMMARY_COLUMNS[3:]:
            if c not in ("seconds", "cpu_seconds", "peak_memory", "error", "warnings") \
                    and old.get(c) not in (None, ""):
                row[c] = old[c]
    elif job.output.endswith(".npz"):    # finished by a worker after the interrupt reached us
        try:
            with np.load(job.output) as z:
                est = CurvatureEstimate(str(z["per"]), z["k1"], z["k2"], z["H"], z["K"],
                                        None, None, np.zeros(0, np.int64))
                row.update(vertices=len(z["V"]), faces=len(z["F"]), **_percentile_stats(est))
        except (OSError, KeyError, ValueError):
            pass
    return row


def sweep_temporaries(outdir):
    """Remove ``*.igl-hhj-tmp.*`` files (left by killed workers) under ``outdir``."""
    n = 0
    for tmp in Path(outdir).rglob(f"*{TMP_MARK}.*"):
        try:
            tmp.unlink()
            n += 1
        except OSError:
            pass
    return n
