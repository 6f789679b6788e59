"""Benchmarks that print wall time and peak memory: ``python -m rftstatic bench [NAME ...]``.

Imports from ``app`` and below; the validation reports may use it. Every child process (a benchmark
in a fresh interpreter, a validation cell) goes through :func:`rftstatic.bench.harness.run_child`.
"""
