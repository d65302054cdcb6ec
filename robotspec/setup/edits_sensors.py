"""Which chain carries a sensor: the assistant's answer to "sensor 'X' is on no chain".

Why its own change: a camera on a wrist moves with the arm, and the spec says so by listing the
sensor under that chain's ``sensors:`` (or the neck's); validate warns of a sensor no chain or
neck carries. A sensor is carried by one part at most, so choosing a carrier takes it off any
other; the torso carries none (the spec has no ``sensors:`` there). A camera's viewing axis is
here too: where it looks is what its chain carries it for.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from robotspec.setup.edits import SetupError, _camera, _chain
from robotspec.setup.validation import Validation
from robotspec.spec.draft.model import Draft, DraftChain

__all__ = ["NO_CARRIER", "SensorEdits"]

#: The carrier choice for a sensor no chain carries.
NO_CARRIER = "(no chain)"


def _holders(d: Draft) -> list[DraftChain]:
    return [*d.chains, *([d.neck] if d.neck is not None else [])]


def _part_of(d: Draft, holder: DraftChain) -> str:
    return "neck" if holder is d.neck else f"chains.{holder.name}"


class SensorEdits:
    """Sensor carriers, for :class:`~robotspec.setup.session.SetupSession`."""

    def edit(self, change: Callable[[Draft], None]) -> Validation:
        """Apply ``change`` as the session's state (:meth:`SetupSession.edit`)."""
        raise NotImplementedError

    def draft(self) -> Draft:
        """A copy of the current draft."""
        raise NotImplementedError

    def carriers(self) -> tuple[str, ...]:
        """The parts that may carry a sensor: every chain, and the neck."""
        d = self.draft()
        return (NO_CARRIER, *(_part_of(d, h) for h in _holders(d)))

    def generic_sensors(self) -> dict[str, dict[str, Any]]:
        """The spec's sensors that are not cameras (``setup/edits_more.py``)."""
        raise NotImplementedError

    def _sensor(self, d: Draft, part: str) -> str:
        """The name of sensor ``part`` (``sensors.NAME``): a camera, or a generic sensor."""
        name = part.removeprefix("sensors.")
        return name if name in self.generic_sensors() else _camera(d, part).name

    def sensor_carrier(self, part: str) -> str:
        """The chain or neck that carries ``part`` (``sensors.NAME``), or :data:`NO_CARRIER`."""
        d = self.draft()
        name = self._sensor(d, part)
        return next((_part_of(d, h) for h in _holders(d) if name in h.sensors), NO_CARRIER)

    def set_sensor_carrier(self, part: str, carrier: str) -> Validation:
        """Put ``part`` on ``carrier`` (a chain or the neck), or on none (:data:`NO_CARRIER`)."""
        if carrier == "torso":
            raise SetupError(
                "the torso carries no sensors in a spec; choose a chain or the neck",
                kind="part",
                name=carrier,
            )

        def change(d: Draft) -> None:
            name = self._sensor(d, part)
            target = None if carrier == NO_CARRIER else _chain(d, carrier)
            for holder in _holders(d):
                if name in holder.sensors and holder is not target:
                    holder.sensors.remove(name)
            if target is not None and name not in target.sensors:
                target.sensors.append(name)

        return self.edit(change)

    def set_camera_axis(self, part: str, axis: tuple[float, float, float]) -> Validation:
        """The axis a camera looks along in its body's frame (its ``forward_facing_axis``).

        +z is an optical frame's (REP 103, written as no axis), +x a body frame's; any other
        unit vector is written as it is (a camera mounted looking sideways, or down).
        """
        if len(axis) != 3 or not all(math.isfinite(v) for v in axis):
            raise SetupError(f"an axis is three finite numbers, not {list(axis)}", kind="value")
        if abs(math.sqrt(sum(v * v for v in axis)) - 1.0) > 1e-6:
            raise SetupError(f"the axis is a unit vector, not {list(axis)}", kind="value")
        a = (float(axis[0]), float(axis[1]), float(axis[2]))

        def change(d: Draft) -> None:
            c = _camera(d, part)
            c.optical, c.axis, c.looks_along_z = a == (0.0, 0.0, 1.0), None, False
            if a not in ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0)):
                c.axis = a
            c.decide.clear()

        return self.edit(change)
