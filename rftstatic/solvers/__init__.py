"""Layer ``solvers``: linear solvers, load-scaled Newton, explicit central differences, the stable time
step, dynamic relaxation, the static route that chains them, and checkpoints.

Imports from ``contact`` and below.
"""
