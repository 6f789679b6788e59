"""Layer ``mesh``: the flat reference mesh (:class:`~rftstatic.mesh.trimesh.TriMesh`), its structured
generators, meshio file I/O and the advancing-front mesher (:mod:`rftstatic.mesh.mesher`).

Imports only the base modules (units, material, errors); every layer above may use it.
"""

GRADATION = 1.3
"""Default gradation limit of a size field [-]: neighbouring sizes one element apart differ by at most this
ratio. The one source of this default (the mesher's background grid, the remeshing size field and drivers,
the scenes' ``remesh.gradation``); here, in the light package module, so that reading it loads no mesher."""
