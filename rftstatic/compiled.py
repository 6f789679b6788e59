"""Whether the optional compiled kernels (numba: ``_explicit_numba``, ``_membrane_numba``) can be used."""

from functools import cache


@cache
def numba_available() -> bool:
    """True when numba imports (the ``fast`` extra); the kernels' numpy twins are used otherwise."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True
