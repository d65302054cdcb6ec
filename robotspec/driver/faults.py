"""The simulated robot's injectable faults, and their names as driver parameters.

Why parameters: a client connected over Robot Raconteur can only reach the simulator through the
robdef's members, and ``setf_param`` / ``getf_param`` are the ones meant for driver-specific
settings. A client testing its own fault handling sets ``fault.estop`` to true, watches the
driver react, and sets it to false again (the operator released the e-stop), exactly as a
scenario script's ``fault:`` and ``clear_fault:`` steps do in process.
"""

from __future__ import annotations

from enum import StrEnum
from typing import Any

import numpy as np

from robotspec.driver.errors import InvalidArgumentError
from robotspec.errors import closest_names

__all__ = ["FAULT_ALIASES", "FAULT_PARAM_PREFIX", "Fault", "fault_param", "fault_param_value"]


class Fault(StrEnum):
    """Faults a test (or a scenario, or a client through ``setf_param``) can inject."""

    lost_feedback = "lost_feedback"
    estop = "estop"
    drive_error = "drive_error"
    disabled = "disabled"
    frozen = "frozen"
    step_exception = "step_exception"


#: Parameter names are ``fault.<name>``.
FAULT_PARAM_PREFIX = "fault."
#: Other names a fault answers to: conformance scenarios (docs/driver.md) call the drive
#: error ``sim_error``.
FAULT_ALIASES = {"sim_error": Fault.drive_error}


def _param_names() -> tuple[str, ...]:
    return tuple(FAULT_PARAM_PREFIX + f.value for f in Fault) + tuple(
        FAULT_PARAM_PREFIX + alias for alias in FAULT_ALIASES
    )


def _valid_list() -> str:
    aliases = {v: k for k, v in FAULT_ALIASES.items()}
    return ", ".join(
        FAULT_PARAM_PREFIX
        + f.value
        + (f" (also {FAULT_PARAM_PREFIX}{aliases[f]})" if f in aliases else "")
        for f in Fault
    )


def fault_param(name: str) -> Fault:
    """The fault a parameter name stands for, or InvalidArgument naming the valid ones.

    The message starts with "Invalid parameter", as the reference's answer to any unknown
    parameter does, so clients matching on it keep working.
    """
    if name.startswith(FAULT_PARAM_PREFIX):
        key = name[len(FAULT_PARAM_PREFIX) :]
        if key in FAULT_ALIASES:
            return FAULT_ALIASES[key]
        try:
            return Fault(key)
        except ValueError:
            pass
    close = closest_names(name, _param_names())
    hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
    raise InvalidArgumentError(
        f"Invalid parameter '{name}'{hint} (the simulated robot's parameters: {_valid_list()})"
    )


def fault_param_value(name: str, value: Any) -> bool:
    """A fault parameter's new value as a bool: true/false, or the numbers 1/0.

    Robot Raconteur delivers a ``varvalue`` as a one-element array (``bool[]``, ``int32[]``,
    ``double[]`` ...): those are unwrapped. Anything else is InvalidArgument.
    """
    v = value
    if isinstance(v, np.ndarray) and v.size == 1:
        v = v.reshape(-1)[0].item()
    elif isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, bool):
        return v
    if isinstance(v, int | float) and v in (0, 1):
        return bool(v)
    raise InvalidArgumentError(f"{name} must be true or false (got {value!r})")
