"""Choose the ``ctd-*`` presets of the fabric library from Feng et al.'s (2022) data set, by the rule of
:mod:`rftstatic.fabrics.library`, and print each chosen row as published.

Usage (the file from github.com/DrapeTester/ClothDrapeTester, commit 24a980c, ``dataset/dataset.csv``)::

    python tools/select_ctd_fabrics.py dataset.csv

Bending length c = (k1 / (rho g))^(1/3) [m] with k1 = "linear warp/weft[SI*1e9]" x 1e-9 N m and rho =
"density[kg.m-2]"; a row's percentile rank is the percentage of rows strictly below it. For each target
(weight rank, mean-bending-length rank) the row nearest in the larger of the two rank differences is
chosen (the first row on a tie). Also printed: the data set's 5th, 50th and 95th percentiles of
k2 kappa / k1 at kappa = 1 / c (how far the data set's nonlinear law departs from k1 at that curvature).
"""

import sys

import numpy as np

from rftstatic.fabrics.library import CTD_TARGETS
from rftstatic.units import STANDARD_GRAVITY


def main(path: str) -> None:
    lines = open(path).read().splitlines()
    data = np.array([[float(c) for c in line.split(",")] for line in lines[1:]])
    rho, k1, k2 = data[:, 0], data[:, 1:3] * 1e-9, data[:, 4:6] * 1e-12
    c = (k1 / (rho[:, None] * STANDARD_GRAVITY)) ** (1.0 / 3.0)
    c_mean = np.sqrt(c[:, 0] * c[:, 1])
    rank_w = np.array([(rho < v).mean() * 100 for v in rho])
    rank_c = np.array([(c_mean < v).mean() * 100 for v in c_mean])
    print(f"{len(data)} rows; k2 kappa/k1 at kappa = 1/c, 5/50/95th percentiles (warp, weft):",
          np.percentile(k2 / k1 / c, [5, 50, 95], axis=0).round(3).tolist())
    for kind, (tw, tc) in CTD_TARGETS.items():
        row = int(np.argmin(np.maximum(abs(rank_w - tw), abs(rank_c - tc))))
        print(f"ctd-{row}-{kind}: ranks {rank_w[row]:.1f} / {rank_c[row]:.1f}, c = {c[row, 0] * 100:.4g} / "
              f"{c[row, 1] * 100:.4g} cm, row as published: {lines[row + 1]}")


if __name__ == "__main__":
    main(sys.argv[1])
