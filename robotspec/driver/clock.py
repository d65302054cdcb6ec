"""Clocks: the loop's notion of time, real or simulated.

Why an abstraction: tests must run in simulated time, deterministically, with no sleeping and no
timing assertions, while ``robotspec drive`` and the benchmark need real periodic scheduling. The
driver only ever calls :meth:`Clock.now` and :meth:`Clock.sleep_until`.
"""

from __future__ import annotations

import time
from typing import Protocol

__all__ = ["Clock", "RealClock", "SimClock"]


class Clock(Protocol):
    """What the driver loop needs from time."""

    def now(self) -> float:
        """Monotonic seconds."""
        ...

    def sleep_until(self, deadline: float) -> None:
        """Return at (or just after) ``deadline``; return at once if it has passed."""
        ...


class SimClock:
    """Simulated time: ``sleep_until`` jumps to the deadline, so loops run as fast as the CPU.

    Why: a 10 s trajectory is tested in milliseconds, and every run gives the same numbers.
    """

    def __init__(self, start: float = 0.0) -> None:
        self._t = start

    def now(self) -> float:
        """The simulated time in seconds."""
        return self._t

    def sleep_until(self, deadline: float) -> None:
        """Advance simulated time to ``deadline`` (never backwards)."""
        if deadline > self._t:
            self._t = deadline

    def advance(self, dt: float) -> None:
        """Move simulated time forward by ``dt`` seconds."""
        self._t += max(0.0, dt)


class RealClock:
    """Wall-clock scheduling: sleep most of the wait, then spin the last part.

    Why spin: ``time.sleep`` overshoots by 50-100 µs on a loaded Linux box, which alone would use up
    most of a 0.25 ms p99 budget at 1 kHz. Spinning only the last ``spin_s`` keeps CPU use low.
    """

    def __init__(self, spin_s: float = 2e-4) -> None:
        self.spin_s = spin_s

    def now(self) -> float:
        """``time.perf_counter()``."""
        return time.perf_counter()

    def sleep_until(self, deadline: float) -> None:
        """Sleep, then spin, until ``deadline``."""
        remaining = deadline - time.perf_counter()
        if remaining > self.spin_s:
            time.sleep(remaining - self.spin_s)
        while time.perf_counter() < deadline:
            pass
