"""The C accelerators and their portable fallbacks: which module answers, chosen once, and why.

Why one place: each compiled core (``model/_kincore.c``, ``collision/_meshcore.c``) has a
pure-Python fallback with the same entry points and answers. A user without a C compiler still
installs robotspec (setup.py makes the build optional), and ``ROBOTSPEC_NO_ACCEL=1`` chooses the
fallbacks even where the C cores are built (to compare, or to rule them out). The choice is made
on the first query, not on import, so a command that computes nothing loads neither.

Why an interface version: a compiled core is a file left behind by a build. An editable install
whose ``.so`` predates a change of the Python side (new arguments, a new table layout) would load
and misread its tables. Each core therefore carries ``INTERFACE``, an integer compiled into it,
and its Python side names the one it speaks; a core with another number (or none: built before
the numbers existed) is refused, the fallback answers, and a :class:`StaleCoreWarning` says so
once. :func:`report` says, for each core, which module answers and why (``robotspec doctor``).
"""

from __future__ import annotations

import importlib
import os
import threading
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from types import ModuleType

__all__ = [
    "NO_ACCEL_ENV",
    "CoreChoice",
    "CoreStatus",
    "StaleCoreWarning",
    "accelerated",
    "accelerators_disabled",
    "choices",
    "report",
    "using",
]

#: The environment variable that turns the C accelerators off (any value but "", "0").
NO_ACCEL_ENV = "ROBOTSPEC_NO_ACCEL"


class StaleCoreWarning(RuntimeWarning):
    """A compiled core speaks another interface than its Python side: the fallback answers."""


def accelerators_disabled() -> bool:
    """Whether ``ROBOTSPEC_NO_ACCEL`` asks for the pure-Python cores."""
    return os.environ.get(NO_ACCEL_ENV, "").strip() not in ("", "0")


@dataclass(frozen=True)
class CoreStatus:
    """Which module answers for one core, and why (what ``robotspec doctor`` prints).

    Attributes:
        name: the compiled module's name (``robotspec.model._kincore``).
        accelerated: whether the C core answers (False: the fallback).
        module: the name of the module that answers.
        reason: why that one: the file loaded, or why the C core was not used.
    """

    name: str
    accelerated: bool
    module: str
    reason: str


class CoreChoice:
    """A compiled module and its fallback; :meth:`core` loads the one to use, once.

    ``interface`` is the version of the calls between the compiled module and its Python side:
    the compiled module's ``INTERFACE`` must equal it, else it is refused as stale.
    """

    def __init__(self, compiled: str, fallback: str, interface: int) -> None:
        self.compiled = compiled
        self.fallback = fallback
        self.interface = interface
        self._core: ModuleType | None = None
        self._reason = ""
        self._lock = threading.Lock()

    def _compiled_or_reason(self) -> tuple[ModuleType | None, str]:
        """The compiled module, or None and why it cannot answer."""
        if accelerators_disabled():
            return None, f"{NO_ACCEL_ENV} is set"
        try:
            module = importlib.import_module(self.compiled)
        except ImportError as exc:  # not built (no compiler at install): the fallback answers
            return None, f"not built ({exc})"
        found = getattr(module, "INTERFACE", None)
        if found != self.interface:
            where = getattr(module, "__file__", self.compiled)
            speaks = "no interface version" if found is None else f"interface {found!r}"
            reason = (
                f"stale build refused: {where} speaks {speaks}, this robotspec needs interface "
                f"{self.interface}; rebuild it (pip install --force-reinstall robotspec, or "
                "pip install -e . in a checkout)"
            )
            # Once per choice (it is loaded once); stacklevel points past the query's frames.
            warnings.warn(
                f"robotspec: {self.compiled}: {reason}; using the slower fallback {self.fallback}",
                StaleCoreWarning,
                stacklevel=4,
            )
            return None, reason
        return module, f"loaded from {getattr(module, '__file__', self.compiled)}"

    def _load(self) -> ModuleType:
        module, self._reason = self._compiled_or_reason()
        return module if module is not None else importlib.import_module(self.fallback)

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

    def status(self) -> CoreStatus:
        """Which module answers and why (loads the core if no query has yet)."""
        module = self.core()
        reason = self._reason or "chosen by the caller (accel.using)"
        return CoreStatus(self.compiled, module.__name__ == self.compiled, module.__name__, reason)

    @contextmanager
    def using(self, module: ModuleType) -> Iterator[None]:
        """Answer with ``module`` inside the block (tests and benchmarks compare the two)."""
        saved, saved_reason = self._core, self._reason
        self._core, self._reason = module, ""
        try:
            yield
        finally:
            self._core, self._reason = saved, saved_reason


def choices() -> tuple[CoreChoice, ...]:
    """Every core's choice: kinematics, then mesh proofs (imported here: they import this)."""
    from robotspec.collision import meshcore
    from robotspec.model import kincore

    return (kincore.CHOICE, meshcore.CHOICE)


def accelerated() -> bool:
    """Whether every compiled core answers (False: at least one query runs in a fallback)."""
    return all(choice.accelerated() for choice in choices())


def report() -> tuple[CoreStatus, ...]:
    """For each core, which module answers and why."""
    return tuple(choice.status() for choice in choices())


@contextmanager
def using(*pairs: tuple[CoreChoice, ModuleType]) -> Iterator[None]:
    """Several choices overridden at once, e.g. ``using((kincore.CHOICE, kin), ...)``."""
    if not pairs:
        yield
        return
    (choice, module), rest = pairs[0], pairs[1:]
    with choice.using(module), using(*rest):
        yield
