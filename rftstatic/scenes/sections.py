"""The scene tables whose keys are declared as data (:mod:`rftstatic.optionspec`), for the reference that
``python -m rftstatic options [SECTION]`` prints and the documentation renders.

Each section maps to its option groups; the scene schema of that table is generated from the same groups
(:data:`rftstatic.scenes.schema.SCHEMA`), so the listing and the checks cannot disagree.
"""

from __future__ import annotations

from rftstatic.errors import SceneError
from rftstatic.optionspec import describe
from rftstatic.remesh.options import RemeshOptions
from rftstatic.scenes.contact_options import ContactOptions
from rftstatic.scenes.dynamics_options import DynamicsOptions
from rftstatic.scenes.motion import GarmentMotionOptions, MotionOptions, list_rows
from rftstatic.scenes.run_options import SOLVER_GROUPS, CantileverOptions

__all__ = ["SECTIONS", "UNDECLARED", "option_rows", "format_rows"]

SECTIONS = {"solver": SOLVER_GROUPS, "dynamics": (DynamicsOptions,), "remesh": (RemeshOptions,),
            "contact": (ContactOptions,), "cantilever": (CantileverOptions,), "motion": (GarmentMotionOptions,)}
"""Scene table -> its declared option groups (``dynamics.frames``, a list of times bounded by ``t_end``, is the one
scene key of these tables that is not a declared option: :mod:`rftstatic.scenes.dynamics_options`)."""


UNDECLARED = {"dynamics": ("frames",)}
"""The scene keys of these tables that are not declared options, each with its schema entry written by hand and
its own check (:mod:`rftstatic.scenes.dynamics_options`: a list of times bounded by ``t_end``)."""


OBSTACLE_SECTIONS = {"obstacles.motion": (MotionOptions,)}
"""Tables inside an ``[[obstacles]]`` entry whose scalar keys are declared options (listed by ``options SECTION``;
their list keys and the obstacle keys are in the obstacle reference: :mod:`rftstatic.scenes.motion`)."""


def option_rows(section: str | None = None) -> list[dict]:
    """One row per declared key (``key``, ``type``, ``unit``, ``range``, ``default``, ``help``, ``group``) of
    ``section`` (None: every section); an unknown section is a :class:`SceneError` naming the known ones."""
    if section is None:
        return [row for name in SECTIONS for row in describe(SECTIONS[name], name)]
    if section in OBSTACLE_SECTIONS:
        return list_rows(section) + describe(OBSTACLE_SECTIONS[section], section)
    if section not in SECTIONS:
        raise SceneError(f'options: no section "{section}" declares its keys as data; known: {", ".join(SECTIONS)}, '
                         f'{", ".join(OBSTACLE_SECTIONS)} (the other tables: the scene-key reference of the '
                         "documentation, docs/howto/scenes.md)")
    return describe(SECTIONS[section], section)


def format_rows(rows: list[dict], style: str = "text") -> str:
    """``rows`` (:func:`option_rows`) as a plain-text listing (``"text"``) or a Markdown table (``"markdown"``)."""
    def cell(row, k):
        v = row[k]
        return str(v).lower() if isinstance(v, bool) else str(v)

    if style == "markdown":
        lines = ["| key | type | unit | range | default | meaning |", "|---|---|---|---|---|---|"]
        lines += [f"| `{r['key']}` | {r['type']} | {r['unit']} | {r['range']} | `{cell(r, 'default')}` | "
                  f"{r['help'].replace('|', '&#124;')} |" for r in rows]
        return "\n".join(lines)
    if style != "text":
        raise SceneError(f'options --format: "{style}" is not a format; use text or markdown')
    width = max(len(r["key"]) for r in rows) if rows else 0
    lines = []
    for r in rows:
        what = ", ".join(x for x in (r["type"], r["unit"] if r["unit"] != "-" else "", r["range"]) if x)
        lines.append(f"{r['key']:<{width}}  {what}; default {cell(r, 'default')}")
        lines.append(f"{'':<{width}}  {r['help']}")
    return "\n".join(lines)
