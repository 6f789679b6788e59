"""Fixtures of the self-contact tests: ``backend`` (a test runs on the numpy path and on the compiled (numba)
twins), ``random_pairs`` and ``central_differences`` (the pair geometry's random inputs and its finite
differences)."""

import numpy as np
import pytest

from rftstatic.contact.self_contact import distance


@pytest.fixture(params=["numpy", "numba"])
def backend(request, monkeypatch):
    """Forces the self-contact loops onto one path (``distance.compiled_for``)."""
    if request.param == "numba":
        pytest.importorskip("numba")
    compiled = request.param == "numba"
    monkeypatch.setattr(distance, "compiled_for", lambda n, choice=None: compiled)
    return request.param


def _random_pairs(kind, n, seed, parallel_every=8):
    """``(n, 4, 3)`` random pairs [m] of ``kind`` ``"pt"`` or ``"ee"``; for edge pairs one in ``parallel_every``
    exactly (anti-)parallel, so that every closest feature occurs."""
    rng = np.random.default_rng(seed)
    x4 = rng.standard_normal((n, 4, 3))
    if kind == "ee":
        m = n // parallel_every
        d = rng.standard_normal((m, 3))
        x4[:m, 1] = x4[:m, 0] + d
        x4[:m, 3] = x4[:m, 2] + rng.choice([-1.0, 0.5, 2.0], size=(m, 1)) * d
    return x4


def _central_differences(fun, x4, h=1e-6):
    """Central differences of ``fun (P, 4, 3) -> (P, ...)`` along every coordinate: ``(P, 12, ...)``."""
    cols = []
    for m in range(12):
        k, i = divmod(m, 3)
        xp, xm = x4.copy(), x4.copy()
        xp[:, k, i] += h
        xm[:, k, i] -= h
        cols.append((fun(xp) - fun(xm)) / (2 * h))
    return np.stack(cols, axis=1)


@pytest.fixture
def random_pairs():
    """:func:`_random_pairs`: ``random_pairs(kind, n, seed, parallel_every=8)``."""
    return _random_pairs


@pytest.fixture
def central_differences():
    """:func:`_central_differences`: ``central_differences(fun, x4, h=1e-6)``."""
    return _central_differences
