"""The array types of the package's signatures, named once (float64 and int64 numpy arrays).

Shapes are documented where arrays are used (``(n, 4, 4)`` poses, ``(dof,)`` configurations).
The checks of a caller's numbers live here too (:func:`real_array`, :func:`finite_array`,
:func:`real_number`), so every query refuses the same things with the same words; each takes the
error type to raise, so this module depends on nothing of the package.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["F64", "I64", "finite_array", "real_array", "real_number"]

#: A float64 numpy array: poses, configurations, Jacobians, joint commands.
F64 = NDArray[np.float64]
#: An int64 numpy array: indices (geometry to body, pair lists).
I64 = NDArray[np.int64]


#: Makes the exception to raise from a message (an error class of robotspec.errors, or a wrapper).
ErrorFactory = Callable[[str], Exception]


def real_array(value: object, what: str, error: ErrorFactory) -> F64:
    """``value`` as a float64 array, or ``error`` naming its dtype when float64 would change it.

    Why: numpy's float64 conversion drops a complex number's imaginary part (a warning at most),
    rounds a longdouble, and parses strings and objects, so a query once answered for numbers
    the caller never gave, or blamed "NaN or infinite values" that were not there. Booleans,
    integers and floats up to float64 are converted; any other dtype is refused by name. ``what``
    starts the message ("configuration must be ...").
    """
    try:
        arr = value if isinstance(value, np.ndarray) else np.asarray(value)
    except (ValueError, TypeError) as exc:  # ragged nested lists
        raise error(f"{what} must be a rectangular array of numbers: {exc}") from None
    kind, size = arr.dtype.kind, arr.dtype.itemsize
    if kind not in "biuf" or (kind == "f" and size > 8):
        why = {
            "c": "complex numbers have no real value",
            "f": "float64 would round it",
            "O": "Python objects, not numbers",
        }.get(kind, "not numbers")
        raise error(f"{what} must be real numbers, got dtype {arr.dtype} ({why})")
    converted: F64 = arr.astype(np.float64, copy=False)
    return converted


def finite_array(arr: F64, what: str, error: ErrorFactory) -> F64:
    """``arr`` unchanged, or ``error`` naming the first NaN or infinite value and its index."""
    if not np.isfinite(arr).all():
        at = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        where = f" at index {at[0] if len(at) == 1 else at}" if at else ""
        raise error(f"{what} contains NaN or infinite values ({arr[at]}{where})")
    return arr


def real_number(
    value: object, what: str, error: ErrorFactory, *, minimum: float = -math.inf
) -> float:
    """``value`` as a finite float of at least ``minimum``, or ``error`` saying what it is.

    Why: a margin or tolerance of the wrong type reached numpy or coal as a bare TypeError or
    ValueError, and an infinite one was accepted by a comparison (``inf >= 0``).
    """
    if type(value) is float and math.isfinite(value) and value >= minimum:
        return value  # the common case, before the checks that name what is wrong
    if isinstance(value, bool | np.bool_) or not isinstance(
        value, int | float | np.integer | np.floating
    ):
        raise error(f"{what} must be a real number, got {type(value).__name__}")
    if isinstance(value, np.floating) and value.dtype.itemsize > 8:
        raise error(f"{what} must be a real number float64 holds, got {value.dtype}")
    number = float(value)
    if not math.isfinite(number):
        raise error(f"{what} must be finite, got {number}")
    if number < minimum:
        raise error(f"{what} must be >= {minimum:g}, got {number:g}")
    return number
