"""Benchmark scripts (run as ``python -m igl_hhj.benchmarks.NAME``); each exposes ``run()``."""
