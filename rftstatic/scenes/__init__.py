"""Layer ``scenes``: the TOML scene schema, its validation, and the one step that turns a scene into a
model and SI solver options.

Imports from ``post`` and below.
"""
