"""A final state that crosses itself is flagged in summary.json's warnings, with the fix for the scene."""

import logging

from rftstatic.io.summary import warn_crossings


def test_no_pairs_no_warning():
    summary = {"self_intersections": {"pairs": 0}, "warnings": []}
    warn_crossings(summary, self_contact=False)
    assert summary["warnings"] == []


def test_crossing_without_self_contact_names_the_key(caplog):
    summary = {"self_intersections": {"pairs": 273}, "warnings": ["earlier"]}
    with caplog.at_level(logging.WARNING):
        warn_crossings(summary, self_contact=False)
    assert summary["warnings"][0] == "earlier" and len(summary["warnings"]) == 2
    text = summary["warnings"][1]
    assert "273 triangle pairs" in text and "contact.self = true" in text and "not physical" in text
    assert text in caplog.text


def test_crossing_with_self_contact_names_its_stiffness():
    summary = {"self_intersections": {"pairs": 4}}
    warn_crossings(summary, self_contact=True)
    assert "contact.self_factor" in summary["warnings"][0]


def test_unchecked_state_is_not_flagged():
    summary = {"self_intersections": {"applicable": False}, "warnings": []}
    warn_crossings(summary, self_contact=False)
    assert summary["warnings"] == []
