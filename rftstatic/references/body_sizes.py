"""A women's size chart for the dress form, from ANSUR II (data/ansur2_women_size_chart.csv).

Each size is named by its bust girth in cm (the control dimension EN 13402-3 designates women's tops and dresses by);
its measurements are the medians of the ANSUR II women (the 2012 Anthropometric Survey of U.S. Army Personnel,
Gordon et al. 2014, NATICK/TR-15/007, public domain) whose chest circumference lies within 2 cm of it: bust, waist and
hip girths and heights, shoulder breadth and height, neck girth at the base and the neck base's height (cervicale),
in cm, and the depth / width ratios of the bust, waist and hip sections. ANSUR's waist lies at the omphalion (the
navel), below ISO 8559-1's natural waist. How the file was made, from which copy of the survey's file:
``tools/ansur_size_chart.py``.
"""

from __future__ import annotations

import csv
import io
from functools import lru_cache
from importlib import resources

__all__ = ["SIZE_CHART_FILE", "size_chart"]

SIZE_CHART_FILE = "ansur2_women_size_chart.csv"
"""The chart in ``rftstatic/references/data`` (``#`` lines: its source)."""


@lru_cache(maxsize=1)
def size_chart() -> dict[int, dict[str, float]]:
    """``{size: {key: value}}``: each size's measurements (lengths in cm, ``*_depth`` ratios, ``women`` the count
    of women it is the median of), keys as :class:`rftstatic.garment.body.DressForm` names them (and ``stature``)."""
    text = resources.files("rftstatic.references").joinpath("data", SIZE_CHART_FILE).read_text(encoding="utf-8")
    rows = csv.DictReader(io.StringIO("\n".join(ln for ln in text.splitlines() if ln and not ln.startswith("#"))))
    return {int(r.pop("size")): {k: float(v) for k, v in r.items()} for r in rows}
