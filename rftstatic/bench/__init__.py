"""Benchmarks that print wall time and peak memory: ``python -m rftstatic bench [NAME ...]``.

Imports from ``app`` and below; the validation reports may use it.
"""
