"""rftstatic: drape simulation with the rotation-free triangles RFT3 and RFT6.

Implements Sze & Zhou, "An efficient rotation-free triangle for drape/cloth
simulations, Part I", Int. J. Comput. Methods 13(3) 1650021 (2016), and its
predecessor Zhou & Sze, IJNME 89 (2012).

Heavy parts (plotting, linear-solver back ends, the mesher, explicit dynamics)
are imported lazily by the modules that need them, so a scene pays only for
what it uses.
"""

__version__ = "0.1.0"
