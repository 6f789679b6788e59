"""Options declared once, as data: each option a dataclass field with its type, unit, range, default and
one line of help (as SfePy declares its solver options).

An options class is a frozen, keyword-only dataclass whose fields are made by :func:`option`; its
``__post_init__`` calls :func:`check` with the class's scene section (``"solver"``), which checks every
field against its declaration and raises :class:`~rftstatic.errors.ParameterError` naming
``section.key``, the value and the range. The scene schema, its validation messages, the unit conversion
of a scene table and the ``python -m rftstatic options`` listing are generated from the same
declarations (:func:`schema_entries`, :func:`from_table`, :func:`describe`), so a key, its default and its
range are written once.

Units: ``unit`` names the kind of quantity (``"length"``, ``"time"``, ``"angle"``); a scene gives the value in
its own units (:class:`~rftstatic.units.UnitSystem`; angles in degrees), the options hold SI, and the declared
range is in SI (shown in the scene's units). ``""`` is a pure number.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import MISSING, dataclass, field, fields

from rftstatic.errors import ParameterError

__all__ = ["OptionSpec", "option", "check", "declared", "schema_entries", "from_table", "describe", "REQUIRED", "scene_values"]

_KINDS = {"bool": (bool,), "int": (int,), "float": (int, float), "str": (str,)}

AUTO = "auto"
"""How a scene says None ("automatic") for a nullable option."""


class _Required:
    """The default of a required option (:data:`REQUIRED`): the scene must give the key."""

    def __repr__(self):
        return "required"


REQUIRED = _Required()
"""Give as the default of :func:`option` for an option without a default: a scene table must give the key
(:func:`from_table` names it when missing) and the listings show "required"."""

UNIT_LABELS = {"": "-", "length": "length", "time": "time", "rate": "1/time", "angle": "deg",
               "stiffness_volumetric": "force/length^3", "element_sizes": "mean element sizes"}
"""The units an option may declare, and how each is shown in the listings (lengths, times and the derived
quantities of :class:`~rftstatic.units.UnitSystem` in the scene's ``units``, a rate in 1/its time, angles in
degrees; ``"element_sizes"`` is a pure number counted in the mesh's mean element size)."""


def scene_factor(unit: str, units=None) -> float:
    """SI value of one scene unit of the quantity ``unit`` [SI / scene unit]: a length or time by the scene's
    :class:`~rftstatic.units.UnitSystem` ``units`` (None: SI), a rate (1/time) by the inverse of the scene's
    time, an angle from degrees to radians, a derived quantity (``"stiffness_volumetric"``) by the unit system's
    factor of that name, else 1."""
    if unit == "angle":
        return math.pi / 180.0
    if not unit or units is None or unit == "element_sizes":
        return 1.0
    if unit == "rate":
        return 1.0 / float(units.time)
    return float(getattr(units, unit))


@dataclass(frozen=True)
class OptionSpec:
    """The declaration of one option.

    Attributes
    ----------
    help : one line saying what it does
    kind : ``"bool"``, ``"int"``, ``"float"`` or ``"str"``
    unit : the quantity's kind in a scene (``"length"``, ``"time"``, ``"rate"`` [1/time], ``"angle"``) or ``""``
        for a pure number
    low, high : the closed range of a number (None: unbounded); ``open_low``/``open_high`` exclude the bound
    choices : the allowed strings of a ``str`` option
    nullable : None is allowed (it means "automatic"; ``help`` says what)
    scene : the option is a key of the scene's table (False: set by the program, e.g. a progress bar)
    required : the option has no default (:data:`REQUIRED`): a scene table must give it
    """

    help: str
    kind: str
    unit: str = ""
    low: float | None = None
    high: float | None = None
    open_low: bool = False
    open_high: bool = False
    choices: tuple = ()
    nullable: bool = False
    scene: bool = True
    required: bool = False

    def range_text(self, factor: float = 1.0) -> str:
        """The range in words: ``"in (0, 1]"``, ``">= 1"``, ``"one of a, b"``, or ``""``; ``factor``: SI value of
        one unit the range is shown in (:func:`scene_factor`)."""
        if self.choices:
            return "one of " + ", ".join(self.choices)
        lo = None if self.low is None else self.low / factor
        hi = None if self.high is None else self.high / factor
        show = (lambda v: f"{int(v):,}") if self.kind == "int" else (lambda v: f"{v:g}")
        if lo is not None and hi is not None:
            return f"in {'(' if self.open_low else '['}{show(lo)}, {show(hi)}{')' if self.open_high else ']'}"
        if lo is not None:
            return f"{'>' if self.open_low else '>='} {show(lo)}"
        if hi is not None:
            return f"{'<' if self.open_high else '<='} {show(hi)}"
        return ""

    def problem(self, value, *, shown=None, factor: float = 1.0) -> str | None:
        """What is wrong with ``value`` (SI) for this option (None: nothing); a message shows ``shown`` (the value
        as the user gave it, default ``value``) and the range in units of ``factor`` [SI per unit]."""
        shown = value if shown is None else shown
        if value is None:
            return None if self.nullable else "must be given (None is not allowed)"
        types = _KINDS[self.kind]
        if not isinstance(value, types) or (isinstance(value, bool) and self.kind != "bool"):
            noun = {"bool": "true or false", "int": "an integer", "float": "a number", "str": "a string"}[self.kind]
            if self.nullable:
                noun += f' or "{AUTO}"'
            return f"must be {noun}, got {shown!r} ({type(value).__name__})"
        if self.kind == "str" and self.choices and value not in self.choices:
            near = difflib.get_close_matches(value, self.choices, n=1)
            hint = f' (did you mean "{near[0]}"?)' if near else ""
            text = value if value.isprintable() else value.encode("unicode_escape").decode()  # one line
            return f'"{text}" is not one of {", ".join(self.choices)}{hint}'
        if self.kind in ("int", "float"):
            if not math.isfinite(value):
                return f"must be a finite number, got {shown!r}"
            below = self.low is not None and (value <= self.low if self.open_low else value < self.low)
            above = self.high is not None and (value >= self.high if self.open_high else value > self.high)
            if below or above:
                label = f" ({UNIT_LABELS[self.unit]})" if self.unit else ""
                return f"{shown!r} is out of range: must be {self.range_text(factor)}{label}"
        return None


def option(default, help: str, *, kind: str | None = None, unit: str = "", low=None, high=None, open_low=False,
           open_high=False, choices=(), scene=True):
    """A dataclass field declared as an option (:class:`OptionSpec`); ``kind`` defaults to the default's type
    (give it when the default is None, which makes the option nullable, or :data:`REQUIRED`, which makes the
    field one without a default: put it in a ``kw_only`` class or before the fields with defaults)."""
    required = default is REQUIRED
    if unit not in UNIT_LABELS:
        raise TypeError(f'option unit "{unit}" is not one of {", ".join(UNIT_LABELS)}')
    if kind is None:
        if required:
            raise TypeError("a required option needs its kind")
        kind = {bool: "bool", int: "int", float: "float", str: "str"}[type(default)]
    spec = OptionSpec(help=help, kind=kind, unit=unit, low=low, high=high, open_low=open_low, open_high=open_high,
                      choices=tuple(choices), nullable=default is None, scene=scene, required=required)
    if required:
        return field(metadata={"option": spec})
    if default is not None and spec.problem(default) is not None:
        raise TypeError(f"option default {default!r}: {spec.problem(default)}")
    return field(default=default, metadata={"option": spec})


def declared(cls) -> list[tuple[str, OptionSpec, object]]:
    """``(name, spec, default)`` of every option field of the options class ``cls``, in declaration order
    (``default`` :data:`REQUIRED` for a required option)."""
    out = []
    for f in fields(cls):
        spec = f.metadata.get("option")
        if spec is not None:
            out.append((f.name, spec, REQUIRED if f.default is MISSING else f.default))
    return out


def check(obj, section: str) -> None:
    """Check every declared field of the options object ``obj`` against its declaration; an integer given
    for a ``float`` option is stored as a float. Raises :class:`ParameterError` with key ``section.name``."""
    for name, spec, _ in declared(type(obj)):
        value = getattr(obj, name)
        bad = spec.problem(value)
        if bad is not None:
            raise ParameterError(f"{section}.{name}", bad)
        if spec.kind == "float" and isinstance(value, int):
            object.__setattr__(obj, name, float(value))


def schema_entries(*classes) -> dict:
    """The scene-schema entries ``{key: (python types, help)}`` of the scene options of ``classes`` (the
    help with unit, range and default, as :func:`describe` shows them)."""
    out = {}
    for cls in classes:
        for name, spec, default in declared(cls):
            if spec.scene:
                types = _KINDS[spec.kind] + ((str,) if spec.nullable else ())
                out[name] = (types if len(types) > 1 else types[0], _help_line(spec, default))
    return out


def from_table(classes, table: dict, section: str, units=None) -> dict:
    """Split a flat scene table ``table`` (scene units) over the options ``classes``: ``{cls: {name: value}}``
    with the values of the keys declared ``unit = "length"`` / ``"time"`` converted to SI by ``units``
    (a :class:`~rftstatic.units.UnitSystem`; None: as given) and ``"auto"`` of a nullable option made None.
    Each value is checked against its declaration as given; an undeclared key, a bad value or a missing
    required key is a ParameterError naming ``section.key``."""
    owner = {name: (cls, spec) for cls in classes for name, spec, _ in declared(cls) if spec.scene}
    out = {cls: {} for cls in classes}
    for key, value in table.items():
        if key not in owner:
            near = difflib.get_close_matches(key, list(owner), n=1)
            hint = f'did you mean "{section}.{near[0]}"? ' if near else ""
            raise ParameterError(f"{section}.{key}", f"unknown option (value {value!r}); {hint}known: "
                                 f"{', '.join(sorted(owner))}")
        cls, spec = owner[key]
        if spec.nullable and value == AUTO:
            value = None
        shown, factor = value, scene_factor(spec.unit, units)
        if factor != 1.0 and isinstance(value, (int, float)) and not isinstance(value, bool):
            value = value * factor
        bad = spec.problem(value, shown=shown, factor=factor)  # the message in the user's own units
        if bad is not None:
            raise ParameterError(f"{section}.{key}", bad)
        out[cls][key] = value
    for key, (cls, spec) in owner.items():
        if spec.required and key not in table:
            raise ParameterError(f"{section}.{key}", f"is required: {spec.help}" +
                                 (f" [{UNIT_LABELS[spec.unit]}]" if spec.unit else ""))
    return out


def scene_values(obj, units=None) -> dict:
    """The declared scene options of the options object ``obj`` (SI) in the scene's units ``units`` (the inverse
    of :func:`from_table`; None stays None), e.g. for a run's summary."""
    out = {}
    for name, spec, _ in declared(type(obj)):
        if spec.scene:
            value, factor = getattr(obj, name), scene_factor(spec.unit, units)
            numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
            out[name] = value / factor if numeric and factor != 1.0 else value
    return out


def _help_line(spec: OptionSpec, default) -> str:
    parts = [spec.help]
    if spec.unit:
        parts.append(f"[{UNIT_LABELS.get(spec.unit, spec.unit)}]")
    if spec.range_text() and not spec.choices:
        parts.append(spec.range_text(scene_factor(spec.unit)))
    if spec.required:
        parts.append("(required)")
    return " ".join(parts)


def describe(classes, section: str) -> list[dict]:
    """One row per scene option of ``classes``: ``key`` (``section.name``), ``type``, ``unit``, ``range``,
    ``default`` and ``help`` (the ``options`` command and the documentation's reference print these)."""
    rows = []
    for cls in classes:
        for name, spec, default in declared(cls):
            if not spec.scene:
                continue
            factor = scene_factor(spec.unit)
            shown = default / factor if factor != 1.0 and isinstance(default, float) else default
            shown = "required" if spec.required else AUTO if default is None else shown
            rows.append({"key": f"{section}.{name}", "type": spec.kind, "unit": UNIT_LABELS.get(spec.unit, spec.unit),
                         "range": spec.range_text(factor), "default": shown,
                         "help": spec.help, "group": cls.__name__})
    return rows
