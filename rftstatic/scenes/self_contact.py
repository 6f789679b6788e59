"""The sheet's self-contact from a scene's ``[contact]`` table (``self``, ``self_thickness``,
``self_factor``): the thickness and its checks against the mesh (and a remeshed run's ``h_lower``), the
automatic stiffness, the :class:`~rftstatic.contact.self_contact.law.SelfContact` of a model."""

from __future__ import annotations

import numpy as np

from rftstatic.scenes.options import contact_options
from rftstatic.scenes.schema import Scene

__all__ = ["SELF_THICKNESS_M", "REMESH_THICKNESS_SHARE", "build_self_contact"]


SELF_THICKNESS_M = 5e-4
"""Default self-contact thickness [m] (0.05 cm) when the material gives none: within the 0.2-1 mm of
woven fabrics and ARCSim's 1 mm repulsion thickness, and below half the 1 cm edges of the paper's
drape meshes."""


REMESH_THICKNESS_SHARE = 0.25
"""Largest self-contact thickness of a remeshed run, as a share of ``remesh.h_lower``: the advancing-front
meshes' shortest edges are about half the target size, and the thickness must stay below half of those."""


def build_self_contact(scene: Scene, mesh, material, kernels: str | None = None):
    """The sheet's self-contact (:class:`~rftstatic.contact.self_contact.law.SelfContact`) when
    ``contact.self = true``, else None. Thickness ``contact.self_thickness`` [scene length] (default
    the material's thickness, else :data:`SELF_THICKNESS_M`); stiffness
    :func:`~rftstatic.contact.self_contact.law.auto_stiffness` times ``contact.self_factor``; their ranges are
    declared (:class:`~rftstatic.scenes.contact_options.ContactOptions`), the checks against the mesh are here.
    ``kernels``: the run's kernel back end (:func:`rftstatic.scenes.build.run_kernels`)."""
    contact = contact_options(scene)
    if not contact.self:
        if contact.self_friction > 0:
            raise scene.error("contact.self_friction", f"{contact.self_friction!r} needs the self-contact: set "
                              "contact.self = true, or contact.self_friction = 0")
        return None
    from rftstatic.contact.self_contact.law import SelfContact, auto_stiffness

    u = scene.units.length
    if contact.self_thickness is None:
        d = float(material.info.get("thickness", SELF_THICKNESS_M))
        key, shown = "material.thickness" if "thickness" in material.info else "contact.self_thickness", d / u
        if not d > 0:
            raise scene.error(key, f"{shown!r} is not a positive thickness; give a thickness > 0")
    else:
        d, key, shown = contact.self_thickness, "contact.self_thickness", scene.get("contact.self_thickness")
    P = mesh.corners  # each element's own flat shape (a sewn mesh's chart X need not be one)
    smallest = float(np.linalg.norm(P[:, [1, 2, 0]] - P, axis=2).min())
    h_lower = scene.get("remesh.h_lower") if scene.get("remesh") is not None else None
    if isinstance(h_lower, (int, float)) and d > REMESH_THICKNESS_SHARE * h_lower * u:
        raise scene.error(key, f"{shown!r} is above {REMESH_THICKNESS_SHARE:g} of remesh.h_lower = {h_lower:g} (scene length "
                          "units): the remeshed meshes' shortest edges (about half h_lower) must stay above twice the "
                          "thickness; give a thinner thickness or a larger remesh.h_lower")
    if d > 0.5 * smallest:
        raise scene.error(key, f"{shown!r} is above half the smallest edge of the mesh ({smallest / u:.4g} / 2 = "
                          f"{0.5 * smallest / u:.4g}, scene length units): the self-contact would push apart "
                          "neighbours that are not in contact; give a thinner thickness or a coarser mesh")
    if not material.weight > 0:
        raise scene.error("contact.self", "true needs material.weight > 0 (the self-contact stiffness is sized "
                          "by the sheet's weight)")
    k = auto_stiffness(weight=material.weight, node_area=float(mesh.node_area.mean()), thickness=d,
                       factor=contact.self_factor)
    friction = None
    if contact.self_friction > 0:  # the slip length as on obstacles: a share of the sheet's size
        from rftstatic.contact.friction import SLIP_LENGTH, FrictionLaw

        mu = np.array([contact.self_friction])
        friction = FrictionLaw(mu, mu, eps=SLIP_LENGTH * float(np.ptp(mesh.X, axis=0).max()))
    try:
        return SelfContact(mesh, d, k, kernels=kernels, friction=friction)
    except ValueError as exc:
        raise scene.error(key, f"{shown!r}: {exc}") from None
