"""How Robot Raconteur calls reach the driver: errors mapped, blocking calls answered later.

The driver raises its own errors (:mod:`robotspec.driver.errors`); clients must see the Robot
Raconteur exception of the same kind (InvalidArgument, OperationAborted, ...). Calls that block
until the robot has done something (a waiting jog, a generator's ``Next()``) run on an executor
and answer RR's asynchronous handler, so a few slow clients never starve RR's own thread pool.
The generator objects a client drives with ``Next`` / ``Abort`` / ``Close`` live here too.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from typing import Any

from pydantic import ValidationError

from robotspec.driver.errors import InvalidArgumentError, error_kind
from robotspec.driver.handles import HomingGenerator, TrajectoryGenerator
from robotspec.errors import RobotSpecError
from robotspec.service import convert
from robotspec.service.node import rr

__all__ = [
    "AsyncCalls",
    "Handler",
    "HomingGeneratorService",
    "TrajectoryGeneratorService",
    "rr_errors",
    "to_rr_error",
]

#: Robot Raconteur exception class names by the driver error's ``rr_name``.
_RR_EXCEPTIONS = {
    "InvalidArgument": "InvalidArgumentException",
    "InvalidOperation": "InvalidOperationException",
    "OperationAborted": "OperationAbortedException",
    "OperationFailed": "OperationFailedException",
    "NotImplemented": "NotImplementedException",
}

Handler = Callable[..., None]


def to_rr_error(exc: BaseException) -> BaseException:
    """The Robot Raconteur exception a client should see for ``exc``.

    Driver errors keep their kind (InvalidArgument, OperationAborted, ...) and message; other
    robotspec errors become OperationFailed; anything else (a bug) becomes OperationFailed naming
    the exception type, rather than RR's opaque UnknownException.
    """
    rrmod = rr()
    rr_base: type[BaseException] = rrmod.RobotRaconteurException
    if isinstance(exc, rr_base):
        return exc
    err: BaseException
    if isinstance(exc, StopIteration):
        err = rrmod.StopIterationException("")
    elif isinstance(exc, RobotSpecError):
        cls_name = _RR_EXCEPTIONS.get(error_kind(exc), "OperationFailedException")
        err = getattr(rrmod, cls_name)(exc.message)
    else:
        err = rrmod.OperationFailedException(f"{type(exc).__name__}: {exc}")
    return err


@contextmanager
def rr_errors() -> Iterator[None]:
    """Re-raise driver errors as the Robot Raconteur exceptions clients expect."""
    try:
        yield
    except StopIteration:
        raise to_rr_error(StopIteration()) from None
    except ValidationError as exc:
        raise to_rr_error(InvalidArgumentError(str(exc.errors()[0]["msg"]))) from None
    except Exception as exc:  # noqa: BLE001 - every error must reach the client typed
        raise to_rr_error(exc) from None


class AsyncCalls:
    """Runs blocking driver calls on the adapter's executor and answers RR's handlers."""

    def __init__(self, executor: ThreadPoolExecutor) -> None:
        self._executor = executor

    def void(self, fn: Callable[[], None], handler: Handler, blocking: bool) -> None:
        """Run ``fn`` (on the executor if ``blocking``), then ``handler(error or None)``."""

        def run() -> None:
            try:
                fn()
            except BaseException as exc:  # noqa: BLE001 - delivered to the client
                handler(to_rr_error(_driver_error(exc)))
                return
            handler(None)

        if blocking:
            self._executor.submit(run)
        else:
            run()

    def value(self, fn: Callable[[], Any], handler: Handler) -> None:
        """Run ``fn`` on the executor, then ``handler(value, None)`` or ``handler(None, error)``."""

        def run() -> None:
            try:
                ret = fn()
            except BaseException as exc:  # noqa: BLE001 - delivered to the client
                handler(None, to_rr_error(_driver_error(exc)))
                return
            handler(ret, None)

        self._executor.submit(run)


def _driver_error(exc: BaseException) -> BaseException:
    if isinstance(exc, ValidationError):
        return InvalidArgumentError(str(exc.errors()[0]["msg"]))
    return exc


class TrajectoryGeneratorService:
    """The ``TrajectoryStatus{generator}`` a client drives with Next / Abort / Close."""

    def __init__(self, calls: AsyncCalls, node: Any, gen: TrajectoryGenerator) -> None:
        self._calls = calls
        self._node = node
        self._gen = gen

    def AsyncNext(self, handler: Handler) -> None:  # noqa: N802 - RR generator API
        """Start or continue the trajectory; answers when it ends, fails, or after 5 s."""
        node = self._node
        gen = self._gen
        self._calls.value(lambda: convert.trajectory_status(node, gen.Next()), handler)

    def Abort(self) -> None:  # noqa: N802
        """Stop the robot (mode ``halt``); ``Next()`` then fails with OperationAborted."""
        with rr_errors():
            self._gen.Abort()

    def Close(self) -> None:  # noqa: N802
        """Cancel this trajectory; the mode stays ``trajectory``."""
        with rr_errors():
            self._gen.Close()


class HomingGeneratorService:
    """The ``ActionStatusCode{generator}`` returned by ``home()``: a driver HomingGenerator.

    The first ``Next()`` starts homing (the robot must be in ``homing`` mode); each ``Next()``
    answers ``complete`` once homed, or ``running`` every 5 s until then; StopIteration after.
    """

    def __init__(self, calls: AsyncCalls, gen: HomingGenerator) -> None:
        self._calls = calls
        self._gen = gen

    def AsyncNext(self, handler: Handler) -> None:  # noqa: N802 - RR generator API
        """Start homing (first call), then wait for it."""
        gen = self._gen
        self._calls.value(lambda: int(gen.Next()), handler)

    def Abort(self) -> None:  # noqa: N802
        """Stop homing: mode ``halt`` (a waiting ``Next()`` fails with OperationAborted)."""
        with rr_errors():
            self._gen.Abort()

    def Close(self) -> None:  # noqa: N802
        """Stop homing, as :meth:`Abort`."""
        with rr_errors():
            self._gen.Close()
