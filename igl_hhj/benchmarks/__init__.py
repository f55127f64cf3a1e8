"""Benchmark scripts (run as ``python -m igl_hhj.benchmarks.NAME``); each exposes ``run()``."""


def progress(iterable, desc, unit, enabled=True):
    """``iterable`` wrapped in a tqdm progress bar when ``enabled`` and tqdm is
    installed (benchmark extra); the plain iterable otherwise."""
    if not enabled:
        return iterable
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is in the benchmark extra
        return iterable
    return tqdm(iterable, desc=desc, unit=unit, disable=None)  # no bar frames in redirected logs
