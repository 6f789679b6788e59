"""Each measure of a study against each varied key: ``DIR/plots/MEASURE.png``.

One numeric varied key: a line of the measure against it. Two: a map over the two keys (filled
contours through the points when there are at least three not on one line, the points coloured by the
measure on top). More: one panel per key, the measure against it as points. Failed points and
measures a scene does not have (no drape on a strip) are left out. matplotlib is imported here only.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _numeric(values) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def plot_study(rows: list[dict], keys: list[str], measures: list[str], folder: Path) -> list[Path]:
    """Draw every measure that has values in ``rows`` (the study's points; failed ones are left out) against
    the numeric varied ``keys``; return the files."""
    rows = [r for r in rows if r.get("status") != "failed"]
    keys = [k for k in keys if rows and _numeric([r.get(k) for r in rows])]
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
        X = np.array([[r[k] for k in keys] for r in pts], float)
        if len(keys) == 2:
            fig, ax = plt.subplots(figsize=(5.5, 4.5))
            _map(ax, X, y, keys, m)
        else:
            fig, axes = plt.subplots(1, len(keys), figsize=(4.5 * len(keys), 3.8), squeeze=False)
            for j, (ax, k) in enumerate(zip(axes[0], keys)):
                order = np.argsort(X[:, j])
                ax.plot(X[order, j], y[order], "o-" if len(keys) == 1 else "o", ms=4)
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
    sc = ax.scatter(X[:, 0], X[:, 1], c=y, cmap="viridis", edgecolors="k", s=30)
    plt.colorbar(sc, ax=ax, label=m)
    ax.margins(0.05)
    ax.set_xlabel(keys[0])
    ax.set_ylabel(keys[1])
