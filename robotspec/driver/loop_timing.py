"""The loop's own account of its timing: steps run, periods missed, the latest wake-up.

Why the loop counts these itself: whether a client's upload (or anything else) stalled the loop
is a question about the loop's deadlines, which only the loop knows. It counts by its own clock
at the moment it wakes, so a benchmark or a test reads the same figures whatever clock drives
it (real, simulated or jittery), and no observer thread has to sample it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["LoopStats", "LoopTiming"]


@dataclass(frozen=True)
class LoopStats:
    """A snapshot of :class:`LoopTiming`.

    Attributes:
        steps: timesteps run.
        missed_periods: deadlines skipped because a wake-up came a period or more late (what
            the loop does then: it skips them rather than catching up).
        worst_late_s: the latest wake-up past its deadline, in seconds.
        period: the loop's nominal period, in seconds.
    """

    steps: int
    missed_periods: int
    worst_late_s: float
    period: float

    @property
    def worst_late_periods(self) -> float:
        """The latest wake-up in periods (0: on time; 1.5: one period missed and a half)."""
        return self.worst_late_s / self.period

    def since(self, earlier: LoopStats) -> LoopStats:
        """The steps and missed periods since ``earlier`` (the worst is this snapshot's own)."""
        return LoopStats(
            self.steps - earlier.steps,
            self.missed_periods - earlier.missed_periods,
            self.worst_late_s,
            self.period,
        )


class LoopTiming:
    """Counts, at each wake-up, how late it came and which deadlines it skipped.

    Args:
        period: the loop's period in seconds.
        start: the clock time of the first deadline.
    """

    def __init__(self, period: float, start: float) -> None:
        self.period = period
        #: The next deadline the loop sleeps until.
        self.next_deadline = start
        self._steps = 0
        self._missed = 0
        self._worst_late = 0.0

    def woke(self, t: float) -> None:
        """The loop woke at ``t`` for ``next_deadline``: count it and set the next deadline.

        Missed deadlines are skipped, not caught up (as the reference does): the next one is
        the first still ahead of ``t``.
        """
        period = self.period
        late = t - self.next_deadline
        self.next_deadline += period
        if t > self.next_deadline:
            missed = math.floor((t - self.next_deadline) / period) + 1
            self.next_deadline += missed * period
            self._missed += missed
        self._steps += 1
        if late > self._worst_late:
            self._worst_late = late

    def stats(self) -> LoopStats:
        """The counts so far."""
        return LoopStats(self._steps, self._missed, self._worst_late, self.period)

    def reset_worst(self) -> None:
        """Start a new window for :attr:`LoopStats.worst_late_s` (the counts keep running)."""
        self._worst_late = 0.0
