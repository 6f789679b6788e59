"""Read-only objects: a :class:`~rftstatic.model.model.Model` and the parts a solve evaluates (the
self-contact law, the potential loads) are built once and never assigned to afterwards; what a solve
changes lives in its :class:`~rftstatic.model.state.State` (DEVELOPERS.md, "Model, State, options").
"""

from __future__ import annotations


class FrozenError(AttributeError):
    """An assignment to an attribute of a built, read-only object."""


class Frozen:
    """Mixin: after :meth:`_freeze` (the last line of ``__init__``) an assignment to, or deletion of, an
    attribute raises :class:`FrozenError`. ``functools.cached_property`` still fills its cache (it writes
    the instance ``__dict__`` directly): built on first use, constant afterwards."""

    __frozen = False

    def _freeze(self) -> None:
        object.__setattr__(self, "_Frozen__frozen", True)

    def __setattr__(self, name, value):
        if self.__frozen:
            raise FrozenError(f"{type(self).__name__} is read-only once built: cannot set {name!r}; what a solve "
                              "changes belongs in its State (rftstatic.model.state)")
        object.__setattr__(self, name, value)

    def __delattr__(self, name):
        if self.__frozen:
            raise FrozenError(f"{type(self).__name__} is read-only once built: cannot delete {name!r}")
        object.__delattr__(self, name)
