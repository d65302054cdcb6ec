"""A one-line progress bar on stderr, for long commands (collision matrix, SRDF audit).

A CLI concern: the library reports progress through a ``progress(done, total)`` callback and
never draws. Why not rich's bar (installed with typer): the policy here is small and tested to
the character: off when stderr is not a terminal (CI logs, pipes) unless asked for.
"""

from __future__ import annotations

import sys
import time
from typing import TextIO

__all__ = ["Progress"]


class Progress:
    """``label [#####.....] done/total  elapsed`` rewritten in place, at most 10 times a second.

    ``enabled=None`` shows the bar only when ``stream`` is a terminal.
    """

    def __init__(
        self,
        total: int,
        label: str,
        *,
        stream: TextIO | None = None,
        enabled: bool | None = None,
        width: int = 30,
    ) -> None:
        self.total = max(int(total), 0)
        self.label = label
        self.stream = sys.stderr if stream is None else stream
        if enabled is None:
            isatty = getattr(self.stream, "isatty", None)
            enabled = bool(isatty and isatty())
        self.enabled = enabled
        self.width = width
        self.done = 0
        self._start = time.perf_counter()
        self._last = -1.0
        self._shown = False
        self._drawn = -1

    def update(self, n: int = 1) -> None:
        """Count ``n`` more units done and redraw if due."""
        self.done = min(self.done + n, self.total)
        now = time.perf_counter()
        if self.enabled and (now - self._last >= 0.1 or self.done == self.total):
            self._last = now
            self._draw(now)

    def report(self, done: int, total: int) -> None:
        """The library's ``progress(done, total)`` callback: set the total, advance to ``done``."""
        self.total = max(int(total), 0)
        self.update(done - self.done)

    def _draw(self, now: float) -> None:
        frac = self.done / self.total if self.total else 1.0
        filled = int(round(frac * self.width))
        bar = "#" * filled + "." * (self.width - filled)
        text = f"\r{self.label} [{bar}] {self.done}/{self.total}  {now - self._start:.1f} s"
        self.stream.write(text)
        self.stream.flush()
        self._shown = True
        self._drawn = self.done

    def close(self) -> None:
        """Finish the line (only if a bar was drawn)."""
        if self.enabled and self._shown:
            if self._drawn != self.done:
                self._draw(time.perf_counter())
            self.stream.write("\n")
            self.stream.flush()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
