"""A batch cut into contiguous sample ranges, each run on its own thread, the caller's included.

Why one helper: the kinematics batch (``kincore.fk_batch``) and the collision batch
(``collision.slices``) both split work whose C loops release the GIL; contiguous slices let
each thread write its own rows of the result, so the answer does not depend on the split, and
the first error is raised on the caller's thread once every slice has ended (no thread is left
writing into the caller's arrays).
"""

from __future__ import annotations

import threading
from collections.abc import Callable

__all__ = ["run_slices"]


def run_slices(n: int, threads: int, work: Callable[[int, int], None]) -> None:
    """``work(lo, hi)`` over ``range(n)`` cut in ``threads`` contiguous slices, at once."""
    if threads <= 1:
        work(0, n)
        return
    errors: list[BaseException] = []

    def run(lo: int, hi: int) -> None:
        try:
            work(lo, hi)
        except BaseException as exc:  # noqa: BLE001 - re-raised on the caller's thread
            errors.append(exc)

    cuts = [n * k // threads for k in range(threads + 1)]
    workers = [
        threading.Thread(target=run, args=(cuts[k], cuts[k + 1]), daemon=True)
        for k in range(1, threads)
    ]
    for w in workers:
        w.start()
    run(cuts[0], cuts[1])
    for w in workers:
        w.join()
    if errors:
        raise errors[0]
