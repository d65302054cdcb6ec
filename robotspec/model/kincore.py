"""Which kinematics core runs the queries: the C accelerator or its numpy fallback.

Why a choice: ``_kincore.c`` is built when the package is installed, but a user without a C
compiler still installs robotspec (setup.py makes the build optional) and gets the same answers
from ``_kincore_py`` (numpy), slower. ``ROBOTSPEC_NO_ACCEL=1`` chooses the fallback even when
the C core is there (to compare, or to rule it out). The choice is made once, on the first query
(not on import: a command that never computes a pose never loads either core), and
:func:`accelerated` tells which it was.

Every entry point is the C core's (see ``_kincore.pyi``), except that :func:`fk_batch` takes
``threads``: the batch is split into that many slices, each one call of the core on its own
Python thread (the C core releases the GIL while it runs, so the slices run in parallel).
"""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType
from typing import Any

import numpy as np

from robotspec.accel import NO_ACCEL_ENV, CoreChoice, accelerators_disabled
from robotspec.arrays import F64
from robotspec.model.slices import run_slices

__all__ = [
    "CHOICE",
    "INTERFACE",
    "NO_ACCEL_ENV",
    "accelerated",
    "accelerators_disabled",
    "core",
    "fk_batch",
]

#: The version of the calls into ``_kincore.c`` (its ``KINCORE_INTERFACE``): bump both together
#: whenever an entry point's arguments, results or table layout change, so that a core left from
#: an older build is refused (robotspec/accel.py) instead of misreading the new tables.
INTERFACE = 1
#: The C kinematics core and its numpy fallback.
CHOICE = CoreChoice("robotspec.model._kincore", "robotspec.model._kincore_py", INTERFACE)
#: The kinematics core in use, loaded on the first call (the choice's own method: queries call it
#: once each, so no wrapper frame sits in front of it).
core: Callable[[], ModuleType] = CHOICE.core


def accelerated() -> bool:
    """Whether queries run in the C core (False: the numpy fallback)."""
    return CHOICE.accelerated()


def fk_batch(
    tree: object, q: object, threads: int = 1, out: Any = None, module: ModuleType | None = None
) -> F64:
    """Every body pose (N, B, 4, 4) of the batch ``q`` (N, D), into ``out`` when given.

    With ``threads`` > 1 the samples are split into that many contiguous slices, one core call
    each on its own thread; the result does not depend on the split. ``q`` is checked whole
    before any slice runs, so an error leaves ``out`` untouched. A ``q`` that is not an array
    (a list of lists) is converted first, as the core converts it (same errors), so that it is
    split over the threads too instead of running on one. ``module`` is the core that built
    ``tree`` (default: the one in use).
    """
    c = core() if module is None else module
    if isinstance(threads, bool) or not isinstance(threads, int) or not 1 <= threads <= 64:
        raise ValueError(f"threads must be between 1 and 64, got {threads!r}")
    if not isinstance(q, np.ndarray):
        from robotspec.model._core_args import from_any

        q = from_any(q, np.float64, 2, 2)
    n = q.shape[0] if isinstance(q, np.ndarray) and q.ndim == 2 else 0
    threads = min(threads, n)
    if threads <= 1:
        poses: F64 = c.fk_batch(tree, q, out, out is not None)
        return poses
    from robotspec.model._core_args import from_any
    from robotspec.model._kincore_py import check_out

    n_out, n_dof = c.tree_size(tree)
    # Converted once here (native, contiguous float64), not once per slice by the core; read
    # and checked as the core reads and checks it, so the errors are the core's.
    arr = np.ascontiguousarray(from_any(q, np.float64, 2, 2))
    if arr.shape[1] != n_dof:
        raise ValueError("configuration has the wrong number of values")
    if not np.isfinite(arr).all():
        raise ValueError("configuration contains NaN or infinite values")
    stream = out is not None
    if stream:  # the core's checks of the caller's array, once (each slice is a view of it)
        check_out(out, (n, n_out, 4, 4))
    result: F64 = np.empty((n, n_out, 4, 4)) if out is None else out

    def run(lo: int, hi: int) -> None:
        c.fk_batch(tree, arr[lo:hi], result[lo:hi], stream)

    run_slices(n, threads, run)
    return result
