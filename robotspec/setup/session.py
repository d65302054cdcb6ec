"""The assistant's editable state: one draft, one lock, a validation after every change.

Why one object shared by every browser tab: two tabs on one server must see one state, and a
change from one must never interleave with another's; each mutation works on a copy under the
lock, validates the text it would save, and only then becomes the state (so a change that fails
halfway leaves nothing behind). Listeners hear of each new state (the page redraws on them).
"""

from __future__ import annotations

import copy
import threading
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from robotspec.errors import RobotSpecError
from robotspec.files.writing import check_writable, write_file
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
    questions_of,
)
from robotspec.setup.save import spec_text, write_spec
from robotspec.setup.source import Source, open_source
from robotspec.setup.targets import SaveFence
from robotspec.setup.text_edit import TextEditError
from robotspec.setup.tree import chain_joints, joint_range, subtree_joints
from robotspec.setup.validation import Validation, validate_text
from robotspec.spec.draft.model import (
    Draft,
    DraftCamera,
    DraftChain,
    DraftDrive,
    DraftFinger,
    DraftManipulator,
)

__all__ = ["SetupError", "SetupSession", "Snapshot"]

_HISTORY = 50


class SetupError(RobotSpecError):
    """A change the assistant cannot make (an unknown part, a link not in the robot)."""


@dataclass(frozen=True)
class Snapshot:
    """One state of the session: its text, its validation, its open questions."""

    version: int
    text: str
    validation: Validation
    questions: tuple[Question, ...]
    saved: bool


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


class SetupSession:
    """A draft being turned into a valid spec, and where it will be saved."""

    def __init__(
        self,
        source: Source,
        output: Path,
        *,
        package_paths: Sequence[str | Path] = (),
        allow_save: Sequence[Path] = (),
    ) -> None:
        self.source = source
        self.world: World = source.world
        self.output = output
        self.package_paths = tuple(package_paths)
        #: Where saves may go, the robot's files they never replace, what this session wrote.
        self.fence = SaveFence(output, tuple(allow_save), dict(source.inputs))
        self._lock = threading.RLock()
        self._draft = copy.deepcopy(source.draft)
        self._history: list[Draft] = []
        self._listeners: list[Callable[[Snapshot], None]] = []
        self._version = 0
        #: Ordered delivery (:meth:`_publish`): the last (version, saved) delivered, and
        #: whether a thread is delivering now.
        self._publish_lock = threading.Lock()
        self._delivered: tuple[int, bool] = (-1, False)
        self._delivering = False
        #: A generated SRDF kept until save: (its name beside the spec, its text).
        self._pending_srdf: tuple[str, str] | None = None
        self._saved: tuple[str, str | None] | None = None
        self._snapshot = self._make_snapshot(self._draft)
        robot = self._snapshot.validation.robot
        if robot is not None and robot.srdf is not None and robot.srdf.file:
            self.fence.inputs.setdefault(Path(robot.srdf.file), "its SRDF")

    @classmethod
    def open(
        cls,
        ref: str,
        *,
        output: Path,
        srdf: str | None = None,
        package_paths: Sequence[str | Path] = (),
        allow_save: Sequence[Path] = (),
    ) -> SetupSession:
        """A session on a URDF (drafted) or a spec (read back); errors as init/validate raise.

        Saves go to ``output``'s folder, or a folder of ``allow_save`` (``--allow-save``).
        """
        source = open_source(ref, srdf=srdf, output=output, package_paths=package_paths)
        return cls(source, output, package_paths=package_paths, allow_save=allow_save)

    # ------------------------------------------------------------------ reading
    @property
    def snapshot(self) -> Snapshot:
        """The current state (a value: it never changes under the caller)."""
        return self._snapshot

    @property
    def validation(self) -> Validation:
        """What validate says of the current text."""
        return self._snapshot.validation

    def draft(self) -> Draft:
        """A copy of the current draft."""
        with self._lock:
            return copy.deepcopy(self._draft)

    def parts(self) -> tuple[str, ...]:
        """Every editable part: drive, torso, neck, chains.X, manipulators.X, sensors.X."""
        d = self._draft
        out = ["drive"]
        out += [k for k in ("torso", "neck") if getattr(d, k) is not None]
        out += [f"chains.{c.name}" for c in d.chains]
        out += [f"manipulators.{m.name}" for m in d.manipulators]
        out += [f"sensors.{c.name}" for c in d.cameras]
        return tuple(out)

    def part_joints(self, part: str) -> tuple[str, ...]:
        """The joints a part's states name: a chain's from root to tip, a hand's below its root."""
        with self._lock:
            d = self._draft
            if part == "robot":
                return tuple(
                    c.name for c in self.world.connections if c.is_active and not c.is_mimic
                )
            if part.startswith("manipulators."):
                return subtree_joints(self.world, _manipulator(d, part).root)
            c = _chain(d, part)
            if c.group is not None and not c.root:
                return ()
            return chain_joints(self.world, c.root, c.tip)

    def part_states(self, part: str) -> dict[str, dict[str, float]]:
        """A part's named states (``robot``: the spec's top-level ``states``)."""
        with self._lock:
            return copy.deepcopy(self._states_of(self._draft, part))

    def joint_range(self, joint: str) -> tuple[float, float]:
        """The range a state's slider spans (the joint's limits)."""
        return joint_range(self.world, joint)

    def subscribe(self, listener: Callable[[Snapshot], None]) -> None:
        """Call ``listener`` with every new state (from the thread that made it)."""
        with self._lock:
            self._listeners.append(listener)

    # ------------------------------------------------------------------ the one way to change
    def _srdf_of(self, draft: Draft) -> tuple[str, str] | None:
        """The generated SRDF ``draft`` names, while it is kept in the session (not saved)."""
        pending = self._pending_srdf
        return pending if pending is not None and draft.srdf == pending[0] else None

    def _validate(self, draft: Draft, text: str, at: Path) -> Validation:
        """What validate says of ``text`` saved as ``at`` (a kept SRDF staged beside it)."""
        srdf = self._srdf_of(draft)
        if srdf is None:
            return validate_text(text, at, package_paths=self.package_paths)

        def naming(staged: str) -> str:
            d = copy.copy(draft)
            d.srdf = staged
            return self._text(d)

        return validate_text(naming, at, package_paths=self.package_paths, srdf=srdf)

    def _text(self, draft: Draft) -> str:
        """The text saving writes: a spec's own text with the changes made, or the draft's."""
        written = self.source.written
        if written is None:
            return spec_text(draft, self.source.kept, self.source.presets)
        try:
            return written.text_of(draft, self.source.presets)
        except TextEditError as exc:
            raise SetupError(exc.message, kind=exc.detail.kind, name=exc.detail.name) from None

    def _make_snapshot(self, draft: Draft) -> Snapshot:
        text = self._text(draft)
        srdf = self._srdf_of(draft)
        return Snapshot(
            self._version,
            text,
            self._validate(draft, text, self.output),
            questions_of(draft, self.source.presets),
            saved=(text, srdf and srdf[1]) == self._saved,
        )

    def edit(self, change: Callable[[Draft], None]) -> Validation:
        """Apply ``change`` to a copy of the draft, validate it, make it the state."""
        with self._lock:
            new = copy.deepcopy(self._draft)
            change(new)
            self._version += 1
            snap = self._make_snapshot(new)
            self._history = [*self._history[-_HISTORY + 1 :], self._draft]
            self._draft, self._snapshot = new, snap
        self._publish()
        return snap.validation

    def _publish(self) -> None:
        """Tell the listeners of the newest state, states in the order they were made.

        Why not each thread its own snapshot after the lock: two edits on two threads (viser
        runs callbacks on a pool) then reach a listener in either order, and a page drew the
        older state last (``delivered [2, 1], session at 2``). One thread delivers at a time;
        a thread finding another delivering leaves its state to it, which delivers states until
        it has delivered the newest (skipping none it has not passed: each is newer than the
        last). So listeners see versions only grow, and always end on the session's state.
        """
        with self._publish_lock:
            if self._delivering:
                return
            self._delivering = True
        try:
            while True:
                with self._lock, self._publish_lock:
                    snap = self._snapshot
                    order = (snap.version, snap.saved)
                    if order <= self._delivered:
                        self._delivering = False
                        return
                    self._delivered = order
                    listeners = list(self._listeners)
                for listener in listeners:
                    listener(snap)
        except BaseException:
            with self._publish_lock:
                self._delivering = False
            raise

    def undo(self) -> Validation:
        """Go back one change (nothing happens when there is none)."""
        with self._lock:
            if not self._history:
                return self.validation
            previous = self._history.pop()
            self._version += 1
            snap = self._make_snapshot(previous)
            self._draft, self._snapshot = previous, snap
        self._publish()
        return snap.validation

    # ------------------------------------------------------------------ changes
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

    def set_srdf(self, ref: str | None) -> Validation:
        """The SRDF the spec names (a path relative to the spec, or a ``package://`` URI)."""
        return self.edit(lambda d: setattr(d, "srdf", ref))

    def keep_srdf(self, text: str) -> tuple[str, Validation]:
        """A generated SRDF, kept in the session and named by the spec; save writes it.

        Why not written now: a generated file is an output like the spec, written by "save" (or
        never); and its name, beside the spec, is never the robot's own SRDF
        (``<spec>.srdf``, else ``<spec>.collisions.srdf``: :meth:`SaveFence.srdf_name`).
        """
        with self._lock:
            name = self.fence.srdf_name(self.output)
            self._pending_srdf = (name, text)
            return name, self.set_srdf(name)

    def _states_of(self, d: Draft, part: str) -> dict[str, dict[str, float]]:
        if part == "robot":
            return d.states
        if part.startswith("manipulators."):
            return _manipulator(d, part).states
        return _chain(d, part).states

    def set_state(self, part: str, name: str, values: Mapping[str, float]) -> Validation:
        """A named state of a part (``robot`` for the spec's own ``states``), joint by joint."""
        if not name.strip():
            raise SetupError("a state needs a name", kind="state")
        clean: dict[str, float] = {}
        for joint, value in values.items():
            if not self.world.has_connection(joint):
                raise SetupError(f"no joint '{joint}' in the robot", kind="joint", name=joint)
            clean[joint] = round(float(value), 6)

        def change(d: Draft) -> None:
            self._states_of(d, part)[name] = clean

        return self.edit(change)

    def remove_state(self, part: str, name: str) -> Validation:
        """Drop a named state."""

        def change(d: Draft) -> None:
            states = self._states_of(d, part)
            if name not in states:
                raise SetupError(f"no state '{name}' on {part}", kind="state", name=name)
            del states[name]

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

    # ------------------------------------------------------------------ saving
    def save(self, path: Path | None = None) -> Path:
        """Write the spec if validate accepts it; refuse (listing the errors) if not.

        ``path`` ("save as") must lie inside the output's folder or one ``allow_save`` gave,
        be a ``.yaml``/``.yml`` file, not a file of the robot, and not an existing file other
        than the output or one this session wrote. A generated SRDF kept in the session is
        written first, beside the spec. A refused save writes and creates nothing.
        """
        with self._lock:
            snap = self._snapshot
            target = path or self.output
            if not snap.validation.valid:
                shown = "; ".join(p.render(str(target)) for p in snap.validation.errors[:5])
                raise SetupError(
                    f"not saved: the spec has {len(snap.validation.errors)} error(s): {shown}",
                    file=str(target),
                    kind="spec",
                )
            fence = self.fence
            dest, under, replace = fence.place(target)
            srdf = self._srdf_of(self._draft)
            srdf_at = None if srdf is None else fence.place(dest.parent / srdf[0], what="the SRDF")
            inputs = fence.input_map()
            for where, folder, force in filter(None, ((dest, under, replace), srdf_at)):
                # A link on the way is refused before the check stages anything there.
                check_writable(where, under=folder, force=force, inputs=inputs)
            if dest.resolve().parent != self.output.resolve().parent:
                check = self._validate(self._draft, snap.text, dest)
                if not check.valid:
                    raise SetupError(
                        "not saved: the spec's relative paths do not resolve from that folder",
                        file=str(target),
                        kind="spec",
                    )
            if srdf is not None and srdf_at is not None:
                s_dest, s_under, s_replace = srdf_at
                write_file(s_dest, srdf[1], under=s_under, force=s_replace, inputs=inputs)
                fence.remember(s_dest)
            write_spec(dest, snap.text, under=under, force=replace, inputs=inputs)
            fence.remember(dest)
            self._saved = (snap.text, srdf and srdf[1])
            self._snapshot = Snapshot(
                snap.version, snap.text, snap.validation, snap.questions, saved=True
            )
        self._publish()
        return target


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
