"""Layer ``io``: what a run writes: summary.json, VTU/PVD files, PNG views and charts, all atomically.

Imports from ``scenes`` and below.
"""
