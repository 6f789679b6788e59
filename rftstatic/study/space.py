"""The parameter space of a study: ``--vary KEY=V1,V2,...``, ``--vary KEY=LO:HI[:log] --samples N``,
``--free KEY=LO:HI``.

A sweep's points are the full grid of the listed values times ``N`` Latin-hypercube samples of the
ranges (McKay, Beckman & Conover 1979: each range cut into ``N`` equal strata, one sample in each,
the strata of different keys paired by random permutations; ``seed`` fixes them, so that the same
command gives the same points and a re-run finds them done). A range marked ``:log`` is sampled
uniformly in log(value). Values are TOML, as for ``--set`` (``3``, ``0.05``, ``"RFT3"``, ``[9,3]``).
"""

from __future__ import annotations

import itertools
import math
import tomllib
from dataclasses import dataclass

import numpy as np


class StudyError(ValueError):
    """Bad study input (an argument, a key, a value, a scheduler): one line naming the argument and
    the value; the command line exits with status 2."""


@dataclass(frozen=True)
class Range:
    """A continuous range of a scene key: ``lo`` .. ``hi`` (scene units), sampled in log when ``log``."""

    key: str
    lo: float
    hi: float
    log: bool = False

    def value(self, u: float) -> float:
        """The key's value at ``u`` in [0, 1] (0: ``lo``, 1: ``hi``)."""
        if self.log:
            return float(self.lo * (self.hi / self.lo) ** u)
        return float(self.lo + (self.hi - self.lo) * u)

    def unit(self, value: float) -> float:
        """Inverse of :meth:`value`: where ``value`` lies in [0, 1]."""
        if self.log:
            return float(math.log(value / self.lo) / math.log(self.hi / self.lo))
        return float((value - self.lo) / (self.hi - self.lo))


def parse_value(raw: str):
    """A TOML value (``3``, ``[9, 3]``, ``"RFT3"``); bare words are strings, as for ``--set``."""
    try:
        return tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        return raw.strip()


def split_values(raw: str) -> list[str]:
    """``V1,V2,...`` split at the commas outside brackets and quotes (``[9,3],[17,5]`` is two values)."""
    parts, depth, quote, cur = [], 0, None, []
    for ch in raw:
        if quote:
            quote = None if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append("".join(cur))
            cur = []
            continue
        cur.append(ch)
    parts.append("".join(cur))
    return [p.strip() for p in parts]


def _key_and_text(text: str, arg: str) -> tuple[str, str]:
    if "=" not in text:
        raise StudyError(f'{arg} "{text}": expected KEY=VALUES, e.g. {arg} material.B_warp=0.05:0.2')
    key, raw = (s.strip() for s in text.split("=", 1))
    if not key or not raw or any(not part for part in key.split(".")):
        raise StudyError(f'{arg} "{text}": expected KEY=VALUES with a dotted scene key, e.g. {arg} '
                         "material.B_warp=0.05:0.2")
    return key, raw


def parse_range(key: str, raw: str, arg: str, text: str) -> Range:
    """``LO:HI`` or ``LO:HI:log`` -> :class:`Range` (a :class:`StudyError` naming ``arg`` and ``text``)."""
    parts = [p.strip() for p in raw.split(":")]
    log = len(parts) == 3 and parts[2] == "log"
    if len(parts) not in (2, 3) or (len(parts) == 3 and not log):
        raise StudyError(f'{arg} "{text}": a range is LO:HI or LO:HI:log, got "{raw}"')
    try:
        lo, hi = float(parts[0]), float(parts[1])
    except ValueError:
        raise StudyError(f'{arg} "{text}": the bounds of "{raw}" are not numbers') from None
    if not (math.isfinite(lo) and math.isfinite(hi)) or not lo < hi:
        raise StudyError(f'{arg} "{text}": a range needs finite LO < HI, got {lo:g}:{hi:g}')
    if log and lo <= 0:
        raise StudyError(f'{arg} "{text}": a log range needs LO > 0, got {lo:g}')
    return Range(key, lo, hi, log)


@dataclass
class Space:
    """The varied keys of a sweep: ``grid`` (key -> list of values) and ``ranges`` (Latin hypercube)."""

    grid: dict
    ranges: list

    @property
    def keys(self) -> list[str]:
        return list(self.grid) + [r.key for r in self.ranges]

    def points(self, samples: int | None, seed: int = 0) -> list[dict]:
        """Every point, ``{key: value}``: the grid's product times ``samples`` hypercube samples."""
        combos = [dict(zip(self.grid, vals)) for vals in itertools.product(*self.grid.values())]
        if not self.ranges:
            return combos
        lhs = latin_hypercube(len(self.ranges), samples, seed)
        sampled = [{r.key: r.value(u) for r, u in zip(self.ranges, row)} for row in lhs]
        return [{**c, **s} for c in combos for s in sampled]


def latin_hypercube(dims: int, n: int, seed: int = 0) -> np.ndarray:
    """(n, dims) points in [0, 1]: one in each of the n strata of every axis (seeded, reproducible)."""
    rng = np.random.default_rng(seed)
    u = (np.arange(n)[:, None] + rng.random((n, dims))) / n
    for j in range(dims):
        u[:, j] = u[rng.permutation(n), j]
    return u


def parse_vary(texts, samples: int | None) -> Space:
    """The ``--vary`` arguments -> :class:`Space`; ``samples`` is required with a range, unused without."""
    if not texts:
        raise StudyError("--vary: give at least one, e.g. --vary material.B_warp=0.05,0.083,0.12")
    grid, ranges = {}, []
    for text in texts:
        key, raw = _key_and_text(text, "--vary")
        if key in grid or key in [r.key for r in ranges]:
            raise StudyError(f'--vary "{text}": {key} is varied twice')
        if ":" in raw and not raw.lstrip().startswith(("[", '"', "'")):
            ranges.append(parse_range(key, raw, "--vary", text))
        else:
            values = [parse_value(v) for v in split_values(raw)]
            if any(v == "" for v in values):
                raise StudyError(f'--vary "{text}": an empty value in "{raw}"')
            grid[key] = values
    if ranges and (samples is None or samples < 1):
        raise StudyError(f"--samples: a range ({ranges[0].key}) needs --samples N >= 1, got {samples}")
    if samples is not None and samples < 1:
        raise StudyError(f"--samples {samples}: must be >= 1")
    return Space(grid, ranges)


def parse_free(texts) -> list[Range]:
    """The ``--free KEY=LO:HI`` arguments of ``fit`` (searched in log(value) when LO > 0)."""
    if not texts:
        raise StudyError("--free: give at least one, e.g. --free material.B_warp=0.03:0.3")
    out = []
    for text in texts:
        key, raw = _key_and_text(text, "--free")
        r = parse_range(key, raw.removesuffix(":log"), "--free", text)
        if key in [f.key for f in out]:
            raise StudyError(f'--free "{text}": {key} is free twice')
        out.append(Range(key, r.lo, r.hi, log=r.lo > 0))
    return out


def format_override(key: str, value) -> str:
    """``key=value`` as ``--set`` reads it (TOML: strings quoted, floats in full precision)."""
    if isinstance(value, str):
        return f'{key}="{value}"'
    if isinstance(value, bool):
        return f"{key}={'true' if value else 'false'}"
    if isinstance(value, float):
        return f"{key}={value!r}"
    if isinstance(value, list):
        return f"{key}=[{', '.join(format_override('v', v)[2:] for v in value)}]"
    return f"{key}={value}"
