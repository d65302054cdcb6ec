"""The names Robot Raconteur accepts for nodes and device identifiers.

Why in the driver package, with no Robot Raconteur import: a RobotInfo file's device name becomes
the node's name and the key of its identifier lock when served, so a name Robot Raconteur cannot
use must be refused when the file is read (``drive --sim`` and ``--serve`` alike), before any
node starts, with the file and line -- not by the Robot Raconteur parser after start-up.
"""

from __future__ import annotations

import re

__all__ = ["MAX_RR_NAME_CHARS", "rr_name_problem", "rr_name_suggestion", "valid_rr_name"]

#: Robot Raconteur keeps a lock file named after the node or device (``NAME.info`` /
#: ``NAME.pid``); file names are limited to 255 bytes, so longer names fail to start.
MAX_RR_NAME_CHARS = 250

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_.\-]*\Z")
_BAD = re.compile(r"[^A-Za-z0-9_.\-]")


def valid_rr_name(name: str) -> bool:
    """Whether ``name`` is a valid RR node or identifier name (``^[a-zA-Z][a-zA-Z0-9_.-]*$``)."""
    return bool(_NAME.match(name)) and len(name) <= MAX_RR_NAME_CHARS


def rr_name_problem(name: str) -> str | None:
    """What makes ``name`` unusable as a Robot Raconteur name, or None when it is fine."""
    if len(name) > MAX_RR_NAME_CHARS:
        return f"is {len(name)} characters long (at most {MAX_RR_NAME_CHARS})"
    if valid_rr_name(name):
        return None
    bad = sorted(set(_BAD.findall(name)))
    if bad:
        return f"contains {', '.join(repr(c) for c in bad)}"
    return "does not start with a letter"


def rr_name_suggestion(name: str) -> str:
    """A valid name close to ``name``: other characters become '_', a letter goes first."""
    out = _BAD.sub("_", name)
    if not out or not out[0].isalpha():
        out = "robot_" + out
    return out[:MAX_RR_NAME_CHARS]
