"""Each measure of a study against each varied key: ``DIR/plots/MEASURE.png``.

One varied key: a line of the measure against it. Two: a map over the two keys (filled contours
through the points when there are at least three not on one line, the points coloured by the measure
on top). More: one panel per key, the measure against it as points. A key with values that are not
numbers (``element = RFT3, RFT6``, ``mesh.nodes = [21,21], [41,41]``) is an axis of categories in the
order of first appearance. Failed points and measures a scene does not have (no drape on a strip) are
left out. matplotlib is imported here only.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def _numeric(values) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def _axis(values) -> tuple[np.ndarray, list[str] | None]:
    """Positions of ``values`` on an axis, and the category labels when they are not numbers."""
    if _numeric(values):
        return np.asarray(values, float), None
    labels = list(dict.fromkeys(json.dumps(v) if isinstance(v, (list, dict)) else str(v) for v in values))
    index = {label: i for i, label in enumerate(labels)}
    return np.array([index[json.dumps(v) if isinstance(v, (list, dict)) else str(v)] for v in values], float), labels


def plot_study(rows: list[dict], keys: list[str], measures: list[str], folder: Path) -> list[Path]:
    """Draw every measure that has values in ``rows`` (the study's points; failed ones are left out) against
    the numeric varied ``keys``; return the files."""
    rows = [r for r in rows if r.get("status") != "failed"]
    if not rows or not keys:
        return []
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for m in measures:
        pts = [r for r in rows if isinstance(r.get(m), (int, float))]
        if not pts:
            continue
        y = np.array([r[m] for r in pts], float)
        axes_ = [_axis([r.get(k) for r in pts]) for k in keys]
        X = np.column_stack([a for a, _ in axes_])
        if len(keys) == 2:
            fig, ax = plt.subplots(figsize=(5.5, 4.5))
            _map(ax, X, y, keys, m)
            for set_ticks, (_, labels) in zip((ax.set_xticks, ax.set_yticks), axes_):
                if labels:
                    set_ticks(range(len(labels)), labels)
        else:
            fig, axes = plt.subplots(1, len(keys), figsize=(4.5 * len(keys), 3.8), squeeze=False)
            for j, (ax, k) in enumerate(zip(axes[0], keys)):
                order = np.argsort(X[:, j], kind="stable")
                ax.plot(X[order, j], y[order], "o-" if len(keys) == 1 else "o", ms=4)
                if axes_[j][1]:
                    ax.set_xticks(range(len(axes_[j][1])), axes_[j][1])
                ax.set_xlabel(k)
                ax.set_ylabel(m)
                ax.grid(alpha=0.3)
        fig.suptitle(f"{m} ({len(pts)} points)")
        fig.tight_layout()
        path = folder / f"{m}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written


def _map(ax, X, y, keys, m) -> None:
    import matplotlib.pyplot as plt

    spread = np.linalg.matrix_rank(X[1:] - X[0]) == 2 if len(X) >= 3 else False
    if spread and np.ptp(y) > 0:
        try:
            ax.tricontourf(X[:, 0], X[:, 1], y, levels=12, cmap="viridis", alpha=0.6)
        except (ValueError, RuntimeError):  # a degenerate triangulation: the points alone
            pass
    sc = ax.scatter(X[:, 0], X[:, 1], c=y, cmap="viridis", edgecolors="k", s=36, zorder=3)
    plt.colorbar(sc, ax=ax, label=m)
    ax.use_sticky_edges = False  # the contours would pin the limits to the outer points, half hiding them
    ax.margins(0.06)
    ax.set_xlabel(keys[0])
    ax.set_ylabel(keys[1])
