"""Layer ``element``: the RF triangle itself, independent of any solver.

- :mod:`.patch`: the 6-node patch, image nodes and the constant bending stiffness (Eq. 9-13);
- :mod:`.membrane`: RFT3 (CST) and RFT6 (mid-side averaged) membrane strain, energy, force and tangent;
- :mod:`.explicit_force`: the internal force kernel of the explicit solver;
- compiled (numba) twins of the hot loops, imported lazily.

Imports from ``mesh`` and the base modules only.
"""
