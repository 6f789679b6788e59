"""Layer ``app``: one driver per analysis type (static, dynamic, relax, remeshed).

Imports from ``io`` and below; the command line and the benchmarks sit on top of it.
"""
