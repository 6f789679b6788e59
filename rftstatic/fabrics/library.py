"""The fabric library: named presets, each with its source and its values in the units as published.

A preset's ``values`` are the model's rigidities in its ``units`` (``C_*`` [force/length], ``B_*``
[force length], ``weight`` [force/area]) and/or lab keys (:mod:`rftstatic.fabrics.lab`, in the
instrument's units); :func:`preset_material` converts them exactly as a scene's ``[material]`` table
is converted. Nothing here is invented: a fabric enters the library only with a source that gives
every value it holds (table and page), and derived values (the twisting rigidity where none was
measured) follow the documented rules of :mod:`rftstatic.fabrics.lab`.

``python -m rftstatic fabrics`` lists the presets with their bending lengths c = (B/W)^(1/3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rftstatic.material import PRESETS as _MATERIAL_PRESETS
from rftstatic.material import voigt_rotation

__all__ = ["FABRICS", "Fabric", "bending_lengths"]


@dataclass(frozen=True)
class Fabric:
    """A library fabric.

    Attributes
    ----------
    name : preset name (``[material] preset = NAME``)
    units : unit system of its model-rigidity values (lab keys carry their own units)
    values : published values (model keys in ``units``, lab keys in their lab units)
    source : citation with the table the values come from
    description : what the fabric is
    measured_dc : published Cusick drape coefficients {"D/d cm": DC [-]} of this fabric, if any
    """

    name: str
    units: str
    values: dict
    source: str
    description: str = ""
    measured_dc: dict = field(default_factory=dict)


FABRICS = {
    "wool-kang-yu": Fabric(
        "wool-kang-yu", _MATERIAL_PRESETS["wool-kang-yu"][0], dict(_MATERIAL_PRESETS["wool-kang-yu"][1]),
        "Kang, T.J. & Yu, W.R. (1995), Drape simulation of woven fabric by using the finite-element method, "
        "J. Text. Inst. 86(4), 635-648; the values as used in Sze & Zhou (2016) §4 (C 1118.2/759.5/41.8 gf/cm, "
        "B 0.083/0.063/0.027 gf cm, 0.019 gf/cm^2)",
        "worsted wool suiting, plain weave (the paper's fabric)"),
}
"""Preset name -> :class:`Fabric`."""


def bending_lengths(material) -> dict:
    """Bending lengths c = (B/W)^(1/3) [m] of a :class:`~rftstatic.material.Material` along its warp and
    weft (material axes) and the flexural rigidities B [N m], from its bending matrix and weight.

    The warp-axis rigidity of a strip: B_11 in the material frame (the un-rotated ``Db``).
    """
    angle = math.radians(material.info.get("warp_angle_deg", 0.0))
    T = voigt_rotation(angle)
    # Db_global = T^T Db_mat T  ->  Db_mat = T^-T Db_global T^-1
    Ti = np.linalg.inv(T)
    Db = Ti.T @ material.Db @ Ti
    w = material.weight
    out = {}
    for k, d in ((0, "warp"), (1, "weft")):
        B = float(Db[k, k])
        out[d] = {"B": B, "c": (B / w) ** (1.0 / 3.0) if w > 0 and B > 0 else None}
    return out
