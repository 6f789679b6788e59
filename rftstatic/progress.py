"""A dependency-free progress bar for long loops (load factor, simulated time).

On a terminal it redraws one line on stderr; otherwise (CI, files) it logs at every tenth of the
way, so logs stay short.
"""

from __future__ import annotations

import logging
import sys
import time

log = logging.getLogger("rftstatic")


class Progress:
    """Progress of a quantity from 0 to ``total`` (e.g. load factor 1, or end time [s])."""

    def __init__(self, total: float, label: str, *, unit: str = "", enabled: bool = True, stream=None):
        self.total = float(total)
        self.label, self.unit = label, unit
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = enabled and hasattr(self.stream, "isatty") and self.stream.isatty()
        self._next_log = 0.1
        self._t0 = time.perf_counter()

    def update(self, value: float, note: str = "") -> None:
        if not self.enabled:
            return
        frac = min(max(value / self.total, 0.0), 1.0) if self.total > 0 else 1.0
        elapsed = time.perf_counter() - self._t0
        if self.tty:
            n = int(30 * frac)
            bar = "#" * n + "-" * (30 - n)
            self.stream.write(f"\r{self.label} [{bar}] {value:.4g}/{self.total:.4g}{self.unit} "
                              f"{elapsed:6.1f}s {note[:40]:<40}")
            self.stream.flush()
        elif frac >= self._next_log:
            log.info("%s: %.0f%% (%.4g%s) %.1fs %s", self.label, 100 * frac, value, self.unit, elapsed, note)
            while self._next_log <= frac:
                self._next_log += 0.1

    def close(self) -> None:
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()
