"""The C cores' argument conversions, in Python: what the numpy fallbacks accept and refuse.

Why a module: ``_kincore.c`` and ``_meshcore.c`` read their arguments through CPython's
``PyArg_ParseTuple`` (``n``: an index, ``d``: a real number, ``p``: a truth value) and numpy's
``PyArray_FROMANY`` (an array of one dtype and a range of dimensions, cast only where no value
can change). A fallback that reads them with ``int()``, ``float()`` or ``np.asarray`` accepts
what the C core refuses (``float("1e-3")``, a float row index, a 2-D array of indices) and fails
where it gives an error with a bare ``OverflowError`` or ``IndexError`` instead. Each function
here is one of those conversions, with the C side's exception type and message, so both cores
refuse a caller's mistake the same way (``tests/test_core_arguments.py`` runs both).
"""

from __future__ import annotations

import operator
from typing import Any, TypeVar

import numpy as np

__all__ = ["from_any", "index", "real", "table", "truth"]

T = TypeVar("T")

#: Bounds of a C ``Py_ssize_t`` on a 64-bit build (numpy's fallbacks need no more).
_SSIZE_MIN, _SSIZE_MAX = -(2**63), 2**63 - 1


def index(value: object) -> int:
    """``value`` as ``PyArg_ParseTuple``'s ``n`` reads it: any integer (``bool`` too), in range.

    A float is a TypeError (C does not round a row or a count), a too large integer an
    OverflowError, as from the C core.
    """
    n = operator.index(value)  # type: ignore[arg-type]  # TypeError as PyNumber_Index raises
    if not _SSIZE_MIN <= n <= _SSIZE_MAX:
        raise OverflowError("Python int too large to convert to C ssize_t")
    return n


def real(value: object) -> float:
    """``value`` as ``PyArg_ParseTuple``'s ``d`` reads it: a real number, never a string.

    ``float()`` would read ``"1e-3"``; ``PyFloat_AsDouble`` takes a float, an object with
    ``__float__`` or an integer (``__index__``), else a TypeError.
    """
    if isinstance(value, float):
        return value
    if hasattr(type(value), "__float__"):
        return float(value)  # type: ignore[arg-type]
    if hasattr(type(value), "__index__"):
        return float(operator.index(value))  # type: ignore[arg-type]  # OverflowError if huge
    raise TypeError(f"must be real number, not {type(value).__name__}")


def truth(value: object) -> bool:
    """``value`` as ``PyArg_ParseTuple``'s ``p`` reads it (``bool()``, errors included)."""
    return bool(value)


def table(obj: object, cls: type[T], what: str) -> T:
    """A table built by the core's own constructor, else the C core's TypeError naming it."""
    if not isinstance(obj, cls):
        raise TypeError(f"expected {what}")
    return obj


def _depth(ndim: int, min_nd: int, max_nd: int) -> None:
    if min_nd and ndim < min_nd:
        raise ValueError("object of too small depth for desired array")
    if max_nd and ndim > max_nd:
        raise ValueError("object too deep for desired array")


def _has_ndmax() -> bool:
    try:
        np.array(0.0, ndmax=1)  # type: ignore[call-overload, unused-ignore]
    except TypeError:  # numpy before 2.4
        return False
    return True


#: Whether ``np.array`` stops discovering dimensions at ``ndmax``, as ``PyArray_FROMANY``
#: does at its maximum (then a sequence nested deeper is numpy's own "would exceed" error).
_NDMAX = _has_ndmax()


def _discovered_ndim(obj: object, max_nd: int) -> int:
    """The dimensions numpy finds in a nested sequence or scalar, looking ``max_nd`` deep."""
    if max_nd and _NDMAX:
        return int(np.array(obj, ndmax=max_nd).ndim)  # type: ignore[call-overload, unused-ignore]
    return int(np.asarray(obj).ndim)


def from_any(
    obj: object, dtype: type[np.generic], min_nd: int = 0, max_nd: int = 0
) -> np.ndarray[Any, Any]:
    """``obj`` as ``PyArray_FROMANY(obj, dtype, min_nd, max_nd, NPY_ARRAY_IN_ARRAY)`` reads it.

    The number of dimensions is checked first (0: any), as numpy does before converting. An
    array is cast only when no value can change (numpy's "safe" rule: not float to int, not
    complex to float, not int64 to uint8), else a TypeError; anything else is converted as
    numpy converts a nested sequence or a scalar, with numpy's own errors.
    """
    if isinstance(obj, np.ndarray):
        _depth(obj.ndim, min_nd, max_nd)
        if obj.dtype == dtype:
            return obj
        want = np.dtype(dtype)
        if not np.can_cast(obj.dtype, want, "safe"):
            raise TypeError(
                f"Cannot cast array data from {obj.dtype!r} to {want!r} according to the rule "
                "'safe'"
            )
        return obj.astype(want)
    if min_nd or max_nd:
        _depth(_discovered_ndim(obj, max_nd), min_nd, max_nd)
    return np.asarray(obj, dtype=dtype)
