"""Routes as drivers: a route advances a :class:`~rftstatic.model.state.State` and may pause.

A route (the load steps, the arc length, the relaxation route, an explicit run, a remesh cycle) is a
generator function ``route(model, state, options, ...)``: it advances ``state`` in place, keeps its own
position (what it needs to go on from there) in ``state.route[name]``, and ``yield``\\ s a :class:`Pause`
wherever it may be saved and later resumed; its ``return`` value is its record (e.g. a
:class:`~rftstatic.solvers.newton.StaticResult`). Routes compose with ``yield from``. Called on a State
whose ``route`` holds a saved position, a route goes on from there as the uninterrupted one did.

Who drives decides what a pause means: :func:`finish` runs a route to its end and ignores them (the
library call, a test); the app layer hands each pause to a checkpoint saver
(:class:`~rftstatic.solvers.checkpoint.CheckpointSaver`), which writes the State when the pause asks or its
throttle allows. No route knows whether, where or how often it is saved.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Pause:
    """A point where a route's State may be saved and resumed from.

    Attributes
    ----------
    what : where the route stands, for messages (e.g. ``"load factor 0.42, 5 increments"``)
    final : the end of a phase (a converged full load, a relaxation segment's end, a failed handover): saved
        whatever the throttle says
    keep : a snapshot may be kept in memory while the throttle holds it back, to be written on an interrupt
        (a static increment); False for the many cheap pauses of an explicit run (one per step), whose
        State is saved only when due
    step : the explicit step just completed (a saver may save every so many steps), or None
    """

    what: str = ""
    final: bool = False
    keep: bool = True
    step: int | None = None


def finish(route):
    """Run ``route`` (a generator, module docstring) to its end, ignoring its pauses; its return value."""
    while True:
        try:
            next(route)
        except StopIteration as stop:
            return stop.value


def drive(route, on_pause=None):
    """Run ``route`` to its end, calling ``on_pause(pause)`` at each of its pauses; its return value."""
    if on_pause is None:
        return finish(route)
    while True:
        try:
            pause = next(route)
        except StopIteration as stop:
            return stop.value
        on_pause(pause)
