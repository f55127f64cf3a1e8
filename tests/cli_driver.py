"""Run ``igl-hhj`` commands in a child process under a memory cap.

The child imports numpy, scipy, libigl and ``igl_hhj.cli`` first, then caps its
address space with ``resource.setrlimit(RLIMIT_AS)`` at its current size plus
``extra_mb`` (so the cap bounds what the *command* may allocate, independent of
the libraries' own footprint), and runs each job through ``cli.main`` with file
descriptors 1/2 captured and a per-job alarm.  The test process itself is never
capped.  A job that crashes or hangs the child is named by the progress file.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

_DRIVER = r"""
import json, os, resource, signal, sys, tempfile, time
import numpy, scipy.sparse, scipy.sparse.linalg, igl
import igl_hhj.cli as cli, igl_hhj.curvature, igl_hhj.baselines, igl_hhj.mesh_report
from igl_hhj.capture import flush_c_stdio as _flush_c_stdio

class Timeout(BaseException):
    pass

def on_alarm(*_):
    raise Timeout()

def vm_bytes():
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024

extra, jobs_path, progress_path = int(sys.argv[1]) << 20, sys.argv[2], sys.argv[3]
jobs = json.load(open(jobs_path))
cap = vm_bytes() + extra
resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
signal.signal(signal.SIGALRM, on_alarm)
progress = open(progress_path, "a")
for argv, seconds in jobs:
    progress.write(json.dumps({"start": argv}) + "\n"); progress.flush()
    out, err = tempfile.TemporaryFile(), tempfile.TemporaryFile()
    sys.stdout.flush(); sys.stderr.flush(); _flush_c_stdio()
    saved = os.dup(1), os.dup(2)
    os.dup2(out.fileno(), 1); os.dup2(err.fileno(), 2)
    t = time.perf_counter()
    signal.alarm(seconds)
    try:
        code = cli.main(argv)
    except Timeout:
        code = "timeout"
    finally:
        signal.alarm(0)
        sys.stdout.flush(); sys.stderr.flush(); _flush_c_stdio()
        os.dup2(saved[0], 1); os.dup2(saved[1], 2); os.close(saved[0]); os.close(saved[1])
    dt = time.perf_counter() - t
    out.seek(0); err.seek(0)
    progress.write(json.dumps({"argv": argv, "code": code, "seconds": dt,
                               "out": out.read(4000).decode("utf-8", "replace"),
                               "err": err.read(4000).decode("utf-8", "replace")}) + "\n")
    progress.flush()
"""


def run_capped(jobs, extra_mb=1024, seconds=20, total_timeout=600):
    """Run ``jobs`` (lists of igl-hhj arguments) in one capped child process.

    Returns a list of dicts ``argv, code, seconds, out, err`` (one per job, in
    order).  Raises AssertionError naming the job if the child dies or hangs.
    """
    with tempfile.TemporaryDirectory() as tmp:
        jobs_path = os.path.join(tmp, "jobs.json")
        progress_path = os.path.join(tmp, "progress.jsonl")
        with open(jobs_path, "w") as fh:
            json.dump([[list(map(str, a)), int(seconds)] for a in jobs], fh)
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
                   MKL_NUM_THREADS="1")
        try:
            proc = subprocess.run([sys.executable, "-c", _DRIVER, str(extra_mb), jobs_path,
                                   progress_path], capture_output=True, text=True, env=env,
                                  timeout=total_timeout)
            died = proc.returncode != 0 and f"exit {proc.returncode}: {proc.stderr[-500:]}"
        except subprocess.TimeoutExpired:
            died = f"hung for {total_timeout} s"
        records, started = [], None
        if os.path.exists(progress_path):
            with open(progress_path) as fh:
                for line in fh:
                    r = json.loads(line)
                    if "start" in r:
                        started = r["start"]
                    else:
                        records.append(r)
                        started = None
        assert not died and started is None and len(records) == len(jobs), (
            f"the capped igl-hhj child died ({died}) during {started}")
        return records


def check_outcome(record, ok_codes):
    """Exit code in ``ok_codes``; success: no error line; failure: exactly one
    ``igl-hhj: error:`` line (warnings allowed), no traceback."""
    code, err = record["code"], record["err"]
    lines = [ln for ln in err.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("igl-hhj: error: ")]
    other = [ln for ln in lines if not ln.startswith(("igl-hhj: error: ", "igl-hhj: warning: "))]
    what = f"{record['argv']} -> {code}: {lines[:5]}"
    assert code in ok_codes, what
    assert not other and "Traceback" not in err, what
    assert len(errors) == (0 if code in (0, 1) else 1), what
    return code
