"""Layer ``post``: measures of a deformed sheet (drape coefficient, boundary, folds, sharp-fold
indicators) and probe interpolation.

Imports from ``remesh`` and below.
"""
