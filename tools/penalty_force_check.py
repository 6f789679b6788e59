"""Check the compiled penalty force (rftstatic.contact.penalty_compiled) against the numpy path along a whole run.

Runs a scene; at every call of ``PenaltyContact.force`` the numpy path (the reference) runs too, on a shallow copy of
the solve's candidate list (a refresh replaces the list's arrays, so the copy refreshes on its own), in alternating
order; the run continues with the compiled result. Prints the number of calls, of calls that differ in any bit, and
each path's time per call (the same process, interleaved: a ratio, not a run's time).

    PYTHONPATH=$PWD python tools/penalty_force_check.py pedestal-round-50 [--set KEY=VALUE ...]
"""

from __future__ import annotations

import argparse
import copy
import tempfile
import time

import numpy as np

import rftstatic.api as api
from rftstatic.contact import penalty


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args(argv)
    force, compiled = penalty.PenaltyContact.force, penalty.compiled_force
    calls, differ, seconds = [0], [0], {"numpy": [], "compiled": []}

    def timed(path, contact, x, candidates):
        penalty.compiled_force = compiled if path == "compiled" else (lambda *a: None)
        try:
            t0 = time.perf_counter()
            out = force(contact, x, candidates=candidates)
            seconds[path].append(time.perf_counter() - t0)
            return out
        finally:
            penalty.compiled_force = compiled

    def checked(contact, x, *, candidates=None):
        mirror = copy.copy(candidates)
        if calls[0] % 2:
            ref, new = timed("numpy", contact, x, mirror), timed("compiled", contact, x, candidates)
        else:
            new, ref = timed("compiled", contact, x, candidates), timed("numpy", contact, x, mirror)
        calls[0] += 1
        differ[0] += not np.array_equal(ref.view(np.int64), new.view(np.int64))
        return new

    penalty.PenaltyContact.force = checked
    try:
        with tempfile.TemporaryDirectory() as out:
            api.run(args.scene, out, overrides=args.set, figures=False)
    finally:
        penalty.PenaltyContact.force = force
    line = f"{args.scene}: {calls[0]} force calls, {differ[0]} differ in some bit"
    for path, t in seconds.items():
        t = np.array(t) * 1e6
        if t.size:
            line += f"; {path} {t.mean():.1f} us mean, {np.median(t):.1f} us median a call"
    print(line)
    return 1 if differ[0] else 0


if __name__ == "__main__":
    raise SystemExit(main())
