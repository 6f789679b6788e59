import numpy as np
import pytest

from rftstatic import material
from rftstatic.mesh import trimesh as mesh
from rftstatic.model import model


@pytest.fixture
def wool():
    return material.preset("wool-kang-yu")


def clamped_strip(nx=21, ny=5, *, element="RFT6", pattern="right", membrane=True):
    """Kang & Yu's 5 x 1 cm wool strip (§4.1), clamped at x = 0, under its weight, in SI."""
    m = mesh.rectangle(0.05, 0.01, nx, ny, origin=(0.0, -0.005), pattern=pattern)
    mat = material.preset("wool-kang-yu")
    sup = model.Supports(m.nodes_in_box(0, 0, -1, 1), np.zeros(0, int), np.zeros((m.n_nodes, 3), bool))
    return model.Model(m, mat, element=element, supports=sup, load=model.gravity_load(m, mat.weight),
                       membrane=membrane)
