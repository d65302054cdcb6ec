"""Clocks: the loop's notion of time, real or simulated.

Why an abstraction: tests must run in simulated time, deterministically, with no sleeping and no
timing assertions, while ``robotspec drive`` and the benchmark need real periodic scheduling. The
driver only ever calls :meth:`Clock.now` and :meth:`Clock.sleep_until`.
"""

from __future__ import annotations

import random
import time
from typing import Protocol

__all__ = ["MAX_STEP_PERIODS", "Clock", "JitteryClock", "RealClock", "SimClock", "step_duration"]

#: A step never integrates more than this many periods of motion, in the driver's profiles and in
#: the simulated arm alike. Why: after a long stall (a debugger, a suspended process) neither may
#: jump the arm by seconds of motion in one go, and both must agree on what a step covers.
MAX_STEP_PERIODS = 10.0


def step_duration(now: float, last: float | None, period: float) -> float:
    """The time one step covers: ``now - last`` within ``[0, MAX_STEP_PERIODS * period]``.

    The first step (``last`` None) covers one period. The driver's profiles and the simulated arm
    both use this, so they integrate the same elapsed time.
    """
    if last is None:
        return period
    dt = now - last
    if not dt > 0.0:
        return 0.0
    cap = MAX_STEP_PERIODS * period
    return cap if dt > cap else dt


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


class JitteryClock(SimClock):
    """Simulated time whose wake-ups are late by a random, seeded amount (loop jitter).

    Why: the driver must end its motions where it was asked even when its periods jitter, as
    they do on a loaded machine; tests and the jitter benchmark inject it deterministically.
    Each ``sleep_until`` returns ``late`` seconds after its deadline, ``late`` drawn from an
    exponential distribution of mean ``mean_late`` (capped at ``max_late``).

    Args:
        mean_late: mean lateness of a wake-up, seconds.
        max_late: largest lateness, seconds.
        seed: the random sequence (same seed, same run).
        start: the start time.
    """

    def __init__(
        self, mean_late: float, max_late: float, seed: int = 0, start: float = 0.0
    ) -> None:
        super().__init__(start)
        self.mean_late = mean_late
        self.max_late = max_late
        self._rng = random.Random(seed)

    def sleep_until(self, deadline: float) -> None:
        """Advance to ``deadline`` plus a random lateness (never backwards)."""
        late = self._rng.expovariate(1.0 / self.mean_late) if self.mean_late > 0 else 0.0
        super().sleep_until(deadline + min(late, self.max_late))
