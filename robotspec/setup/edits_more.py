"""What a spec says that a draft does not: frames' rotations, generic sensors, accepted warnings.

Why as text edits kept beside the draft (``setup/extras.py``): the draft is what ``init``
decides; a spec kept in git says more, and the page must be able to say it too. Each edit here
is checked first (a name the spec does not hold, a link not in the robot, a quaternion that is
not a unit one, an empty reason: each refused with why), then made through the round-trip
editor by :meth:`SetupSession.edit`, so it changes only its own lines and undo takes it back.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import yaml

from robotspec.errors import closest_names
from robotspec.model.world import World
from robotspec.setup.edits import SetupError
from robotspec.setup.extras import DELETE, Edit, Entry, Extras
from robotspec.setup.validation import Validation
from robotspec.spec.draft.model import Draft, DraftFrame

if TYPE_CHECKING:
    from robotspec.setup.session import Snapshot

__all__ = ["MoreEdits", "ROTATIONS"]

#: How a frame's rotation is given: none, roll-pitch-yaw (rad), or a quaternion [x, y, z, w].
ROTATIONS = ("none", "rpy", "quaternion")


def _numbers(values: Sequence[float], n: int, what: str) -> list[float]:
    """``n`` finite numbers (an integral one written as an integer), or a refusal saying why."""
    if len(values) != n:
        raise SetupError(f"{what} takes {n} numbers, not {len(values)}", kind="value")
    out: list[float] = []
    for v in values:
        x = float(v)
        if not math.isfinite(x):
            raise SetupError(f"{what}: {v} is not a finite number", kind="value")
        out.append(int(x) if x == int(x) and abs(x) < 1e15 else x)
    return out


def parse_numbers(text: str) -> list[float]:
    """Numbers typed as ``0, 0, 1.57`` or ``[0 0 1.57]``; a word that is not one refused."""
    words = text.replace("[", " ").replace("]", " ").replace(",", " ").split()
    out = []
    for w in words:
        try:
            out.append(float(w))
        except ValueError:
            raise SetupError(f"'{w}' is not a number", kind="value") from None
    return out


class MoreEdits:
    """Frames' rotations, generic sensors, accepted warnings (mixed into ``SetupSession``)."""

    _lock: threading.RLock
    _snapshot: Snapshot
    world: World

    def edit(
        self,
        change: Callable[[Draft], None],
        *,
        extras: Callable[[Extras], Extras] | None = None,
        what: str | None = None,
    ) -> Validation:
        """Apply a change as the session's state (:meth:`SetupSession.edit`)."""
        raise NotImplementedError

    def _link(self, name: str, what: str) -> str:
        raise NotImplementedError

    def draft(self) -> Draft:
        """A copy of the current draft."""
        raise NotImplementedError

    def _data(self) -> dict[str, Any]:
        """The spec's data as the current text states it."""
        data = yaml.safe_load(self._snapshot.text)
        return data if isinstance(data, dict) else {}

    # ------------------------------------------------------------------ frames
    def frames(self) -> dict[str, dict[str, Any]]:
        """The spec's own extra frames (``description.frames``), as written."""
        desc = self._data().get("description") or {}
        frames = desc.get("frames") if isinstance(desc, dict) else None
        return {str(k): v for k, v in (frames or {}).items() if isinstance(v, dict)}

    def add_frame(self, name: str, parent: str, xyz: Sequence[float] = (0, 0, 0)) -> Validation:
        """A frame the URDF lacks (a tool frame), fixed to link ``parent`` at ``xyz`` (m)."""
        name = name.strip()
        if not name:
            raise SetupError("a frame needs a name", kind="frame")
        if name in self.frames() or self.world.has_body(name):
            raise SetupError(f"'{name}' is a link or frame already", kind="frame", name=name)
        self._link(parent, "frame parent")
        x, y, z = _numbers(xyz, 3, "a position [x, y, z]")
        return self.edit(lambda d: d.frames.append(DraftFrame(name, parent, (x, y, z), "")))

    def set_frame_position(self, frame: str, xyz: Sequence[float]) -> Validation:
        """Move an extra frame in its parent link (``xyz``, m)."""
        x, y, z = _numbers(xyz, 3, "a position [x, y, z]")

        def change(d: Draft) -> None:
            f = next((f for f in d.frames if f.name == frame), None)
            if f is None:
                raise SetupError(
                    f"no frame '{frame}' of this spec",
                    kind="frame",
                    name=frame,
                    suggestions=closest_names(frame, [f.name for f in d.frames]),
                )
            f.xyz = (x, y, z)

        return self.edit(change)

    def set_frame_rotation(self, frame: str, kind: str, values: Sequence[float] = ()) -> Validation:
        """Turn an extra frame: ``rpy`` (rad, fixed axes), ``quaternion`` [x, y, z, w], ``none``.

        The other way of giving a rotation goes (a frame gives one, not both).
        """
        frames = self.frames()
        if frame not in frames:
            raise SetupError(
                f"no frame '{frame}' under description.frames",
                kind="frame",
                name=frame,
                suggestions=closest_names(frame, frames),
            )
        if kind not in ROTATIONS:
            raise SetupError(f"a rotation is {', '.join(ROTATIONS)}, not '{kind}'", kind="value")
        at = ("description", "frames", frame)
        ops: list[Edit] = []
        if kind == "rpy":
            ops = [
                Edit("set", (*at, "rpy"), _numbers(values, 3, "rpy")),
                Edit(DELETE, (*at, "quaternion")),
            ]
        elif kind == "quaternion":
            q = _numbers(values, 4, "a quaternion [x, y, z, w]")
            norm = math.sqrt(sum(v * v for v in q))
            if abs(norm - 1.0) > 1e-3:
                raise SetupError(
                    f"a quaternion [x, y, z, w] is a unit one: the norm of {q} is {norm:.4g}",
                    kind="value",
                )
            ops = [Edit("set", (*at, "quaternion"), q), Edit(DELETE, (*at, "rpy"))]
        else:
            ops = [Edit(DELETE, (*at, "rpy")), Edit(DELETE, (*at, "quaternion"))]

        def extras(e: Extras) -> Extras:
            for op in ops:
                e = e.with_edit(op)
            return e

        return self.edit(lambda d: None, extras=extras)

    # ------------------------------------------------------------------ generic sensors
    def generic_sensors(self) -> dict[str, dict[str, Any]]:
        """The spec's sensors that are not cameras (a lidar, a force-torque sensor), as written."""
        sensors = self._data().get("sensors") or {}
        return {
            str(k): v
            for k, v in sensors.items()
            if isinstance(v, dict) and v.get("type") == "generic"
        }

    def _generic(self, name: str) -> None:
        known = self.generic_sensors()
        if name not in known:
            raise SetupError(
                f"no generic sensor '{name}'",
                kind="sensor",
                name=name,
                suggestions=closest_names(name, known),
            )

    def add_generic_sensor(self, name: str, body: str, kind: str = "") -> Validation:
        """A sensor that is not a camera on ``body``; ``kind`` is free-form (``lidar``)."""
        name = name.strip()
        if not name:
            raise SetupError("a sensor needs a name", kind="sensor")
        sensors = self._data().get("sensors") or {}
        if name in sensors:
            raise SetupError(f"a sensor '{name}' exists already", kind="sensor", name=name)
        self._link(body, "sensor body")
        value: dict[str, Any] = {"type": "generic", "body": body}
        if kind.strip():
            value["kind"] = kind.strip()
        edit = Edit("set", ("sensors", name), value)
        return self.edit(lambda d: None, extras=lambda e: e.with_edit(edit))

    def set_generic_sensor(
        self, name: str, *, body: str | None = None, kind: str | None = None
    ) -> Validation:
        """Change a generic sensor's body or kind (an empty kind removes it)."""
        self._generic(name)
        ops: list[Edit] = []
        if body is not None:
            ops.append(Edit("set", ("sensors", name, "body"), self._link(body, "sensor body")))
        if kind is not None:
            k = kind.strip()
            ops.append(
                Edit("set", ("sensors", name, "kind"), k)
                if k
                else Edit(DELETE, ("sensors", name, "kind"))
            )

        def extras(e: Extras) -> Extras:
            for op in ops:
                e = e.with_edit(op)
            return e

        return self.edit(lambda d: None, extras=extras)

    def remove_generic_sensor(self, name: str) -> Validation:
        """Drop a generic sensor, and its name from the chain or neck that carries it."""
        self._generic(name)

        def change(d: Draft) -> None:
            for holder in [*d.chains, d.neck]:
                if holder is not None and name in holder.sensors:
                    holder.sensors.remove(name)

        edit = Edit(DELETE, ("sensors", name))
        return self.edit(change, extras=lambda e: e.with_edit(edit))

    # ------------------------------------------------------------------ accepted warnings
    def accepted_entries(self) -> list[tuple[str, str, str]]:
        """The spec's ``accept_warnings`` entries as written: (at, says, because)."""
        entries = self._data().get("accept_warnings") or []
        return [
            (str(x.get("at")), str(x.get("says")), str(x.get("because", "")))
            for x in entries
            if isinstance(x, dict)
        ]

    def _entry(self, at: str, says: str) -> None:
        labels = [f"{a}: {s}" for a, s, _ in self.accepted_entries()]
        if f"{at}: {says}" not in labels:
            raise SetupError(
                f"no accept_warnings entry '{at}: {says}'",
                kind="warning",
                name=f"{at}: {says}",
                suggestions=closest_names(f"{at}: {says}", labels),
            )

    def set_accepted_reason(self, at: str, says: str, because: str) -> Validation:
        """Give an accepted warning another reason (its ``because``; empty: refused, why)."""
        reason = " ".join(because.split())
        if not reason:
            raise SetupError(
                "give the reason this warning does not apply to this robot (to remove the "
                "entry, press remove)",
                kind="value",
            )
        self._entry(at, says)
        new = self.draft().accepted
        mine = [i for i, (a, s, _) in enumerate(new) if (a, s) == (at, says)]
        if mine:  # accepted in this session: its own lines say the new reason

            def change(d: Draft) -> None:
                d.accepted[mine[0]] = (at, says, reason)

            return self.edit(change)
        edit = Edit("set", ("accept_warnings", Entry(at, says), "because"), reason)
        return self.edit(lambda d: None, extras=lambda e: e.with_edit(edit))

    def remove_accepted(self, at: str, says: str) -> Validation:
        """Remove an ``accept_warnings`` entry: validate warns of that warning again."""
        self._entry(at, says)
        new = self.draft().accepted
        mine = [i for i, (a, s, _) in enumerate(new) if (a, s) == (at, says)]
        if mine:

            def change(d: Draft) -> None:
                del d.accepted[mine[0]]

            return self.edit(change)
        last = len(self.accepted_entries()) == 1  # the list goes with its last entry
        edit = Edit(DELETE, ("accept_warnings",) if last else ("accept_warnings", Entry(at, says)))
        return self.edit(lambda d: None, extras=lambda e: e.with_edit(edit))
