"""Layer ``element``: the RF triangle itself, independent of any solver.

- :mod:`.patch`: the 6-node patch, image nodes and the constant bending stiffness (Eq. 9-13);
- :mod:`.kernels`: the membrane strain, stress, energy, force and tangent and the explicit force loop,
  written once; run vectorised with numpy (the loops' twins in :mod:`.kernels_numpy`) or compiled by
  :mod:`._kernels_numba` (numba, imported lazily);
- :mod:`.membrane`: RFT3 (CST) and RFT6 (mid-side averaged) strain-point gradients and the membrane
  operator that the model calls;
- :mod:`.explicit_force`: the internal force kernel of the explicit solver.

Imports from ``mesh`` and the base modules only.
"""
