"""Which mesh core the collision checker uses: the C proofs or the fallback that leaves all to coal.

Why a choice: ``_meshcore.c`` proves mesh pairs apart (or crossing) before coal's narrow phase,
tens of times cheaper than coal on nearly touching meshes, but it is an accelerator only: without
it (not built, or ``ROBOTSPEC_NO_ACCEL=1``, see :mod:`robotspec.model.kincore`) ``_meshcore_py``
checks the same arguments, proves nothing, and coal answers every candidate. Chosen once, on the
checker's first query.
"""

from __future__ import annotations

import threading
from types import ModuleType

from robotspec.model.kincore import accelerators_disabled

__all__ = ["accelerated", "core"]

_core: ModuleType | None = None
_lock = threading.Lock()


def _load() -> ModuleType:
    if not accelerators_disabled():
        try:
            from robotspec.collision import _meshcore
        except ImportError:  # not built (no compiler at install): coal answers alone
            pass
        else:
            return _meshcore
    from robotspec.collision import _meshcore_py

    return _meshcore_py


def core() -> ModuleType:
    """The mesh core in use (loaded on the first call)."""
    global _core
    if _core is None:
        with _lock:
            if _core is None:
                _core = _load()
    return _core


def accelerated() -> bool:
    """Whether mesh pairs are proven apart in C first (False: coal tests every candidate)."""
    return core().__name__.endswith("._meshcore")
