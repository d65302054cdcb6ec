"""Which mesh core the collision checker uses: the C proofs or the fallback that leaves all to coal.

Why a choice: ``_meshcore.c`` proves mesh pairs apart (or crossing) before coal's narrow phase,
tens of times cheaper than coal on nearly touching meshes, but it is an accelerator only: without
it (not built, or ``ROBOTSPEC_NO_ACCEL=1``, see :mod:`robotspec.model.kincore`) ``_meshcore_py``
checks the same arguments, proves nothing, and coal answers every candidate. Chosen once, on the
checker's first query.
"""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType

from robotspec.accel import CoreChoice

__all__ = ["CHOICE", "INTERFACE", "accelerated", "core"]

#: The version of the calls into ``_meshcore.c`` (its ``MESHCORE_INTERFACE``): bump both together
#: whenever an entry point's arguments or results change (a stale core is refused, see
#: robotspec/accel.py).
INTERFACE = 3
#: The C mesh proofs and the fallback that proves nothing.
CHOICE = CoreChoice("robotspec.collision._meshcore", "robotspec.collision._meshcore_py", INTERFACE)
#: The mesh core in use, loaded on the first call (the choice's own method: queries call it
#: once each, so no wrapper frame sits in front of it).
core: Callable[[], ModuleType] = CHOICE.core


def accelerated() -> bool:
    """Whether mesh pairs are proven apart in C first (False: coal tests every candidate)."""
    return CHOICE.accelerated()
