"""Branch switching at a critical point of the load path (:mod:`rftstatic.solvers.continuation`).

Past a limit point or a bifurcation the tangent K has ``m > 0`` negative eigenvalues: the equilibrium
there is unstable, and the stable branches leave it along the critical modes. :func:`switch_branch`
computes the eigenvector ``phi`` of the lowest eigenvalue (shift-invert Lanczos with the path's own
factorisation, :func:`~rftstatic.solvers.inertia.lowest_modes`), pushes the state by ``+- eta phi``
(``eta`` = :data:`SWITCH_AMPLITUDE` mean element sizes at the node that moves most) and lets Newton's
line-searched descent (:func:`~rftstatic.solvers.newton.newton`, displacement iteration: an Armijo
search on the energy with the positive semi-definite or shifted tangent where K is indefinite) settle
each start at the given load factor. Of the equilibria reached, the stable ones (inertia 0) are
preferred and among them the one of lower energy (at a bifurcation) or the one farther from the
branch that ended (at a limit point); both are recorded.

At a bifurcation the two pushes give the two halves of the secondary branch (mirror images on a
symmetric sheet: equal energies); at a limit point (the load factor turned back) the load factor of
the switch lies beyond the largest one reached, where the branch that ended no longer exists, so the
descent finds the branch the sheet snaps to (the quasi-static path a slowly loaded sheet follows).
"""

from __future__ import annotations

import logging
from dataclasses import replace

import numpy as np

from rftstatic.solvers.inertia import lowest_modes
from rftstatic.solvers.linear import LinearSolveError
from rftstatic.solvers.newton import newton

log = logging.getLogger(__name__)

SWITCH_AMPLITUDE = 0.5
"""Push along the critical mode, in mean element sizes at its largest node [-]: large enough to leave
the unstable equilibrium's neighbourhood in one push (a fold's amplitude is a few element sizes), small
enough not to stretch the membrane."""

SWITCH_ITERATIONS = 150
"""Newton iterations of the descent from each push (at an intermediate load factor the solver's
``max_iterations`` would apply): a fold forming on a coarse mesh takes 20-60 line-searched steps."""

MODES = 4
"""Most eigenpairs computed at a switch (the lowest one is followed; the others are recorded)."""


def switch_branch(model, U, lam, K, fac, opts, state, inertia, max_step, *, seed=0, away_from=None):
    """Leave the unstable equilibrium ``(U (N, 3) [m], lam)`` along the lowest mode of ``K`` (free dofs,
    factorised as ``fac``, an :class:`~rftstatic.solvers.inertia.InertiaFactor`).

    Returns ``(choice, record)``: ``choice`` a dict (``U``, ``negative``, ``energy``, ``factor``,
    ``K``) of the equilibrium chosen (module docstring), or None when no push converged; ``away_from``
    (N, 3) [m]: at a limit point, the last stable state before it: the stable equilibrium farthest from
    it is chosen (the branch snapped to; the other push may fall back onto the branch that ended when
    the switch's load factor is still below the limit's); ``record`` the
    switch's summary (eigenvalues [N/m], each branch's energy [J], negative pivots and iterations).
    """
    free = model.free.ravel()
    n = model.mesh.n_nodes
    record = {"lam": float(lam), "negative_before": int(fac.negative), "branches": []}
    try:
        vals, vecs = lowest_modes(K, fac, k=min(MODES, fac.negative + 1), seed=seed)
    except (LinearSolveError, ArithmeticError, RuntimeError) as exc:  # ARPACK did not converge
        record["error"] = f"lowest mode: {exc}"
        return None, record
    record["eigenvalues"] = [float(v) for v in vals]
    phi = np.zeros(3 * n)
    phi[free] = vecs[:, 0]
    phi = phi.reshape(n, 3)
    phi /= max(float(np.linalg.norm(phi, axis=1).max()), 1e-300)
    eta = SWITCH_AMPLITUDE * float(model.mesh.element_size.mean())
    descent = replace(opts, max_iterations=max(opts.max_iterations, SWITCH_ITERATIONS), iteration="displacement")
    found = []
    for sign in (1.0, -1.0):
        nt = newton(model, U + sign * eta * phi, lam, descent, state, max_step, scheme="displacement")
        branch = {"sign": sign, "converged": bool(nt.converged), "iterations": int(nt.iterations)}
        if nt.converged:
            _, K2 = model.tangent(nt.U, lam=lam, candidates=state.candidates, pairs=state.self_pairs,
                                  slip=state.slip)
            try:
                fac2 = inertia.factor(K2)
            except LinearSolveError as exc:
                branch["error"] = str(exc)
                record["branches"].append(branch)
                continue
            energy = model.potential(nt.U, lam, candidates=state.candidates, pairs=state.self_pairs,
                                     slip=state.slip)
            branch.update(negative=fac2.negative, energy=float(energy))
            found.append({"U": nt.U, "negative": fac2.negative, "energy": energy, "factor": fac2, "K": K2,
                          "sign": sign})
        record["branches"].append(branch)
    if not found:
        return None, record
    stable = [c for c in found if c["negative"] == 0]
    pool = stable or found
    if away_from is None:
        choice = min(pool, key=lambda c: (c["negative"], c["energy"]))
    else:  # a limit point: the branch the sheet snaps to, not the one that ended
        choice = max(pool, key=lambda c: float(np.abs(c["U"] - away_from).max()))
    record["chosen"] = choice["sign"]
    record["negative_after"] = int(choice["negative"])
    log.info("branch switch at load factor %.6g: lowest eigenvalue %.3g N/m, branch %+g (energy %.6g J, %d "
             "negative pivots)", lam, vals[0], choice["sign"], choice["energy"], choice["negative"])
    return choice, record
