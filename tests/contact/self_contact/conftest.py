"""The ``backend`` fixture: a test runs on the numpy path and on the compiled (numba) twins."""

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
