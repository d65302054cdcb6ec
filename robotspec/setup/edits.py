"""The assistant's changes to a draft: chains, hands, cameras, the drive, answers to questions.

Why apart from the session: :class:`~robotspec.setup.session.SetupSession` owns the state (one
lock, validation, ordered delivery, saving); this module says what each change does to a draft,
each checked before it is made (a link not in the robot, a part that does not exist) and each
made through the session's one way to change, :meth:`SetupSession.edit`.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING

from robotspec.errors import RobotSpecError
from robotspec.model.world import World
from robotspec.setup.questions import (
    BODY_FRAME,
    DRIVES,
    FACINGS,
    FORWARDS,
    KEEP,
    OPTICAL,
    REMOVE,
    ROLES,
    Question,
)
from robotspec.setup.validation import Validation
from robotspec.spec.draft.model import (
    Draft,
    DraftCamera,
    DraftChain,
    DraftDrive,
    DraftFinger,
    DraftManipulator,
)

if TYPE_CHECKING:
    from robotspec.setup.session import Snapshot
    from robotspec.setup.source import Source

__all__ = ["PartEdits", "SetupError"]


class SetupError(RobotSpecError):
    """A change the assistant cannot make (an unknown part, a link not in the robot)."""


def _chain(draft: Draft, part: str) -> DraftChain:
    if part in ("torso", "neck"):
        c = getattr(draft, part)
        if c is None:
            raise SetupError(f"the robot has no {part}; add one first", kind="part", name=part)
        return c  # type: ignore[no-any-return]
    name = part.removeprefix("chains.")
    for c in draft.chains:
        if c.name == name:
            return c
    raise SetupError(f"no chain '{name}'", kind="chain", name=name)


def _manipulator(draft: Draft, part: str) -> DraftManipulator:
    name = part.removeprefix("manipulators.")
    for m in draft.manipulators:
        if m.name == name:
            return m
    raise SetupError(f"no manipulator '{name}'", kind="manipulator", name=name)


def _camera(draft: Draft, part: str) -> DraftCamera:
    name = part.removeprefix("sensors.")
    for c in draft.cameras:
        if c.name == name:
            return c
    raise SetupError(f"no camera '{name}'", kind="sensor", name=name)


def _facing(axis: tuple[float, float, float]) -> tuple[float, float, float, float]:
    import numpy as np

    from robotspec.spec.draft.hands import facing_quaternion

    q = facing_quaternion(np.array(axis, dtype=np.float64))
    return (0.0, 0.0, 0.0, 1.0) if q is None else q


class PartEdits:
    """The changes of :class:`~robotspec.setup.session.SetupSession` to a draft's parts."""

    world: World
    source: Source
    _lock: threading.RLock
    _snapshot: Snapshot

    def edit(self, change: Callable[[Draft], None]) -> Validation:
        """Apply ``change`` as the session's state (:meth:`SetupSession.edit`)."""
        raise NotImplementedError

    def _link(self, name: str, what: str) -> str:
        if not self.world.has_body(name):
            from robotspec.errors import closest_names

            near = closest_names(name, self.world.body_names)
            raise SetupError(
                f"{what}: no link '{name}' in the robot", kind="link", name=name, suggestions=near
            )
        return name

    def set_chain(
        self,
        part: str,
        *,
        root: str | None = None,
        tip: str | None = None,
        kind: str | None = None,
        side: str | None = "",
    ) -> Validation:
        """Change a chain (or the torso, the neck): its root, tip, kind, side; answers its mark."""
        if root is not None:
            self._link(root, "root")
        if tip is not None:
            self._link(tip, "tip")
        if kind is not None and kind not in ROLES:
            raise SetupError(f"a chain's kind is arm, leg or chain, not '{kind}'", kind="kind")
        if side not in ("", None, "left", "right"):
            raise SetupError(f"a side is left or right, not '{side}'", kind="side")

        def change(d: Draft) -> None:
            c = _chain(d, part)
            if root is not None or tip is not None:
                if c.group is not None:  # an SRDF group written as root/tip from now on
                    c.group = None
                c.root = root if root is not None else c.root
                c.tip = tip if tip is not None else c.tip
                c.decide.clear()
            if kind is not None:
                c.role = kind
                c.decide.clear()
            if side != "":
                c.side = side

        return self.edit(change)

    def add_chain(self, name: str, root: str, tip: str, kind: str = "arm") -> Validation:
        """A new chain (``torso`` and ``neck`` make those parts)."""
        self._link(root, "root")
        self._link(tip, "tip")

        def change(d: Draft) -> None:
            if name in ("torso", "neck"):
                if getattr(d, name) is not None:
                    raise SetupError(f"the robot has a {name} already", kind="part", name=name)
                setattr(d, name, DraftChain(name, root, tip, "robotspec setup", role=name))
                return
            if any(c.name == name for c in d.chains):
                raise SetupError(f"a chain '{name}' exists already", kind="chain", name=name)
            d.chains.append(DraftChain(name, root, tip, "robotspec setup", role=kind))

        return self.edit(change)

    def remove(self, part: str) -> Validation:
        """Drop a part; references to it (a chain's manipulator, a neck's sensors) go too."""

        def change(d: Draft) -> None:
            kind, _, name = part.partition(".")
            if part in ("torso", "neck"):
                _chain(d, part)
                setattr(d, part, None)
            elif kind == "chains":
                d.chains.remove(_chain(d, part))
            elif kind == "manipulators":
                d.manipulators.remove(_manipulator(d, part))
                for c in d.chains:
                    if c.manipulator == name:
                        c.manipulator = None
            elif kind == "sensors":
                d.cameras.remove(_camera(d, part))
                for holder in [*d.chains, d.neck]:
                    if holder is not None and name in holder.sensors:
                        holder.sensors.remove(name)
            elif kind == "frames":
                frame = next((f for f in d.frames if f.name == name), None)
                if frame is None:
                    raise SetupError(f"no frame '{name}'", kind="frame", name=name)
                d.frames.remove(frame)
                for m in d.manipulators:
                    if m.tool_frame == name:
                        m.tool_frame = frame.parent
            else:
                raise SetupError(f"no part '{part}'", kind="part", name=part)

        return self.edit(change)

    def set_manipulator(
        self,
        part: str,
        *,
        root: str | None = None,
        tool_frame: str | None = None,
        thumb: tuple[str, str] | None = None,
        finger: tuple[str, str] | None = None,
        generic: bool = False,
        facing: tuple[float, float, float] | None = None,
        named: tuple[str, str] | None = None,
    ) -> Validation:
        """Change a hand: its root, tool frame, fingers (root, tip), or the way it faces.

        ``thumb`` with ``finger`` makes a parallel gripper; ``thumb`` with ``named`` fingers
        (name, tip) a hand of named fingers (its parallel ``finger`` goes). A hand's fingers, its
        thumb too, start at their first link past the hand's root, as the compiler requires.
        """
        for link, what in ((root, "root"), (tool_frame, "tool frame")):
            if link is not None:
                self._link(link, what)
        for pair, what in ((thumb, "thumb"), (finger, "finger"), (named and named[1:], "finger")):
            for link in pair or ():
                self._link(link, what)
        if named is not None and not named[0].strip():
            raise SetupError("a named finger needs a name", kind="finger")

        def change(d: Draft) -> None:
            m = _manipulator(d, part)
            m.root = root if root is not None else m.root
            m.tool_frame = tool_frame if tool_frame is not None else m.tool_frame
            if thumb is not None:
                m.thumb = DraftFinger(*thumb)
            if finger is not None:
                m.finger = DraftFinger(*finger)
            if named is not None:
                m.finger = None
                m.fingers[named[0].strip()] = DraftFinger(self._past(m.root, named[1]), named[1])
                if m.thumb is not None:
                    m.thumb = DraftFinger(self._past(m.root, m.thumb.tip), m.thumb.tip)
            if generic:
                m.thumb = m.finger = None
                m.fingers = {}
            if facing is not None:
                m.front_facing = _facing(facing)
            m.decide.clear()

        return self.edit(change)

    def _past(self, root: str, tip: str) -> str:
        """The first link below ``root`` on the way to ``tip`` (``root`` if tip is not below)."""
        w = self.world
        if root == tip or not w.has_body(root) or not w.is_ancestor(root, tip):
            return root
        return w.compute_chain_of_kinematic_structure_entities(root, tip)[1].name

    def add_manipulator(
        self, name: str, root: str, tool_frame: str, chain: str | None = None
    ) -> Validation:
        """A new generic hand, optionally carried by a chain (``chains.X``)."""
        self._link(root, "root")
        self._link(tool_frame, "tool frame")

        def change(d: Draft) -> None:
            if any(m.name == name for m in d.manipulators):
                raise SetupError(f"a manipulator '{name}' exists", kind="manipulator", name=name)
            d.manipulators.append(DraftManipulator(name, root, tool_frame, "robotspec setup"))
            if chain is not None:
                _chain(d, chain).manipulator = name

        return self.edit(change)

    def set_camera(
        self,
        part: str,
        *,
        body: str | None = None,
        preset: str | None = None,
        field_of_view: tuple[float, float] | None = None,
        optical: bool | None = None,
    ) -> Validation:
        """Change a camera: its body, preset or angles (rad), which way its frame looks."""
        if body is not None:
            self._link(body, "camera body")
        if preset is not None and preset not in self.source.presets:
            raise SetupError(
                f"no camera preset '{preset}'; there are {', '.join(self.source.presets)}",
                kind="preset",
                name=preset,
            )

        def change(d: Draft) -> None:
            c = _camera(d, part)
            c.body = body if body is not None else c.body
            if preset is not None:
                c.preset, c.field_of_view = preset, None
            if field_of_view is not None:
                c.preset, c.field_of_view = None, (float(field_of_view[0]), float(field_of_view[1]))
            if optical is not None:
                c.optical = optical
            c.decide.clear()  # a person decided this camera: its question is answered

        return self.edit(change)

    def add_camera(self, name: str, body: str, *, optical: bool = True) -> Validation:
        """A new camera on ``body`` (its angles still to decide)."""
        self._link(body, "camera body")

        def change(d: Draft) -> None:
            if any(c.name == name for c in d.cameras):
                raise SetupError(f"a camera '{name}' exists", kind="sensor", name=name)
            d.cameras.append(DraftCamera(name, body, optical))

        return self.edit(change)

    def set_drive(self, kind: str) -> Validation:
        """How the base moves: fixed, omni, differential or floating."""
        if kind not in DRIVES:
            raise SetupError(f"a drive is {', '.join(DRIVES)}, not '{kind}'", kind="drive")

        def change(d: Draft) -> None:
            old = d.drive
            if kind == "fixed":
                d.drive = DraftDrive("fixed", source="robotspec setup")
            else:
                joint = old.joint if old is not None else None
                frame = old.parent_frame if old is not None and old.parent_frame else "odom"
                d.drive = DraftDrive(kind, joint, frame, source="robotspec setup")

        return self.edit(change)

    def set_forward(self, axis: tuple[float, float, float] | None) -> Validation:
        """Which way the robot faces in its root link's frame (None: +x, the default)."""
        if axis is not None and (len(axis) != 3 or abs(sum(v * v for v in axis) - 1.0) > 1e-6):
            raise SetupError(f"the facing is a unit vector, not {list(axis)}", kind="forward")

        def change(d: Draft) -> None:
            d.forward = None if axis is None else (float(axis[0]), float(axis[1]), float(axis[2]))
            d.forward_decide = None if axis is None else ""

        return self.edit(change)

    def answer(self, question: str, choice: str = KEEP) -> Validation:
        """Answer an open question: keep the guess, or apply one of its alternatives."""
        with self._lock:
            q = next((q for q in self._snapshot.questions if q.id == question), None)
        if q is None:
            raise SetupError(f"no open question '{question}'", kind="question", name=question)
        if choice not in q.choices:
            raise SetupError(
                f"'{choice}' is not a choice of {question}: {', '.join(q.choices)}",
                kind="choice",
                name=choice,
            )
        if choice == REMOVE:
            return self.remove(q.part)
        if choice.startswith("drive: "):
            return self.set_drive(choice.removeprefix("drive: "))
        if choice.startswith("preset: "):
            return self.set_camera(q.part, preset=choice.removeprefix("preset: "))
        if choice in FORWARDS:
            return self.set_forward(FORWARDS[choice])
        if choice in FACINGS:
            return self.set_manipulator(q.part, facing=FACINGS[choice])
        if choice == "make it generic":
            return self.set_manipulator(q.part, generic=True)
        if choice in (OPTICAL, BODY_FRAME):
            return self.set_camera(q.part, optical=choice == OPTICAL)
        for role, words in ROLES.items():
            if choice == f"make it {words}":
                return self.set_chain(q.part, kind=role)
        return self.edit(lambda d: _keep(d, q))


def _keep(d: Draft, q: Question) -> None:
    """Keep a guess: its DECIDE mark goes, nothing else changes."""
    kind, _, name = q.part.partition(".")
    if q.id.endswith(".field_of_view"):
        from robotspec.spec.draft.render import PLACEHOLDER_FOV

        _camera(d, q.part).field_of_view = PLACEHOLDER_FOV
    elif q.part == "forward":
        d.forward_decide = ""
    elif q.part == "drive" and d.drive is not None:
        d.drive.decide = None
    elif q.part in ("torso", "neck") or kind == "chains":
        _chain(d, q.part).decide.clear()
    elif kind == "manipulators":
        _manipulator(d, q.part).decide.clear()
    elif kind == "sensors":
        _camera(d, q.part).decide.clear()
    elif kind == "frames":
        for f in d.frames:
            if f.name == name:
                f.reason = ""
