"""The ``[contact]`` table of a scene, declared once (:mod:`rftstatic.optionspec`): the penalty contact with
the obstacles (:class:`~rftstatic.contact.penalty.PenaltyContact`, built by
:func:`rftstatic.scenes.build.build_contact`) and the sheet's self-contact
(:func:`rftstatic.scenes.self_contact.build_self_contact`).

The scene schema, ``python -m rftstatic options contact`` and the scene -> SI conversion
(:func:`rftstatic.scenes.options.contact_options`) are generated from :class:`ContactOptions`. The checks
that need the mesh (a self-contact thickness below half the smallest edge and a share of ``remesh.h_lower``)
stay where the mesh is known.
"""

from __future__ import annotations

from dataclasses import dataclass

from rftstatic.optionspec import check, option

__all__ = ["ContactOptions", "MAX_SMOOTHING"]

MAX_SMOOTHING = 1.0
"""Widest C2 onset of the penalty contact, in mean element sizes (default 0.05): the sheet rests about this
far above the obstacle, and a wider onset is no longer a contact (at 1e300 its energy overflows)."""


@dataclass(frozen=True, kw_only=True)
class ContactOptions:
    """``[contact]`` of a scene, in SI. A bad value raises :class:`~rftstatic.errors.ParameterError` naming
    ``contact.<field>``."""

    penalty: float | None = option(None, 'penalty stiffness ("auto": from the fabric\'s rigidities, weight and '
                                   "element size, times contact.factor)", kind="float",
                                   unit="stiffness_volumetric", low=0.0, open_low=True)
    factor: float = option(1.0, "multiplier of the automatic penalty", low=0.0, open_low=True)
    hold_inplane: bool | None = option(None, 'hold the in-plane rigid modes of a sheet on its support ("auto": '
                                       "yes on a frictionless support, no with friction, which holds them)",
                                       kind="bool")
    smoothing: float = option(0.05, "width of the C2 penalty onset (0: the plain quadratic penalty); the sheet "
                              "rests about that far above the obstacle", unit="element_sizes", low=0.0,
                              high=MAX_SMOOTHING)
    friction: float = option(0.0, "Coulomb friction coefficient mu of the sheet on the obstacles, static and "
                             "kinetic (0: frictionless)", low=0.0)
    friction_static: float | None = option(None, 'static friction coefficient ("auto": contact.friction)',
                                           kind="float", low=0.0)
    friction_kinetic: float | None = option(None, 'kinetic friction coefficient ("auto": contact.friction), at '
                                            "most the static one", kind="float", low=0.0)
    self: bool = option(False, "self-contact of the sheet: its layers never pass through each other")
    self_thickness: float | None = option(None, 'self-contact thickness ("auto": material.thickness, else '
                                          "0.05 cm); below half the smallest edge", kind="float", unit="length",
                                          low=0.0, open_low=True)
    self_factor: float = option(1.0, "multiplier of the automatic self-contact stiffness", low=0.0, open_low=True)
    self_friction: float = option(0.0, "Coulomb friction coefficient mu between the sheet's layers in self-contact "
                                  "(lagged by the static Newton solves; 0: frictionless); needs contact.self",
                                  low=0.0)

    def __post_init__(__dataclass_self__):
        check(__dataclass_self__, "contact")
