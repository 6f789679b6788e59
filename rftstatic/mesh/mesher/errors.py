"""Errors raised by the mesher."""


class MeshingError(ValueError):
    """Bad mesher input, or a front that cannot be closed.

    The message names the offending loop, value or location and says what to
    change.  It subclasses :class:`ValueError` so that callers validating
    scene input can catch both alike.
    """
