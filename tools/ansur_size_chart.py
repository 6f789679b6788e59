"""Write the dress form's size chart (rftstatic/references/data/ansur2_women_size_chart.csv) from ANSUR II.

Source: the 2012 Anthropometric Survey of U.S. Army Personnel (ANSUR II; Gordon, C.C. et al. (2014), NATICK/TR-15/007;
public domain), its women's file ``ANSUR II FEMALE Public.csv`` (1,986 women, millimetres; distributed at
https://www.openlab.psu.edu/ansur2/), read here from the copy in github.com/sharad18/Adidas-Data-Challenge (commit
59dbdc2b99c84d565003b4b4f3a809edf7d27c4d; checked by its git blob hash, :data:`BLOB`).

Sizes are named by their bust girth in cm (the control dimension by which EN 13402-3 designates women's tops and
dresses); a size takes the women whose chest circumference (ANSUR's, at the bust points: ISO 8559-1's bust girth)
lies within 2 cm of it, and each measurement of the chart is their median (sizes with fewer than :data:`LEAST`
women are left out, and those whose depth / width ratios lie outside the dress form's 0.4-1.0: :data:`RATIOS`). ANSUR's waist circumference and height are at the omphalion (the navel), lower than ISO 8559-1's
natural waist; the depth / width ratios are the medians of chest, waist and buttock depth over chest, waist and hip
breadth.

    python tools/ansur_size_chart.py "ANSUR II FEMALE Public.csv"
"""

from __future__ import annotations

import csv
import hashlib
import sys
from pathlib import Path

import numpy as np

BLOB = "11aa789be390f5575a9ebc3f6a399da586ef3a1a"
"""git blob hash of the women's file as read (``git hash-object``)."""

LEAST = 30
"""Fewest women of a size."""

RATIOS = (0.4, 1.0)
"""The depth / width ratios :class:`rftstatic.garment.body.DressForm` takes (an ellipse deeper than wide is refused)."""

COLUMNS = {  # chart key: (ANSUR column, or a ratio of two), in mm -> cm
    "bust_girth": "chestcircumference", "waist_girth": "waistcircumference", "hip_girth": "buttockcircumference",
    "bust_height": "chestheight", "waist_height": "waistheightomphalion", "hip_height": "buttockheight",
    "shoulder_breadth": "biacromialbreadth", "shoulder_height": "acromialheight", "neck_girth": "neckcircumferencebase",
    "neck_height": "cervicaleheight", "stature": "stature",
    "bust_depth": ("chestdepth", "chestbreadth"), "waist_depth": ("waistdepth", "waistbreadth"),
    "hip_depth": ("buttockdepth", "hipbreadth"),
}

OUT = Path(__file__).resolve().parent.parent / "rftstatic" / "references" / "data" / "ansur2_women_size_chart.csv"


def main(path):
    raw = Path(path).read_bytes()
    blob = hashlib.sha1(b"blob %d\0" % len(raw) + raw).hexdigest()
    if blob != BLOB:
        raise SystemExit(f"{path}: git blob {blob}, expected {BLOB}: not the file this chart was made from")
    rows = list(csv.DictReader(raw.decode("latin-1").splitlines()))
    data = {k: np.array([float(r[c]) for r in rows]) if isinstance(c, str) else
            np.array([float(r[c[0]]) / float(r[c[1]]) for r in rows]) for k, c in COLUMNS.items()}
    bust = data["bust_girth"] / 10.0
    lines = ["# Dress form size chart from ANSUR II women (tools/ansur_size_chart.py; source in its docstring): size =",
             "# bust girth [cm], the women within 2 cm of it, medians; lengths in cm, *_depth ratios [-].",
             ",".join(["size", "women", *COLUMNS])]
    for size in range(72, 132, 4):
        sel = np.abs(bust - size) < 2.0
        if sel.sum() < LEAST:
            continue
        vals = [np.median(data[k][sel]) / (1.0 if k.endswith("_depth") else 10.0) for k in COLUMNS]
        if not all(RATIOS[0] <= v <= RATIOS[1] for k, v in zip(COLUMNS, vals) if k.endswith("_depth")):
            continue
        lines.append(",".join([str(size), str(int(sel.sum()))] + [f"{v:.4g}" if isinstance(v, float) else str(v)
                                                                 for v in map(float, vals)]))
    OUT.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))


if __name__ == "__main__":
    main(sys.argv[1])
