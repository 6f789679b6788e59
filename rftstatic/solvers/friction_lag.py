"""The lag iteration of static friction (:mod:`rftstatic.contact.friction`): Newton at one load factor, the lag
committed at its solution, Newton again, until the normal forces and the sticking set settle.

The lag is State: ``state.contact_history["friction"]`` (checkpointed with it); the penalty law reads it through
the solve's candidate list (``state.candidates.friction``), which :func:`link` points at it.
"""

from __future__ import annotations

import logging

import numpy as np

from rftstatic.contact.friction import anchored_lag, commit, initial_lag
from rftstatic.contact.self_contact.friction import anchored_pairs_lag, commit_pairs, empty_pairs_lag
from rftstatic.errors import ConvergenceError

log = logging.getLogger(__name__)

KEY = "friction"
"""The lag's key in ``State.contact_history``."""

SELF_KEY = "self_friction"
"""The key of the lag of the friction between layers (:mod:`rftstatic.contact.self_contact.friction`)."""

LAG_ITERATIONS = 12
"""Most Newton solves at one load factor while the lag settles."""

LAG_TOL = 1e-2
"""The lag has settled when the normal forces changed by less than this share of the largest one and either no
node changed between sticking and sliding or the last solve with the committed lag moved no node by more than the
slip length (sliding nodes trail their anchors by it: the same state again)."""


def law_of(model):
    """The model's friction law, or None (no penalty contact, or frictionless)."""
    return getattr(model.contact, "friction", None) if model.contact is not None else None


def self_law_of(model):
    """The friction law between layers of the model's self-contact, or None."""
    return getattr(model.self_contact, "friction", None) if getattr(model, "self_contact", None) is not None else None


def active(model) -> bool:
    """Whether the model has any lagged friction: on obstacles or between layers."""
    return law_of(model) is not None or self_law_of(model) is not None


def link(model, state, U) -> None:
    """Make the lag (the initial one, :func:`~rftstatic.contact.friction.initial_lag`, if the State has none) the
    one the solve's contact evaluations see; likewise the lag between layers (none before the first commit)."""
    slaw = self_law_of(model)
    if slaw is not None and state.self_pairs is not None:
        lag = state.contact_history.get(SELF_KEY)
        if lag is None:
            lag = state.contact_history[SELF_KEY] = empty_pairs_lag(slaw)
        state.self_pairs.friction = lag
    law = law_of(model)
    if law is None or state.candidates is None:
        return
    lag = state.contact_history.get(KEY)
    if lag is None:
        lag = state.contact_history[KEY] = initial_lag(law, model.contact, model.positions(U), model.load)
    state.candidates.friction = lag


def anchor(model, state, U) -> None:
    """Anchor (and link) the lag at the relaxed displacements ``U (N, 3)`` [m] before a Newton handover of the
    relaxation route (:func:`~rftstatic.contact.friction.anchored_lag`; nothing without friction): the relaxation's
    impulses held the sheet where it rests, the lag holds it there for Newton."""
    law, slaw = law_of(model), self_law_of(model)
    if law is not None:
        state.contact_history[KEY] = anchored_lag(law, model.contact, model.positions(U))
    if slaw is not None:  # the pairs' impulses held the layers where they rest: anchored there likewise
        state.contact_history[SELF_KEY] = anchored_pairs_lag(slaw, model.self_contact, model.positions(U),
                                                             state.self_pairs)
    link(model, state, U)  # the tangent of the stability check before the handover sees the anchored lag


def handover_kinetic(model, given: float | None) -> float:
    """The kinetic energy / its peak at which the relaxation route first hands over to Newton: ``given``
    (``solver.handover_kinetic``), else :data:`~rftstatic.solvers.options.HANDOVER_KINETIC` without friction and
    :data:`~rftstatic.solvers.options.HANDOVER_KINETIC_FRICTION` with it (:func:`anchor` sets the stick anchors
    there)."""
    from rftstatic.solvers.options import HANDOVER_KINETIC, HANDOVER_KINETIC_FRICTION

    if given is not None:
        return float(given)
    return HANDOVER_KINETIC if law_of(model) is None and self_law_of(model) is None else HANDOVER_KINETIC_FRICTION


def predict(model, state, lam_to: float) -> None:
    """Scale the normal forces committed at load factor ``lag["lam"]`` to the solve at ``lam_to`` (the forces a
    growing load presses with: lagged unscaled, a sheet held at one load factor would slide at the next before
    the lag caught up). The committed forces stay as they were, so a cut back scales them again."""
    for key in (KEY, SELF_KEY):
        lag = state.contact_history.get(key) if active(model) else None
        if lag is not None and lag["lam"] > 0:
            lag["normal_force"] = lag["committed_force"] * (lam_to / lag["lam"])


def settle(model, state, nt, lam, solve):
    """Commit the lag at the converged Newton result ``nt`` and solve again (``solve(U)`` -> a new result at the
    same load) until it settles (:data:`LAG_TOL`): ``(result, iterations of the extra solves)``, the result's lag
    committed. A solve that does not converge is returned as it is (the caller cuts back or fails)."""
    law, slaw = law_of(model), self_law_of(model)
    eps = min(v.eps for v in (law, slaw) if v is not None)
    its = 0
    moved = np.inf  # the largest nodal move of the last re-solve [m]
    for k in range(LAG_ITERATIONS):
        x = model.positions(nt.U)
        change = {"normal_force": 0.0, "stick_changes": 0}
        if law is not None:
            lag, change = commit(law, model.contact, state.contact_history[KEY], x, lam)
            state.contact_history[KEY] = state.candidates.friction = lag
        if slaw is not None:
            lag, more = commit_pairs(slaw, model.self_contact, state.contact_history[SELF_KEY], x, state.self_pairs,
                                     lam)
            state.contact_history[SELF_KEY] = state.self_pairs.friction = lag
            change = {"normal_force": max(change["normal_force"], more["normal_force"]),
                      "stick_changes": change["stick_changes"] + more["stick_changes"]}
        log.debug("friction lag %d at load factor %.6g: %s, moved %.3g m", k, lam, change, moved)
        if change["normal_force"] < LAG_TOL and (change["stick_changes"] == 0 or moved < eps):
            break  # a fixed point: the committed lag gives back the state it was committed at
        again = solve(nt.U)
        its += again.iterations
        if not again.converged:
            return again, its
        moved = float(np.abs(again.U - nt.U).max())
        nt = again
    else:
        lag = state.contact_history.get(KEY, {"nodes": np.zeros(0, int)})
        share = float(np.mean(lag["slid"])) if lag["nodes"].size else 0.0
        mu = np.unique(lag["mu"]) if lag["nodes"].size else np.zeros(0)
        raise ConvergenceError(
            f"load factor {lam:.6g}: friction does not hold the sheet: the normal forces and the sticking set did not "
            f"settle in {LAG_ITERATIONS} solves, {share:.0%} of the {lag['nodes'].size} contact nodes sliding "
            f"(mu = {', '.join(f'{m:g}' for m in mu)}). Where the tangential load exceeds mu times the normal force "
            "(a sheet on a plane steeper than its friction angle) there is no static equilibrium: run it as a dynamic "
            "scene, or raise contact.friction", None)
    return nt, its


def sliding_share(model, state) -> float:
    """Share of the lagged contact nodes that slid at the last commit (0 without friction)."""
    lag = state.contact_history.get(KEY) if law_of(model) is not None else None
    if lag is None or lag["nodes"].size == 0:
        return 0.0
    return float(np.mean(lag["slid"]))


def explain(model, state, exc) -> None:
    """Add to the message of a failed static solve ``exc`` (a ConvergenceError) what the friction did at the last
    committed state: the share of its contact nodes that had slid and what that means."""
    lag = state.contact_history.get(KEY) if law_of(model) is not None else None
    if lag is None or lag["nodes"].size == 0 or "friction" in str(exc):
        return
    law = law_of(model)
    exc.args = (f"{exc}. With friction (mu static {', '.join(f'{m:g}' for m in np.unique(law.mu_static))}, kinetic "
                f"{', '.join(f'{m:g}' for m in np.unique(law.mu_kinetic))}) {sliding_share(model, state):.0%} of the "
                f"{lag['nodes'].size} contact nodes had slid at the last equilibrium: where the tangential load exceeds "
                "mu times the normal force (a sheet on a plane steeper than its friction angle) there is no static "
                "equilibrium; run it as a dynamic scene, or raise contact.friction",) + exc.args[1:]
