"""Seeded out-of-plane starts that tip a symmetric flat sheet off its bifurcation (§6.2: drapes have
several equilibria): random smooth Fourier modes, or an n-fold lift about the sheet's centre.

All are lifts (never into an obstacle), in units of the mean element size.
"""

from __future__ import annotations

import numpy as np


def start_perturbation(mesh, opts) -> np.ndarray:
    """The out-of-plane start ``(N,)`` [m] that the solver options ``opts`` ask for (``perturbation``,
    ``perturbation_folds``, ``seed`` of :class:`~rftstatic.solvers.options.RouteOptions`): random modes
    or an n-fold lift."""
    if opts.perturbation_folds:
        return fold_perturbation(mesh, opts.perturbation_folds, opts.seed, opts.perturbation)
    return smooth_perturbation(mesh, opts.seed, opts.perturbation)


def fold_pattern(mesh, folds: int, seed: int) -> np.ndarray:
    """``(r/R)^2 cos(n theta + phi)`` at the nodes ``(N,)`` [-]: an n-fold pattern about the sheet's centroid.

    ``r``, ``theta`` are polar coordinates about the centroid, ``R`` the largest ``r``, and the phase
    ``phi`` is drawn from ``seed``. Zero at the centre, growing outwards where the skirt buckles.
    """
    rho, theta = _polar(mesh)
    phase = np.random.default_rng(seed).uniform(0, 2 * np.pi)
    return rho ** 2 * np.cos(folds * theta + phase)


def _polar(mesh) -> tuple[np.ndarray, np.ndarray]:
    """``(r / R, theta)`` of the nodes about the sheet's centroid, ``R`` the largest ``r``."""
    X = mesh.X - mesh.X.mean(axis=0)
    r = np.hypot(X[:, 0], X[:, 1])
    return r / r.max(), np.arctan2(X[:, 1], X[:, 0])


def fold_perturbation(mesh, folds: int, seed: int, amplitude: float) -> np.ndarray:
    """An n-fold out-of-plane start ``(N,)`` [m]: ``a (r/R)^2 (1 + cos(n theta + phi)) / 2``.

    ``theta`` and ``r`` are polar coordinates about the sheet's centroid, ``R`` the largest ``r``,
    ``a`` is ``amplitude`` mean element sizes and the phase ``phi`` is drawn from ``seed``. A lift
    only, like :func:`smooth_perturbation`; it grows outwards, where the skirt buckles, so that a
    symmetric drape leaves its bifurcation towards the branch with ``folds`` folds (§6.2: drapes
    have several equilibria). Whether that branch is a stable equilibrium is for the solve to say.
    """
    w = 0.5 * (_polar(mesh)[0] ** 2 + fold_pattern(mesh, folds, seed))
    return amplitude * float(mesh.element_size.mean()) * w


def smooth_perturbation(mesh, seed: int, amplitude: float) -> np.ndarray:
    """A seeded, smooth out-of-plane start ``(N,)`` [m]: random low Fourier modes of the sheet.

    Six modes with wavelengths between a half and a sixth of the sheet size, shifted and scaled to
    lie between 0 and ``amplitude`` mean element sizes (upward, never into an obstacle). Smooth, so that it tips a symmetric start
    off its bifurcation without stretching the membrane; the seed is reported with the result.
    """
    rng = np.random.default_rng(seed)
    X = mesh.X - mesh.X.mean(axis=0)
    size = float(np.ptp(mesh.X, axis=0).max())
    w = np.zeros(mesh.n_nodes)
    for _ in range(6):
        k = 2 * np.pi * rng.uniform(2.0, 6.0) / size
        direction = rng.normal(size=2)
        direction /= np.linalg.norm(direction)
        w += rng.normal() * np.cos(k * X @ direction + rng.uniform(0, 2 * np.pi))
    # lift only (0 .. amplitude): a start pushed into an obstacle would meet the full penalty
    w = (w - w.min()) / max(np.ptp(w), 1e-300)
    return amplitude * float(mesh.element_size.mean()) * w
