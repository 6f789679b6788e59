"""The fabric library: named presets, each with its source and its values in the units as published.

A preset's ``values`` are the model's rigidities in its ``units`` (``C_*`` [force/length], ``B_*``
[force length], ``weight`` [force/area]) and/or lab keys (:mod:`rftstatic.fabrics.lab`, in the
instrument's units); :func:`rftstatic.scenes.material.build_material` converts them as a scene's
``[material]`` table is converted. Nothing here is invented: a fabric enters the library only with a source that gives
every value its ``values`` hold (table and page, or file, commit and row); what the source does not give
is in ``derived`` by a stated rule (``derived_rule``), and the twisting rigidity where none was measured
follows the documented rule of :mod:`rftstatic.fabrics.lab`.

Presets from Feng, Huang, Xu & Wang (2022), "Learning-Based Bending Stiffness Parameter Estimation by
a Drape Tester", ACM Trans. Graph. 41(6), doi:10.1145/3550454.3555464, public data set
``dataset/dataset.csv`` of github.com/DrapeTester/ClothDrapeTester (commit 24a980c0c78d, 618 rows, no
fabric names): ``ctd-<row>-<kind>``, ``row`` the 0-based data row (header excluded, as the repository's
``subspace/train.txt`` indexes it; file line row + 2). What the columns are and which the model takes:
:mod:`rftstatic.fabrics.lab` (``ctd_*`` keys): the density and the linear (small-curvature) bending
rigidities k1 along warp and weft are *published* and used (``values``); the bias k1 and the nonlinear k2
are published but not used by the linear model (``not_used``, verbatim with the file's column names). The warp
and weft k2 enter on request only (``[material] nonlinear_bending = true`` next to the preset: the softening of
:mod:`rftstatic.element.nonlinear_bending`, :func:`nonlinear_values`), so a preset's results do not change.
The five rows are chosen by a rule, not by hand (``tools/select_ctd_fabrics.py``): with the data set's
percentile ranks of the weight and of the mean bending length sqrt(c_warp c_weft), the row nearest (in
the larger of the two rank differences; first row on a tie) to (10, 10) light-soft, (10, 90) light-stiff,
(50, 50) medium, (90, 10) heavy-soft and (90, 90) heavy-stiff.

What the data set does not give is *derived* by a stated rule (``Fabric.derived``, ``derived_rule``), never
silently: the membrane rigidities C_warp, C_weft, C_shear are the library wool's (the library's only
published ones), C12 = B12 = 0, and B_twist = sqrt(B_warp B_weft) / 2 (:func:`rftstatic.fabrics.lab.
default_twist`, the rule for any fabric without a measured twist). Measured effect of the membrane rule
(docs/howto/fabric-data.md): the cantilever does not feel it (bending length within 0.03 % for the
membrane x 0.1 and x 10), the Cusick drape does (``ctd-213-medium``, default mesh: DC 55.4 % -> 42.3 % with
the membrane x 0.1, 62.4 % with x 3): a ``ctd-*`` preset's bending length is the data set's, its DC rests
on the borrowed membrane.

``python -m rftstatic fabrics`` lists the presets with their bending lengths c = (B/W)^(1/3), their
sources, and the quantities that do not come from the source.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rftstatic.material import PRESETS as _MATERIAL_PRESETS
from rftstatic.material import voigt_rotation

__all__ = ["CTD_COLUMNS", "CTD_K2", "CTD_SOURCE", "CTD_TARGETS", "FABRICS", "Fabric", "bending_lengths",
           "nonlinear_values"]


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
    short_source : a short citation for listings
    derived : values the source does not give, by ``derived_rule`` (model keys in ``units``); a quantity
        the ``values`` give is never taken from here
    derived_rule : the rule that gives ``derived`` (and, where neither gives it, B_twist by default)
    not_used : published values of the source that the linear model does not take (the source's names
        and units)
    """

    name: str
    units: str
    values: dict
    source: str
    description: str = ""
    measured_dc: dict = field(default_factory=dict)
    short_source: str = ""
    derived: dict = field(default_factory=dict)
    derived_rule: str = ""
    not_used: dict = field(default_factory=dict)


FABRICS = {
    "wool-kang-yu": Fabric(
        "wool-kang-yu", _MATERIAL_PRESETS["wool-kang-yu"][0], dict(_MATERIAL_PRESETS["wool-kang-yu"][1]),
        "Kang, T.J. & Yu, W.R. (1995), Drape simulation of woven fabric by using the finite-element method, "
        "J. Text. Inst. 86(4), 635-648; the values as used in Sze & Zhou (2016) §4 (C 1118.2/759.5/41.8 gf/cm, "
        "B 0.083/0.063/0.027 gf cm, 0.019 gf/cm^2)",
        "worsted wool suiting, plain weave (the paper's fabric)",
        short_source="Kang & Yu (1995), via Sze & Zhou (2016)"),
}
"""Preset name -> :class:`Fabric` (the ``ctd-*`` presets are added below)."""

CTD_SOURCE = ("Feng, Huang, Xu & Wang (2022), Learning-based bending stiffness parameter estimation by a drape "
              "tester, ACM Trans. Graph. 41(6), doi:10.1145/3550454.3555464; public data set "
              "github.com/DrapeTester/ClothDrapeTester, commit 24a980c0c78da5cc4af36c8b6e67326b96a1de8f, file "
              "dataset/dataset.csv")
"""The data set of the ``ctd-*`` presets (module docstring)."""

CTD_COLUMNS = ("density[kg.m-2]", "linear warp[SI*1e9]", "linear weft[SI*1e9]", "linear diag[SI*1e9]",
               "nonlinear warp[SI*1e12]", "nonlinear weft[SI*1e12]", "nonlinear diag[SI*1e12]")
"""The data set's header, verbatim."""

_CTD_USED = {"density[kg.m-2]": "ctd_density", "linear warp[SI*1e9]": "ctd_B_warp",
             "linear weft[SI*1e9]": "ctd_B_weft"}

CTD_K2 = {"nonlinear warp[SI*1e12]": "ctd_k2_warp", "nonlinear weft[SI*1e12]": "ctd_k2_weft"}
"""The data set's k2 columns and the lab keys that take them (opt-in: :func:`nonlinear_values`)."""

_MEMBRANE_RULE = ("membrane rigidities C_warp, C_weft, C_shear of the library's wool-kang-yu (not in the data set; "
                  "the cantilever does not feel them, the Cusick DC does: docs/howto/fabric-data.md), "
                  "C12 = B12 = 0, B_twist = sqrt(B_warp B_weft) / 2 (not measured)")

CTD_TARGETS = {"light-soft": (10, 10), "light-stiff": (10, 90), "medium": (50, 50), "heavy-soft": (90, 10),
                "heavy-stiff": (90, 90)}
"""Selection targets (percentile of weight, percentile of mean bending length) of the ``ctd-*`` presets."""


def _ctd(row: int, kind: str, published: tuple) -> Fabric:
    """A preset from data row ``row`` (0-based, header excluded) of the data set, ``published`` the row's
    seven values in the file's column order (:data:`CTD_COLUMNS`), as printed in the file."""
    cells = dict(zip(CTD_COLUMNS, published, strict=True))
    wool_units, wool = _MATERIAL_PRESETS["wool-kang-yu"]
    if wool_units != "cm-gf-s":
        raise ValueError("the ctd-* membrane rule takes the wool's rigidities in cm-gf-s")
    tw, tc = CTD_TARGETS[kind]
    return Fabric(
        f"ctd-{row}-{kind}", wool_units, {_CTD_USED[k]: v for k, v in cells.items() if k in _CTD_USED},
        f"{CTD_SOURCE}, data row {row} (0-based, header excluded; file line {row + 2})",
        f"{kind}: the data set's fabric nearest the {tw}th percentile of weight and the {tc}th of mean bending "
        "length (tools/select_ctd_fabrics.py); the data set names no fabric or weave",
        short_source=f"Feng et al. (2022) data set, row {row}",
        derived={k: wool[k] for k in ("C_warp", "C_weft", "C_shear")}, derived_rule=_MEMBRANE_RULE,
        not_used={k: v for k, v in cells.items() if k not in _CTD_USED})


# Each row's seven values copied from dataset/dataset.csv (commit 24a980c) as printed there.
for _fab in (
    _ctd(291, "light-soft", (0.0490, 1078.5, 815.2, 884.8, -2316.3, -1867.0, -898.7)),
    _ctd(12, "light-stiff", (0.0604, 33479.0, 4057.1, 10634.9, -113052.8, -31447.7, -101178.0)),
    _ctd(213, "medium", (0.2023, 14501.9, 10176.5, 17466.7, -26843.8, -35285.0, -27435.6)),
    _ctd(350, "heavy-soft", (0.3873, 7830.1, 4695.5, 7774.6, -13876.9, -6049.8, -9819.1)),
    _ctd(367, "heavy-stiff", (0.3989, 135107.1, 35003.8, 69487.1, -579994.0, -102949.3, -252014.6)),
):
    FABRICS[_fab.name] = _fab
del _fab


def nonlinear_values(fab: Fabric) -> dict:
    """The lab keys of a preset's published k2 (``{"ctd_k2_warp": v, "ctd_k2_weft": v}`` [1e-12 N m^2], as
    printed in the data set), or ``{}`` for a preset whose source gives none."""
    return {key: fab.not_used[col] for col, key in CTD_K2.items() if col in fab.not_used}


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
