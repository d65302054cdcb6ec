"""The assistant's editable state: one draft, one lock, a validation after every change.

Why one object shared by every browser tab: two tabs on one server must see one state, and a
change from one must never interleave with another's; each mutation works on a copy under the
lock, validates the text it would save, and only then becomes the state (so a change that fails
halfway leaves nothing behind). Listeners hear of each new state, in the order made (the page
redraws on them). What each change does to the draft is :mod:`robotspec.setup.edits`.
"""

from __future__ import annotations

import copy
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from robotspec.errors import RobotSpecError
from robotspec.files.writing import check_writable, write_file
from robotspec.model.world import World
from robotspec.setup.accept import AcceptEdits, with_accepted
from robotspec.setup.edits import PartEdits, SetupError
from robotspec.setup.edits_more import MoreEdits
from robotspec.setup.edits_sensors import SensorEdits
from robotspec.setup.edits_states import StateEdits
from robotspec.setup.extras import Extras, apply_edits
from robotspec.setup.history import History, describe
from robotspec.setup.questions import Question, questions_of
from robotspec.setup.save import spec_text, write_spec
from robotspec.setup.source import Source, open_source
from robotspec.setup.targets import SaveFence
from robotspec.setup.text_edit import TextEditError
from robotspec.setup.validation import Validation, validate_text
from robotspec.spec.draft.model import Draft

__all__ = ["SetupError", "SetupSession", "Snapshot"]


@dataclass(frozen=True)
class Snapshot:
    """One state of the session: its text, its validation, its open questions."""

    version: int
    text: str
    validation: Validation
    questions: tuple[Question, ...]
    saved: bool


class SetupSession(PartEdits, MoreEdits, SensorEdits, StateEdits, AcceptEdits):
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
        #: What the session holds beside the draft (``setup/extras.py``), undone with it.
        self._extras = Extras()
        #: Undo and redo, each step with what it changed (``setup/history.py``).
        self._history: History[tuple[Draft, Extras, Snapshot]] = History()
        self._listeners: list[Callable[[Snapshot], None]] = []
        self._version = 0
        #: Ordered delivery (:meth:`_publish`): the last (version, saved) delivered, and
        #: whether a thread is delivering now.
        self._publish_lock = threading.Lock()
        self._delivered: tuple[int, bool] = (-1, False)
        self._delivering = False
        self._saved: tuple[str, str | None] | None = None
        self._snapshot = self._make_snapshot(self._draft, self._extras)
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

    def part_origin(self, part: str) -> str | None:
        """Where another file (a composed robot's part, an extended spec) defines ``part``.

        Such a part is shown, and its changes are refused with that place: the assistant edits
        only the spec it opened. None: the opened spec (or the draft) holds it.
        """
        written = self.source.written
        return None if written is None else written.defined_in(part)

    @property
    def extras(self) -> Extras:
        """What the session holds beside the draft now (a value)."""
        return self._extras

    @property
    def pair_choices(self) -> dict[frozenset[str], bool]:
        """Collision pairs a person disabled (True) or checks (False), by hand (setup/pairs.py)."""
        return dict(self._extras.pairs)

    def subscribe(self, listener: Callable[[Snapshot], None]) -> None:
        """Call ``listener`` with every new state (from the thread that made it)."""
        with self._lock:
            self._listeners.append(listener)

    # ------------------------------------------------------------------ the one way to change
    @staticmethod
    def _srdf_of(draft: Draft, extras: Extras) -> tuple[str, str] | None:
        """The generated SRDF ``draft`` names, while it is kept in the session (not saved)."""
        pending = extras.srdf
        return pending if pending is not None and draft.srdf == pending[0] else None

    def _validate(self, draft: Draft, extras: Extras, text: str, at: Path) -> Validation:
        """What validate says of ``text`` saved as ``at`` (a kept SRDF staged beside it)."""
        srdf = self._srdf_of(draft, extras)
        if srdf is None:
            return validate_text(text, at, package_paths=self.package_paths)

        def naming(staged: str) -> str:
            d = copy.copy(draft)
            d.srdf = staged
            return self._text(d, extras)

        return validate_text(naming, at, package_paths=self.package_paths, srdf=srdf)

    def _text(self, draft: Draft, extras: Extras) -> str:
        """The text saving writes: a spec's own text with the changes made, or the draft's."""
        written = self.source.written
        try:
            if written is None:
                text = spec_text(draft, self.source.kept, self.source.presets)
            else:
                text = written.text_of(draft, self.source.presets)
            if extras.edits:  # what the draft cannot state; before the entries accepted now
                elsewhere = written.elsewhere if written is not None else (lambda path: None)
                fixed = ("description",) if written is not None and written.composed else ()
                text = apply_edits(text, extras.edits, elsewhere=elsewhere, fixed=fixed)
            return with_accepted(text, draft.accepted)  # new accept_warnings lines, if any
        except TextEditError as exc:
            raise SetupError(exc.message, kind=exc.detail.kind, name=exc.detail.name) from None

    def _make_snapshot(self, draft: Draft, extras: Extras) -> Snapshot:
        text = self._text(draft, extras)
        srdf = self._srdf_of(draft, extras)
        return Snapshot(
            self._version,
            text,
            self._validate(draft, extras, text, self.output),
            questions_of(draft, self.source.presets),
            saved=(text, srdf and srdf[1]) == self._saved,
        )

    def edit(
        self,
        change: Callable[[Draft], None],
        *,
        extras: Callable[[Extras], Extras] | None = None,
        what: str | None = None,
    ) -> Validation:
        """Apply ``change`` to a copy of the draft, validate it, make it the state.

        ``extras`` changes what the session holds beside the draft in the same step; ``what``
        is how undo names the step (default: the lines it changed).
        """
        with self._lock:
            try:
                new = copy.deepcopy(self._draft)
                change(new)
                ext = self._extras if extras is None else extras(self._extras)
                snap = self._make_snapshot(new, ext)
            except RobotSpecError as exc:
                self._history.fail(exc.message)
                raise
            self._version += 1
            snap = replace(snap, version=self._version)
            before = (self._draft, self._extras, self._snapshot)
            said = what or describe(before[2].text, snap.text)
            self._history.record(before, (new, ext, snap), said)
            self._draft, self._extras, self._snapshot = new, ext, snap
        self._publish()
        return snap.validation

    def failed(self, what: str) -> None:
        """An action of the page failed and changed nothing: the next undo says so."""
        with self._lock:
            self._history.fail(what)

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
        return self.step(back=True)[0]

    def redo(self) -> Validation:
        """Make the change undone last again (nothing happens when there is none)."""
        return self.step(back=False)[0]

    def step(self, *, back: bool) -> tuple[Validation, str]:
        """Undo (``back``) or redo one change; what it did in words ("undone: line 12: ...").

        The first undo after a failed action undoes nothing and says so
        (:class:`~robotspec.setup.history.History`).
        """
        with self._lock:
            step, said = self._history.undo() if back else self._history.redo()
            if step is None:
                return self.validation, said
            draft, extras, snap = step.before if back else step.after
            self._version += 1
            # The text and its validation as they were; saved or not is judged now.
            srdf = self._srdf_of(draft, extras)
            saved = (snap.text, srdf and srdf[1]) == self._saved
            snap = replace(snap, version=self._version, saved=saved)
            self._draft, self._extras, self._snapshot = copy.deepcopy(draft), extras, snap
        self._publish()
        return snap.validation, said

    # ------------------------------------------------------------------ states and the SRDF
    def set_srdf(self, ref: str | None) -> Validation:
        """The SRDF the spec names (a path relative to the spec, or a ``package://`` URI)."""
        return self.edit(lambda d: setattr(d, "srdf", ref))

    def keep_srdf(
        self,
        text: str,
        *,
        extras: Callable[[Extras], Extras] | None = None,
        what: str | None = None,
    ) -> tuple[str, Validation]:
        """A generated SRDF, kept in the session and named by the spec; save writes it.

        One change undo takes back whole: the SRDF kept before, the spec's ``srdf:`` line, and
        ``extras`` (a pair or a passive joint chosen by hand, said as ``what``).

        Why not written now: a generated file is an output like the spec, written by "save" (or
        never); and its name, beside the spec, is never the robot's own SRDF
        (``<spec>.srdf``, else ``<spec>.collisions.srdf``: :meth:`SaveFence.srdf_name`).
        """
        with self._lock:
            name = self.fence.srdf_name(self.output)

            def kept(e: Extras) -> Extras:
                return replace(e if extras is None else extras(e), srdf=(name, text))

            said = what or f"the SRDF {name} kept until save"
            return name, self.edit(lambda d: setattr(d, "srdf", name), extras=kept, what=said)

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
            srdf = self._srdf_of(self._draft, self._extras)
            srdf_at = None if srdf is None else fence.place(dest.parent / srdf[0], what="the SRDF")
            inputs = fence.input_map()
            for where, folder, force in filter(None, ((dest, under, replace), srdf_at)):
                # A link on the way is refused before the check stages anything there.
                check_writable(where, under=folder, force=force, inputs=inputs)
            if dest.resolve().parent != self.output.resolve().parent:
                check = self._validate(self._draft, self._extras, snap.text, dest)
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
