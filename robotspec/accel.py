"""The C accelerators and their portable fallbacks: which module answers, chosen once.

Why one place: each compiled core (``model/_kincore.c``, ``collision/_meshcore.c``) has a
pure-Python fallback with the same entry points and answers. A user without a C compiler still
installs robotspec (setup.py makes the build optional), and ``ROBOTSPEC_NO_ACCEL=1`` chooses the
fallbacks even where the C cores are built (to compare, or to rule them out). The choice is made
on the first query, not on import, so a command that computes nothing loads neither.
"""

from __future__ import annotations

import importlib
import os
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import ModuleType

__all__ = ["NO_ACCEL_ENV", "CoreChoice", "accelerators_disabled", "using"]

#: The environment variable that turns the C accelerators off (any value but "", "0").
NO_ACCEL_ENV = "ROBOTSPEC_NO_ACCEL"


def accelerators_disabled() -> bool:
    """Whether ``ROBOTSPEC_NO_ACCEL`` asks for the pure-Python cores."""
    return os.environ.get(NO_ACCEL_ENV, "").strip() not in ("", "0")


class CoreChoice:
    """A compiled module and its fallback; :meth:`core` loads the one to use, once."""

    def __init__(self, compiled: str, fallback: str) -> None:
        self.compiled = compiled
        self.fallback = fallback
        self._core: ModuleType | None = None
        self._lock = threading.Lock()

    def _load(self) -> ModuleType:
        if not accelerators_disabled():
            try:
                return importlib.import_module(self.compiled)
            except ImportError:  # not built (no compiler at install): the fallback answers
                pass
        return importlib.import_module(self.fallback)

    def core(self) -> ModuleType:
        """The module in use (loaded on the first call)."""
        if self._core is None:
            with self._lock:
                if self._core is None:
                    self._core = self._load()
        return self._core

    def accelerated(self) -> bool:
        """Whether the compiled module answers (False: the fallback)."""
        return self.core().__name__ == self.compiled

    @contextmanager
    def using(self, module: ModuleType) -> Iterator[None]:
        """Answer with ``module`` inside the block (tests and benchmarks compare the two)."""
        saved = self._core
        self._core = module
        try:
            yield
        finally:
            self._core = saved


@contextmanager
def using(*pairs: tuple[CoreChoice, ModuleType]) -> Iterator[None]:
    """Several choices overridden at once, e.g. ``using((kincore.CHOICE, kin), ...)``."""
    if not pairs:
        yield
        return
    (choice, module), rest = pairs[0], pairs[1:]
    with choice.using(module), using(*rest):
        yield
