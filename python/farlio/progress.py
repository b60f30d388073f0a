"""A one-line progress display with a live frame rate (stderr, only on a terminal)."""

from __future__ import annotations

import sys
import time

#: seconds between redraws
REDRAW_PERIOD_S = 0.2


class Progress:
    def __init__(self, total: int, label: str, enabled: bool | None = None):
        self.total = total
        self.label = label
        self.enabled = sys.stderr.isatty() if enabled is None else enabled
        self.start = time.perf_counter()
        self._last = 0.0
        self.done = 0

    def update(self, done: int, extra: str = "") -> None:
        self.done = done
        now = time.perf_counter()
        if not self.enabled or (now - self._last < REDRAW_PERIOD_S and done < self.total):
            return
        self._last = now
        rate = done / max(now - self.start, 1e-9)
        width = 30
        filled = int(width * done / max(self.total, 1))
        sys.stderr.write(
            f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] {done}/{self.total} {rate:5.1f} Hz {extra}   "
        )
        sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")
