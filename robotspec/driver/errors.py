"""The driver's error kinds, named after the Robot Raconteur exceptions clients see.

Why separate kinds: the reference distinguishes InvalidArgument (bad input), InvalidOperation
(wrong state), OperationAborted (interrupted), OperationFailed and NotImplemented, and scenario
scripts assert which one a call raises. All are :class:`~robotspec.errors.DriverError`, so the CLI
renders them like every other robotspec error.
"""

from __future__ import annotations

from robotspec.errors import DriverError

__all__ = [
    "InvalidArgumentError",
    "InvalidOperationError",
    "NotImplementedDriverError",
    "OperationAbortedError",
    "OperationFailedError",
    "error_kind",
]


class InvalidArgumentError(DriverError):
    """An argument is malformed, not finite or out of limits (RR ``InvalidArgument``)."""

    rr_name = "InvalidArgument"


class InvalidOperationError(DriverError):
    """The call is not allowed in the current mode or state (RR ``InvalidOperation``)."""

    rr_name = "InvalidOperation"


class OperationAbortedError(DriverError):
    """A pending operation was interrupted: halt, error, lost comms (RR ``OperationAborted``)."""

    rr_name = "OperationAborted"


class OperationFailedError(DriverError):
    """An operation ran but failed, e.g. trajectory tracking (RR ``OperationFailed``)."""

    rr_name = "OperationFailed"


class NotImplementedDriverError(DriverError):
    """The driver has no such feature (RR ``NotImplementedError``)."""

    rr_name = "NotImplemented"


def error_kind(exc: BaseException) -> str:
    """The Robot Raconteur name of an error (``DriverError`` for other robotspec errors)."""
    return str(getattr(exc, "rr_name", type(exc).__name__))
