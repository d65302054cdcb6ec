"""One Python class per Robot Raconteur structure type, instead of one per decoded value.

Robot Raconteur's Python binding builds the class of a structure by calling
``RobotRaconteurPythonUtil.CreateStructureType(name, fields)`` whenever it needs one, and it
needs one for *every structure it decodes*: a client's 35,000-waypoint trajectory made 35,000
``JointTrajectoryWaypoint`` classes on the server, each with its slot descriptors, ``__init__``
function, closure cell, dict and tuples (30 objects the garbage collector tracks per waypoint:
1,050,000 for that upload). Making them took about a second of the interpreter's time, and the
collector's passes over them (hundreds of ms each, holding the interpreter) stalled the driver
loop by a third of a second or more (issue 31).

:func:`install` replaces that function with one that makes each distinct class once and hands
out the same class again: keyed by the structure's name and its fields' initialisers (type,
arguments), so two services that define a structure of the same name differently still get
classes of their own. The classes are equivalent by construction (same name, slots and
initialisers), which is what Robot Raconteur's own client stubs assume when they cache them.
The binding looks the function up by name on each call (checked in the tests), so the
replacement takes effect for every node in the process, servers and clients alike.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

__all__ = ["cached_structure_types", "install"]

_lock = threading.Lock()
_installed: list[Callable[..., Any]] = []
_classes: dict[tuple[Any, ...], Any] = {}


def _key(name: str, fields: dict[str, Any]) -> tuple[Any, ...]:
    """The class's identity: its name, and each field's name, initialiser and arguments.

    The fields as they are when they hash (0.5 us for a waypoint's seven: this runs once per
    decoded structure, 35,000 times for a long trajectory); their ``repr`` otherwise (a list
    among the arguments), which is 30 times slower.
    """
    key = (name, tuple(fields.items()))
    try:
        hash(key)
    except TypeError:
        return (name, tuple((k, init[0], repr(init[1])) for k, init in fields.items()))
    return key


def install(util: Any) -> None:
    """Make ``util.CreateStructureType`` (``RobotRaconteurPythonUtil``) reuse its classes.

    Idempotent; thread-safe. A field description that cannot be keyed (not the binding's
    ``(initialiser, args)`` pairs) is passed to the original function, uncached.
    """
    with _lock:
        if _installed:
            return
        original: Callable[..., Any] = util.CreateStructureType

        def create_structure_type(name: str, fields: dict[str, Any]) -> Any:
            try:
                key = _key(name, fields)
            except (TypeError, IndexError, AttributeError):
                return original(name, fields)
            cls = _classes.get(key)
            if cls is None:
                cls = _classes.setdefault(key, original(name, fields))
            return cls

        util.CreateStructureType = create_structure_type
        _installed.append(original)


def cached_structure_types() -> int:
    """How many distinct structure classes were made since :func:`install`."""
    return len(_classes)
