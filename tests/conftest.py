"""Shared fixtures. The test folders mirror the package's layers (tests/<layer>/test_*.py)."""

import pytest

from rftstatic import material


@pytest.fixture
def wool():
    return material.preset("wool-kang-yu")
