"""A minimal progress bar on stderr for long CLI work (never used inside traced code)."""

from __future__ import annotations

import sys
import time


class Progress:
    """Context manager printing ``label [#####     ] k/n  elapsed`` to stderr.

    Silent when ``enabled`` is False or stderr is not a terminal (unless forced).
    """

    def __init__(self, total: int, label: str = "", enabled: bool = True, force: bool = False):
        self.total = max(int(total), 1)
        self.label = label
        self.enabled = enabled and (force or sys.stderr.isatty())
        self.k = 0
        self.t0 = time.perf_counter()

    def __enter__(self):
        self._draw()
        return self

    def update(self, n: int = 1):
        self.k = min(self.k + n, self.total)
        self._draw()

    def _draw(self):
        if not self.enabled:
            return
        width = 30
        filled = int(width * self.k / self.total)
        bar = "#" * filled + " " * (width - filled)
        dt = time.perf_counter() - self.t0
        sys.stderr.write(f"\r{self.label} [{bar}] {self.k}/{self.total} {dt:6.1f}s")
        sys.stderr.flush()

    def __exit__(self, *exc):
        if self.enabled:
            sys.stderr.write("\n")
            sys.stderr.flush()
        return False
