"""A minimal progress bar for terminals (silent when stderr is not a TTY)."""

from __future__ import annotations

import sys
import time

#: set by ``--quiet`` (every command): no bar even on a terminal
QUIET = False


class Progress:
    def __init__(self, label: str, *, stream=None, enabled: bool | None = None):
        self.stream = stream or sys.stderr
        self.enabled = (self.stream.isatty() and not QUIET) if enabled is None else enabled
        self.label = label
        self.t0 = time.perf_counter()
        self._last = -1

    def __call__(self, fraction: float):
        if not self.enabled:
            return
        pct = int(100 * fraction)
        if pct == self._last:
            return
        self._last = pct
        bar = "#" * (pct // 4) + "." * (25 - pct // 4)
        el = time.perf_counter() - self.t0
        self.stream.write(f"\r{self.label} [{bar}] {pct:3d}%  {el:5.1f} s")
        if fraction >= 1:
            self.stream.write("\n")
        self.stream.flush()
