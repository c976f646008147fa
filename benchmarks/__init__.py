"""Benchmarks: the ``react3d bench`` runner and its scene sets (package data), plus standalone
benchmark scripts (``python3 benchmarks/bench_*.py``) that print a table and write JSON."""
