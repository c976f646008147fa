"""Benchmark scripts (``python3 benchmarks/bench_*.py``) that print a table and write JSON; the
``react3d bench`` runner, its scene sets and the miss-cause tracer are in ``flows/bench/``."""
