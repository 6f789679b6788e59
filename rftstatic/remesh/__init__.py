"""Layer ``remesh``: global adaptive remeshing (§5): the curvature size field (Eq. 28-29), the transfer
of the state to a new mesh and the adaptive static and relaxation drivers.

Imports from ``solvers`` and below; a new mesh's model comes from a factory the caller passes in.
"""
