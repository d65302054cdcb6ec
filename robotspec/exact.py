"""Numbers in messages, printed so that they read back as the very value compared.

Why: a check compares floats exactly (within a stated tolerance), so a message that rounds
them lies at the edge. ``f"{x:g}"`` prints PR2's ``l_shoulder_pan_joint`` upper limit
2.2853981634 as ``2.2854``; a state of 2.2854 then reads as "outside [-0.714602, 2.2854]".
The shortest text that round-trips (Python's ``repr``) never does that.
"""

from __future__ import annotations

__all__ = ["exact"]


def exact(value: float) -> str:
    """The shortest text that reads back as ``value`` (``0.31``, ``2.2853981634``, ``0``, ``inf``).

    Whole numbers drop ``.0`` (a limit of 0 reads ``0``), as ``:g`` printed them before.
    """
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text
