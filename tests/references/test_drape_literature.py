"""The literature module of measured Cusick drape: rftstatic.references.drape_literature.

Its entries are data, so these tests check that they are well formed and consistent with each other: every
source names where it was found and what of it was readable; a measured row passes the row check and comes
from a source whose table was within reach; the row check rejects what a transcription error would give; the
second search's log names every source that search added.
"""

import copy
import math
import re

import pytest

from rftstatic.references import drape_literature as lit

HOST = re.compile(r"(?:https?://)?((?:[a-z0-9-]+\.)+[a-z]{2,})/")
ENTRY_KEYS = {"citation", "found_at", "readable", "says", "table_within_reach", "search"}


def _good_row() -> dict:
    """A well-formed row (its values illustrative, not a fabric of the literature) whose copy file exists."""
    return {"citation": "Author, A. (2000), A study, J. Textiles 1, 1-2", "url": "https://example.org/a-study",
            "where": "Table 2, p. 5", "copy": lit.SEARCH_LOG_FILE, "fabric": "F1",
            "printed": {"B warp (gf cm2/cm)": "0.083", "W (mg/cm2)": "19.0", "DC (%)": "45.2", "nodes": "7"},
            "kes_B_warp": 0.083, "kes_B_weft": 0.063, "kes_W": 19.0, "kes_T": None,
            "specimen_diameter_cm": 30.0, "disc_diameter_cm": 18.0, "dc_percent": 45.2, "nodes": 7}


@pytest.mark.parametrize("entries", [lit.SEARCHED, lit.SKIRT_SEARCHED], ids=["fabrics", "skirts"])
def test_every_source_says_where_and_what_was_readable(entries):
    assert entries
    for e in entries:
        assert set(e) == ENTRY_KEYS, e["citation"]
        for key in ("citation", "found_at", "readable", "says"):
            assert isinstance(e[key], str) and e[key].strip(), (e["citation"], key)
        assert isinstance(e["table_within_reach"], bool) and e["search"] in (1, 2)
    citations = [e["citation"] for e in entries]
    assert len(set(citations)) == len(citations)


def test_measured_rows_pass_the_check_and_come_from_a_table_in_reach():
    in_reach = {e["citation"] for e in lit.SEARCHED if e["table_within_reach"]}
    for row in lit.MEASURED_ROWS:
        lit.check_row(row)
        assert row["citation"] in in_reach, row["citation"]
    for row in lit.SKIRT_ROWS:
        assert row["citation"] in {e["citation"] for e in lit.SKIRT_SEARCHED if e["table_within_reach"]}


def test_check_row_accepts_a_well_formed_row_and_needs_every_field():
    lit.check_row(_good_row())
    for key in lit.ROW_FIELDS:
        row = _good_row()
        del row[key]
        with pytest.raises(ValueError, match=rf"missing field\(s\) \['{key}'\]"):
            lit.check_row(row)


@pytest.mark.parametrize("key, value, message", [
    ("dc_percent", 145.2, r"dc_percent = 145.2, must be in \[0, 100\]"),
    ("dc_percent", -1.0, r"dc_percent = -1.0"),
    ("kes_B_warp", 0.0, r"kes_B_warp = 0.0, must be > 0"),
    ("kes_W", math.nan, r"kes_W = nan, must be > 0"),
    ("kes_T", -0.5, r"kes_T = -0.5, must be > 0"),
    ("disc_diameter_cm", 30.0, r"disc_diameter_cm = 30.0 is not below specimen_diameter_cm = 30.0"),
    ("nodes", 6.5, r"nodes = 6.5, must be a non-negative integer or None"),
    ("nodes", True, r"nodes = True"),
    ("where", " ", r"where = ' ', must be non-empty text"),
    ("printed", {}, r"printed = \{\}, must map headers to values"),
    ("copy", "no_such_table.txt", r"copy = 'no_such_table.txt' is not a file of rftstatic/references/data"),
])
def test_check_row_rejects_transcription_errors(key, value, message):
    row = copy.deepcopy(_good_row())
    row[key] = value
    with pytest.raises(ValueError, match=message):
        lit.check_row(row)


def test_check_row_takes_none_where_a_study_gives_no_value():
    row = _good_row()
    row["nodes"] = None
    row["kes_T"] = None
    lit.check_row(row)


def test_search_log_is_complete_and_names_every_source_the_second_search_added():
    log = lit.search_log()
    assert len(log) >= 30
    for r in log:
        assert tuple(r) == lit.SEARCH_LOG_COLUMNS and all(v.strip() for v in r.values()), r
    assert {r["corpus"] for r in log} >= {"pages", "code", "docs", "find_string", "find_repos"}
    returned = " ".join(r["returned"] for r in log)
    for e in lit.SEARCHED + lit.SKIRT_SEARCHED:
        if e["search"] != 2:
            continue
        hosts = {h.removeprefix("www.") for h in HOST.findall(e["found_at"])}
        assert hosts or "not stored" in e["found_at"], e["citation"]
        for host in hosts:
            assert host in returned, (e["citation"], host)


def test_secondary_rows_are_the_copied_transcription_and_stay_apart_from_measured_rows():
    table = {r["id"]: r for r in lit.secondary_table()}
    assert set(table) == {r["fabric"] for r in lit.SECONDARY_ROWS}
    columns = {"kes_B": "B_gf*cm^2/cm", "kes_2HB": "2HB_gf*cm/cm", "kes_W": "W_mg/cm^2", "kes_T": "T_mm",
               "dc_percent": "DC_pub_%"}
    for row in lit.SECONDARY_ROWS:
        copied = table[row["fabric"]]
        assert row["name"] == copied["name"].lower()
        for key, column in columns.items():
            assert row[key] == float(copied[column]), (row["fabric"], key)
        assert row["nodes"] == int(copied["nodes_pub"])
        assert 0.0 < row["dc_percent"] < 100.0 and row["nodes"] >= 0
        assert min(row[k] for k in ("kes_B", "kes_2HB", "kes_W", "kes_T")) > 0.0
    source = next(e for e in lit.SEARCHED if e["citation"].startswith("Matsudaira"))
    assert not source["table_within_reach"], "a transcription is not the paper's table"
    assert all(r.get("citation") != source["citation"] for r in lit.MEASURED_ROWS)
