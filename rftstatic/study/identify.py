"""How well a fit's targets determine its free keys: the sensitivity matrix at the optimum.

S[i, j] = d log m_i / d log k_j (target i, free key j; central differences of the fit). A relative
error e (a vector over the targets: the measurements' or the mesh's) moves the fitted keys by about
S^+ e (S^+ the pseudo-inverse), so:

- the *amplification* of key j, |row j of S^+| (the 2-norm), is the most a 1 % error of unit norm can
  move k_j, in %; with one target and one key it is 1/|s| (the strip's tip drop: s = -0.10, ~10 x);
- a small singular value of S against the largest (a large condition number) is a combination of keys
  that the targets barely see: they cannot tell those keys apart (e.g. B_warp and B_weft from the warp
  strip alone), and the fit picks one of many nearly equal answers;
- fewer targets than free keys can never identify them all.
"""

from __future__ import annotations

import math

import numpy as np

WEAK_SENSITIVITY = 0.2
"""A key whose amplification exceeds 1 / this (5 %: an error of 1 % in the measurements) is reported."""
NEAR_SINGULAR = 20.0
"""A sensitivity matrix whose condition number exceeds this is reported as near-singular."""


def analyse(sensitivity: dict, keys: list[str]) -> dict:
    """The matrix, its singular values, condition number and each key's amplification (module docstring);
    ``sensitivity``: {target: {key: s or None}}. A matrix with a missing entry (a measure of 0) has only
    ``matrix``, ``targets``, ``keys``."""
    targets = list(sensitivity)
    S = np.array([[np.nan if sensitivity[t].get(k) is None else sensitivity[t][k] for k in keys] for t in targets],
                 dtype=float)
    out = {"targets": targets, "keys": list(keys), "matrix": [[_num(v) for v in row] for row in S]}
    if S.size == 0 or not np.all(np.isfinite(S)):
        return out
    u, sv, vt = np.linalg.svd(S, full_matrices=False)
    smallest = sv[-1] if len(keys) <= len(targets) else 0.0  # more keys than targets: a null direction
    condition = math.inf if smallest == 0 else float(sv[0] / smallest)
    pinv = np.linalg.pinv(S)
    out.update(singular_values=[float(v) for v in sv], condition_number=_num(condition),
               weakest_combination={k: float(c) for k, c in zip(keys, _weakest(S, vt))},
               amplification={k: float(np.linalg.norm(pinv[j])) for j, k in enumerate(keys)})
    return out


def _weakest(S: np.ndarray, vt: np.ndarray) -> np.ndarray:
    """The unit combination of log keys that moves the targets least (a null vector with fewer targets)."""
    if S.shape[1] > S.shape[0]:
        full = np.linalg.svd(S, full_matrices=True)[2]
        v = full[-1]
    else:
        v = vt[-1]
    return v * (1 if v[np.argmax(np.abs(v))] > 0 else -1)


def _num(v):
    return None if v is None or not math.isfinite(v) else float(v)


def warnings(analysis: dict) -> list[str]:
    """The lines the fit prints on stderr: too few targets, a near-singular matrix, each weakly
    identified key (module docstring)."""
    keys, targets = analysis["keys"], analysis["targets"]
    lines = []
    if "amplification" not in analysis:
        return ["the sensitivity matrix has a missing entry (a measure of 0 at the optimum): identifiability "
                "not assessed"]
    if len(targets) < len(keys):
        lines.append(f"{len(targets)} target(s) cannot identify {len(keys)} free keys: the fit picks one of "
                     "many answers; add a target (e.g. another run with --run) or fix a key")
    cond = analysis["condition_number"]
    if len(targets) >= len(keys) and (cond is None or cond > NEAR_SINGULAR):
        combo = " ".join(f"{c:+.2f} log {k}" for k, c in analysis["weakest_combination"].items() if abs(c) > 0.05)
        shown = "infinite" if cond is None else f"{cond:.3g}"
        lines.append(f"the sensitivity matrix is near-singular (condition number {shown}, singular values "
                     + ", ".join(f"{v:.3g}" for v in analysis["singular_values"])
                     + f"): the targets barely move when the keys change along {combo}, so that combination is "
                     "hardly determined")
    for k, amp in analysis["amplification"].items():
        if amp > 1 / WEAK_SENSITIVITY:
            lines.append(f"{k} is barely identifiable from the targets: an error of 1 % in the measurements or "
                         f"the mesh can move the fitted {k} by ~{amp:.3g} % (d log measure / d log {k}: "
                         + ", ".join(f"{t} {row[keys.index(k)]:+.3g}" for t, row in zip(targets, analysis["matrix"]))
                         + ")")
    return lines
