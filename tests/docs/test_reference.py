"""The generated reference (``docs/_ext/rftstatic_docs.py``) documents every scene key: every key of the scene
schema (nested tables flattened), every declared option with its meaning, every obstacle type with its keys,
and every subcommand of the command line."""

from __future__ import annotations

import importlib.util
from collections.abc import Mapping
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def gen():
    spec = importlib.util.spec_from_file_location("rftstatic_docs", ROOT / "docs" / "_ext" / "rftstatic_docs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _keys(table: Mapping, prefix: str = ""):
    for key, (kind, _help) in table.items():
        name = f"{prefix}{key}"
        yield name
        if isinstance(kind, Mapping):
            yield from _keys(kind, name + ".")
        elif isinstance(kind, list):
            yield from _keys(kind[0], name + "[].")


def test_every_schema_key_is_in_the_reference(gen):
    from rftstatic.scenes.schema import SCHEMA
    from rftstatic.scenes.sections import SECTIONS, option_rows

    page = gen.scene_keys_markdown()
    for name in _keys(SCHEMA):
        top = name.split(".")[0].split("[")[0]
        if top == "obstacles" or (top in SECTIONS and "." in name):
            continue  # the obstacle types and the declared tables' options are checked below
        if top in SECTIONS:
            assert f"## `[{name}]`" in page, f"table [{name}] is missing from the generated reference"
            continue
        assert f"`{name}`" in page, f"scene key {name} is missing from the generated reference"
    assert "## `[[obstacles]]`" in page
    for row in option_rows():
        assert f"`{row['key']}`" in page and row["help"].replace("|", "&#124;") in page, row["key"]


def test_every_obstacle_key_is_in_the_reference(gen):
    from rftstatic.contact.obstacles import obstacle_class, obstacle_types

    page = gen.scene_keys_markdown()
    for name in obstacle_types():
        section = page.split(f'### `type = "{name}"`', 1)[1].split("\n### ", 1)[0].split("\n## ", 1)[0]
        for key, sk in obstacle_class(name).scene_keys.items():
            assert f"| `{key}` |" in section and sk.help in section, (name, key)
    square = page.split('### `type = "square-pedestal"`', 1)[1].split("\n### ", 1)[0]
    assert "`height`" in square and "`size`" in square and "infinitely tall" in square


def test_the_cli_page_lists_every_subcommand(gen):
    page = gen.cli_markdown()
    for command in ("case", "list", "fabrics", "options", "sweep", "fit", "bench", "validate"):
        assert f"## `{command}`" in page
        assert f"usage: rftstatic {command}" in page
