"""Layer ``model``: a :class:`~rftstatic.model.model.Model` (mesh, patches, material, supports, loads,
contact law, constant matrices) built once per mesh, the sparse assembly plan and the load terms.

Imports from ``element``, ``mesh`` and the base modules only.
"""
