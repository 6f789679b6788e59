"""Layer ``mesh``: the flat reference mesh (:class:`~rftstatic.mesh.trimesh.TriMesh`), its structured
generators, meshio file I/O and the advancing-front mesher (:mod:`rftstatic.mesh.mesher`).

Imports only the base modules (units, material, errors); every layer above may use it.
"""
