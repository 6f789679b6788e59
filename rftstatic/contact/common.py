"""Argument checks shared by the contact laws: obstacle lists and point arrays."""

from __future__ import annotations

import numpy as np


def as_list(obstacles) -> list:
    """Obstacles as a list; a single obstacle is accepted. Raise naming a bad entry."""
    items = [obstacles] if hasattr(obstacles, "signed_distance") else list(obstacles)
    for i, ob in enumerate(items):
        if not (hasattr(ob, "signed_distance") and hasattr(ob, "normal_gradient")):
            raise ValueError(
                f"obstacles[{i}] = {ob!r} is not an obstacle (needs signed_distance and normal_gradient)"
            )
    return items


def as_points(x, n_nodes: int | None = None, name: str = "x") -> np.ndarray:
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 3 or (n_nodes is not None and arr.shape[0] != n_nodes):
        want = "(N, 3)" if n_nodes is None else f"({n_nodes}, 3)"
        raise ValueError(f"{name} must have shape {want}, got shape {arr.shape}")
    return arr


def positive(name: str, value, *, allow_zero: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        raise ValueError(f"{name} must be a finite number {'>= 0' if allow_zero else '> 0'}, got {value!r}")
    return v
