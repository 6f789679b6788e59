"""The contact-law interface: the one place a contact law (penalty today, friction next) plugs into
both the static and the explicit solver.

A law is the ``contact`` of a :class:`~rftstatic.model.model.Model`. Newton sees it through the
model's energy, residual and tangent (:meth:`Model.energies`, :meth:`Model.residual`,
:meth:`Model.tangent`); the explicit solver through the internal force kernel
(:class:`~rftstatic.element.explicit_force.ForceKernel`), which adds ``law.force``. Both pass the
solve's per-contact object (``new_candidates()``, kept in :attr:`rftstatic.model.state.State.candidates`:
the candidate list of the penalty law, and the place for history such as friction anchors, with
:attr:`~rftstatic.model.state.State.contact_history`). The law itself holds no solve state, so one
Model serves any number of solves.

The explicit solver's *kinematic* treatment of obstacles (§6.3, :mod:`rftstatic.contact.kinematic`) is
not a law of this kind: it projects positions and velocities after each step and needs only the
obstacles.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from rftstatic.contact.penalty import ContactState


@runtime_checkable
class ContactLaw(Protocol):
    """What the solvers ask of a contact law; positions ``x (N, 3)`` [m], ``candidates`` the object
    :meth:`new_candidates` made for this solve (or None: evaluate every node)."""

    def new_candidates(self) -> object:
        """A fresh per-solve object (candidate list, history) for a :class:`~rftstatic.model.state.State`."""

    def evaluate(self, x: np.ndarray, *, tangent: bool = True, candidates=None) -> ContactState:
        """Energy [J], force ``(N, 3)`` [N] (the gradient of the energy), node-diagonal tangent blocks
        ``(N, 3, 3)`` [N/m] (the gradient of the force), gaps ``(N,)`` [m] and the active set."""

    def energy(self, x: np.ndarray, *, candidates=None) -> float:
        """The contact energy [J]."""

    def force(self, x: np.ndarray, *, candidates=None) -> np.ndarray:
        """The gradient of the contact energy ``(N, 3)`` [N] (the explicit loop's per-step call)."""

    def tangent_blocks(self, x: np.ndarray, *, candidates=None) -> np.ndarray:
        """Node-diagonal blocks ``(N, 3, 3)`` [N/m] of the force's gradient."""

    def max_penetration(self, x: np.ndarray) -> float:
        """Largest penetration depth [m] (for ``summary.json``)."""

    def active(self, x: np.ndarray) -> np.ndarray:
        """``(N,)`` bool: nodes in contact."""
