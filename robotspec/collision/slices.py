"""A batch split by sample ranges over threads: one slice per thread, the caller's thread included.

Why threads and not processes: the collision checker's batch spends its time in C loops that
release the GIL (the kinematics, the broad phase, the mesh proofs), so threads share the built
geometry and run those loops at once, where worker processes would each rebuild it. Slices are
contiguous, so each thread writes its own rows of the result and the answer does not depend on
how many threads ran.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from robotspec.errors import CollisionError
from robotspec.model.slices import run_slices

__all__ = ["MAX_THREADS", "MIN_SLICE", "checked_threads", "run_in_slices"]

#: The most threads a batch is split over.
MAX_THREADS = 64
#: Samples below which a slice is not worth a thread (starting one costs about 0.1 ms).
MIN_SLICE = 64


def checked_threads(threads: object) -> int:
    """``threads`` as an int from 1 to ``MAX_THREADS``; CollisionError naming it otherwise."""
    if (
        isinstance(threads, bool | np.bool_)
        or not isinstance(threads, int | np.integer)
        or not 1 <= threads <= MAX_THREADS
    ):
        raise CollisionError(
            f"threads must be an integer between 1 and {MAX_THREADS}, got {threads!r}",
            kind="config",
        )
    return int(threads)


def run_in_slices(n: int, threads: int, work: Callable[[int, int], None]) -> None:
    """``work(lo, hi)`` over ``range(n)`` cut in at most ``threads`` contiguous slices, at once.

    The first slice runs on the caller's thread. The first error of any slice is raised here,
    after every slice has ended (no thread is left writing into the caller's arrays).
    """
    run_slices(n, max(1, min(threads, n // MIN_SLICE)), work)
