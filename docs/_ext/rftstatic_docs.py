"""Sphinx extension of the rftstatic documentation: writes the generated pages before the build reads them.

At ``builder-inited`` it writes into ``docs/_generated/`` (never committed):

- ``scene_keys.md``: every scene key, from the options' single source: the declared tables
  (:data:`rftstatic.scenes.sections.SECTIONS`, the rows ``python -m rftstatic options --format markdown``
  prints), the other tables from :data:`rftstatic.scenes.schema.SCHEMA`, and the obstacle types from
  their registry (:mod:`rftstatic.contact.obstacles`);
- ``cli.md``: ``python -m rftstatic --help`` and every subcommand's ``--help``;
- ``examples/NAME.txt``: what each script of ``docs/examples/`` prints (each run in a fresh interpreter);
- ``validation/``: the validation reports of ``validation/`` (index and reports, with their plots).

The package never imports this module; :func:`scene_keys_markdown` and :func:`cli_markdown` are plain
functions that the tests call too.
"""

from __future__ import annotations

import contextlib
import inspect
import io
import math
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1]
ROOT = DOCS.parent
GENERATED = DOCS / "_generated"


# ----------------------------------------------------------------------------------------------- scene keys
def _type_name(kind) -> str:
    from rftstatic.scenes.schema import ListOf, PointsXY

    if isinstance(kind, PointsXY):
        return "[x, y] or [[x, y], ...]"
    if isinstance(kind, ListOf):
        inner = _type_name(kind.item)
        n = f"{kind.length} " if kind.length is not None else ""
        s = "s" if not inner.startswith("[") else ""
        text = f"array of {n}{inner}{s}"
        if kind.choices:
            text += " (" + ", ".join(kind.choices) + ")"
        return text
    kinds = kind if isinstance(kind, tuple) else (kind,)
    names = {int: "integer", float: "number", str: "string", bool: "boolean", list: "array", dict: "table"}
    if set(kinds) == {int, float}:
        return "number"
    return " or ".join(names.get(k, getattr(k, "__name__", str(k))) for k in kinds)


def _cell(text: str) -> str:
    return str(text).replace("|", "&#124;").replace("\n", " ")


def _schema_rows(table: Mapping, prefix: str) -> list[tuple[str, str, str]]:
    """(dotted key, type, meaning) of every key of a schema table, nested tables flattened."""
    rows = []
    for key, (kind, help_) in table.items():
        name = f"{prefix}{key}"
        if isinstance(kind, Mapping):
            rows.append((name, "table", help_))
            rows += _schema_rows(kind, name + ".")
        elif isinstance(kind, list):
            rows.append((name, "array of tables", help_))
            rows += _schema_rows(kind[0], name + "[].")
        else:
            rows.append((name, _type_name(kind), help_))
    return rows


def _table(header: tuple[str, ...], rows) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(_cell(c) for c in row) + " |" for row in rows]
    return lines + [""]


def _obstacle_default(cls, sk) -> str:
    if sk.required:
        return "required"
    value = sk.default
    if value is None:
        param = inspect.signature(cls).parameters.get(sk.arg)
        if param is None or param.default is inspect.Parameter.empty:
            return "-"
        value = param.default
    if value is None:
        return "-"
    if isinstance(value, float) and math.isinf(value):
        return "none (unbounded)"
    if isinstance(value, tuple):
        value = list(value)
    return f"`{value}`"


def scene_keys_markdown() -> str:
    """The reference of every scene key, as one Markdown page."""
    from rftstatic.contact.obstacles import obstacle_class, obstacle_types
    from rftstatic.scenes.schema import SCHEMA
    from rftstatic.scenes.sections import SECTIONS, UNDECLARED, format_rows, option_rows

    out = ["# Scene keys", "",
           "Generated when the documentation is built, from the declarations the scenes are checked against: "
           "the declared option tables (`rftstatic.optionspec`, listed by `python -m rftstatic options SECTION`), "
           "the scene schema `rftstatic.scenes.schema.SCHEMA` for the other tables, and the obstacle registry "
           "`rftstatic.contact.obstacles` for `[[obstacles]]`. Every number is in the scene's `units` unless the "
           "key says otherwise (the lab keys of `[material]` are in the instruments' units). `--set KEY=VALUE` "
           "overrides any key (`--set mesh.nodes=[21,101]`, `--set supports.0.kind=pinned`); arrays of tables are "
           "written `supports[]` here and indexed `supports.0` in `--set`.", ""]
    out += ["## Top-level keys and undeclared tables", ""]
    rows = []
    for name, kind_help in SCHEMA.items():
        if name in SECTIONS or name == "obstacles":
            continue
        rows += _schema_rows({name: kind_help}, "")
    out += _table(("key", "type", "meaning"), [(f"`{k}`", t, h) for k, t, h in rows])

    out += ["## `[[obstacles]]`", "",
            "Each `[[obstacles]]` table names its `type` and that type's keys. Lengths are in the scene's units "
            "(converted by the length scale of `units`). Registered types:", ""]
    for name in obstacle_types():
        cls = obstacle_class(name)
        out += [f"### `type = \"{name}\"`", ""]
        doc = inspect.getdoc(cls) or ""
        if doc:
            out += [doc.split("\n\n")[0].replace("\n", " "), ""]
        out += _table(("key", "type", "default", "length", "meaning"),
                      [(f"`{k}`", _type_name(sk.kinds), _obstacle_default(cls, sk), "yes" if sk.length else "no",
                        sk.help) for k, sk in cls.scene_keys.items()])

    for section in SECTIONS:
        out += [f"## `[{section}]`", "", SCHEMA[section][1] + ".", "",
                format_rows(option_rows(section), "markdown"), ""]
        extra = [(f"`{section}.{k}`", _type_name(SCHEMA[section][0][k][0]), SCHEMA[section][0][k][1])
                 for k in UNDECLARED.get(section, ())]
        if extra:
            out += ["Keys of this table checked by the scene schema rather than declared as options:", ""]
            out += _table(("key", "type", "meaning"), extra)
    return "\n".join(out) + "\n"


# ----------------------------------------------------------------------------------------------------- CLI
def _help(argv: list[str]) -> str:
    from rftstatic import cli

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.suppress(SystemExit):
        cli.main(argv)
    return buf.getvalue()


def cli_markdown() -> str:
    """``python -m rftstatic --help`` and each subcommand's ``--help``, as one Markdown page."""
    top = _help(["--help"])
    match = re.search(r"\{([a-z,\-]+)\}", top)
    commands = match.group(1).split(",") if match else []
    out = ["# Command line", "",
           "Generated when the documentation is built from the parser of `rftstatic.cli` (`python -m rftstatic "
           "COMMAND --help` prints the same).", "", "```text", top.rstrip(), "```", ""]
    for command in commands:
        out += [f"## `{command}`", "", "```text", _help([command, "--help"]).rstrip(), "```", ""]
    return "\n".join(out) + "\n"


# ------------------------------------------------------------------------------------------------ examples
def run_example(script: Path, timeout: float = 300.0) -> str:
    """What ``script`` prints on stdout, run in a fresh interpreter from the repository root."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
               MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, str(script)], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=timeout, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"docs example {script.name} failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
    return proc.stdout


# ---------------------------------------------------------------------------------------------- validation
def copy_validation(dest: Path) -> None:
    """The validation index and reports (Markdown and PNG) under ``dest``, the index as ``index.md``."""
    src = ROOT / "validation"
    dest.mkdir(parents=True, exist_ok=True)
    reports = sorted(p for p in src.glob("*.md") if p.name != "README.md")
    for p in reports:
        shutil.copyfile(p, dest / p.name)
    for p in src.glob("*.png"):
        shutil.copyfile(p, dest / p.name)
    index = (src / "README.md").read_text(encoding="utf-8")
    toctree = ["", "```{toctree}", ":hidden:", ""] + [p.stem for p in reports] + ["```", ""]
    (dest / "index.md").write_text(index + "\n".join(toctree), encoding="utf-8")


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text(encoding="utf-8") != text:  # unchanged files keep Sphinx's cache
        path.write_text(text, encoding="utf-8")


def generate(app=None) -> None:
    """Write every generated page (the ``builder-inited`` hook)."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    _write(GENERATED / "scene_keys.md", scene_keys_markdown())
    _write(GENERATED / "cli.md", cli_markdown())
    for script in sorted((DOCS / "examples").glob("*.py")):
        _write(GENERATED / "examples" / f"{script.stem}.txt", run_example(script))
    copy_validation(GENERATED / "validation")


def setup(app):
    app.connect("builder-inited", generate)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
