"""The setup assistant's page: the robot in 3D, its tree, the questions, parts, states, checks.

Why on the view's viser server (:class:`~robotspec.render.viewer.RobotViewer` without its panel):
the robot is drawn, posed and coloured the way ``view`` and ``render`` draw it, and nothing beyond
the ``view`` extra is needed. Every control is server-side state shared by all tabs, so two tabs
see one assistant; every callback goes through :meth:`SetupPage._guarded`, so whatever a page
sends, the server answers with a message, never a crash.

viser is used as ``Any`` (as in the viewer): its API is large and its stubs must not decide the
package's strict typing.
"""

from __future__ import annotations

import html
import sys
import threading
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from robotspec.errors import RobotSpecError
from robotspec.render.scene import GREY, colour_parts
from robotspec.render.viewer import RobotViewer
from robotspec.setup.access import PageAccess, start_guarded
from robotspec.setup.collisions import AuditReport
from robotspec.setup.questions import FACINGS, FORWARDS, Question
from robotspec.setup.session import SetupSession, Snapshot
from robotspec.setup.tree import TreeRow, tree_rows
from robotspec.setup.validation import Problem, Validation

__all__ = ["SELECTED_COLOUR", "SetupPage"]

#: The picked link, drawn apart from every part colour.
SELECTED_COLOUR = (230, 20, 20)
_NEW_KINDS = ("arm", "leg", "chain", "torso", "neck", "manipulator", "camera")
_NO_PRESET = "(angles below)"
#: Above this many links the tree is text (and the link list picks): a button each is too many.
_MAX_TREE_BUTTONS = 400


def _bare(session: SetupSession) -> Any:
    """The robot with no parts, to draw when the spec as given does not compile."""
    from robotspec.setup.save import spec_text
    from robotspec.setup.validation import validate_text

    d = session.draft()
    d.chains, d.manipulators, d.cameras, d.torso, d.neck, d.states = [], [], [], None, None, {}
    v = validate_text(spec_text(d, {}), session.output, package_paths=session.package_paths)
    if v.robot is None:
        first = v.errors[0] if v.errors else None
        raise RobotSpecError(first.message if first else "the robot does not compile")
    return v.robot


def _problem_line(p: Problem) -> str:
    where = f"line {p.line}" if p.line is not None else ""
    if p.file is not None:
        where = f"{Path(p.file).name}:{p.line}" if p.line is not None else Path(p.file).name
    icon = "✖" if p.severity != "warning" else "⚠"
    return f"- {icon} `{p.part}` {where}: {html.escape(p.message)}"


class SetupPage:
    """The page of one session, served until :meth:`stop`."""

    def __init__(
        self,
        session: SetupSession,
        *,
        host: str = "127.0.0.1",
        port: int = 8080,
        audit_report: AuditReport | None = None,
    ) -> None:
        self.session = session
        self._audit_report = audit_report
        robot = session.validation.robot or _bare(session)
        #: This run's secret and origin rule; every handshake of the server passes it first.
        self.access = PageAccess.for_host(host)
        self.viewer = start_guarded(
            self.access,
            lambda: RobotViewer(
                robot,
                robot.world.default_configuration(),
                host=host,
                port=port,
                on_missing_mesh="skip",
                controls=False,
            ),
            lambda viewer: viewer.stop(),
        )
        self.server: Any = self.viewer.server
        self.rows: tuple[TreeRow, ...] = tree_rows(session.world)
        self.links = tuple(r.link for r in self.rows)
        self._colours: dict[str, tuple[int, int, int]] = dict(self.viewer.scene.body_colours)
        self._groups: dict[str, str] = dict(self.viewer.scene.group_of_body)
        self._legend = ""
        self.selected: str | None = None
        self._gui_lock = threading.RLock()
        self._questions_shown: tuple[Question, ...] | None = None
        self._q_handles: list[Any] = []
        self._sliders: dict[str, Any] = {}
        #: Whether a collision check runs; checked and set under its lock (two tabs may press).
        self._busy = False
        self._busy_lock = threading.Lock()
        self.shown_version = -1
        #: The (version, saved) drawn last: an older snapshot arriving late is not drawn.
        self._shown: tuple[int, bool] = (-1, False)
        self.last_message = ""
        self._build()
        for body, handles in self.viewer.visual_meshes.items():
            for h in handles:
                h.on_click(self._guarded(self._picker(body)))
        session.subscribe(self._on_snapshot)
        self._on_snapshot(session.snapshot)
        self._select_part(self._part.value)
        self._show_sliders()

    def _picker(self, body: str) -> Callable[[Any], None]:
        def pick(_event: Any) -> None:
            self.select(body)

        return pick

    @property
    def url(self) -> str:
        """Where to point a browser: the page's address with this run's token."""
        return self.access.address(str(self.viewer.url))

    def stop(self) -> None:
        """Stop serving."""
        self.viewer.stop()

    # ------------------------------------------------------------------ robustness
    def _guarded(self, fn: Callable[[Any], None]) -> Callable[[Any], None]:
        """A callback that acts on a person's input only, and reports instead of raising."""

        def run(event: Any) -> None:
            if getattr(event, "client", True) is None:
                return  # a value the server set itself
            try:
                fn(event)
            except RobotSpecError as exc:
                near = f" (did you mean {', '.join(exc.suggestions)}?)" if exc.suggestions else ""
                self.say(f"**{exc.severity}:** {html.escape(exc.message)}{near}")
            except Exception as exc:  # noqa: BLE001 - the server outlives any bug in one action
                traceback.print_exc(file=sys.stderr)
                self.say(f"**internal error:** {type(exc).__name__}: {html.escape(str(exc))}")

        return run

    def say(self, text: str) -> None:
        """Show the outcome of the last action."""
        self.last_message = text
        self._message.content = text

    def _after(self, v: Validation, done: str) -> None:
        if v.valid:
            self.say(f"{done}; the spec is valid")
        else:
            shown = "\n".join(_problem_line(p) for p in v.errors[:4])
            self.say(f"{done}; **the spec is now invalid:**\n\n{shown}")

    # ------------------------------------------------------------------ building
    def _build(self) -> None:
        gui = self.server.gui
        panel = gui.add_panel()
        with panel.add_tab("Kinematic tree"):
            self._tree = gui.add_html("")
            self._tree_buttons: dict[str, Any] = {}
            self._tree_colours: dict[str, tuple[int, int, int]] = {}
            if len(self.rows) <= _MAX_TREE_BUTTONS:  # a tree to click in
                for r in self.rows:
                    b = gui.add_button(
                        "· " * r.depth + r.link,
                        color=GREY,
                        hint=f"{r.joint} ({r.joint_type})" if r.joint else "the root link",
                    )
                    b.on_click(self._guarded(self._picker(r.link)))
                    self._tree_buttons[r.link] = b
        panel.dock_left()
        panel.set_width(300)
        self._status = gui.add_markdown("")
        self._message = gui.add_markdown("Pick a link in the robot or the tree.")
        self._link = gui.add_dropdown("link", self.links, initial_value=self.links[0])
        self._link.on_update(self._guarded(lambda _e: self.select(str(self._link.value))))
        tabs = gui.add_tab_group()
        with tabs.add_tab("Questions"):
            self._q_intro = gui.add_markdown("")
            self._q_folder = gui.add_folder("open questions")
        with tabs.add_tab("Parts"):
            self._build_parts(gui)
        with tabs.add_tab("States"):
            self._build_states(gui)
        with tabs.add_tab("Check & save"):
            self._build_check(gui)

    def _button(self, gui: Any, label: str, action: Callable[[], None]) -> Any:
        b = gui.add_button(label)
        b.on_click(self._guarded(lambda _e: action()))
        return b

    def _build_parts(self, gui: Any) -> None:
        s = self.session
        self._part = gui.add_dropdown("part", s.parts(), initial_value=s.parts()[0])
        self._part.on_update(self._guarded(lambda _e: self._select_part(str(self._part.value))))
        self._part_info = gui.add_markdown("")
        self._f_chain = gui.add_folder("chain")
        with self._f_chain:
            self._button(gui, "root = picked link", lambda: self._set_chain(root=self._pick()))
            self._button(gui, "tip = picked link", lambda: self._set_chain(tip=self._pick()))
            self._kind = gui.add_dropdown("kind", ("arm", "leg", "chain"))
            self._kind.on_update(self._guarded(lambda _e: self._set_chain(kind=self._kind.value)))
            self._side = gui.add_dropdown("side", ("by position", "left", "right"))
            self._side.on_update(self._guarded(lambda _e: self._set_side()))
        self._f_hand = gui.add_folder("manipulator")
        with self._f_hand:
            self._button(gui, "tool frame = picked link", lambda: self._set_hand(tool=True))
            self._button(gui, "hand root = picked link", lambda: self._set_hand(root=True))
            self._button(gui, "thumb tip = picked link", lambda: self._set_hand(thumb=True))
            self._button(gui, "finger tip = picked link", lambda: self._set_hand(finger=True))
            self._finger_name = gui.add_text("finger name", "index")
            self._button(gui, "named finger tip = picked link", lambda: self._set_hand(named=True))
            self._button(gui, "no fingers (generic)", lambda: self._set_hand(generic=True))
            self._facing = gui.add_dropdown("tool faces", tuple(FACINGS))
            self._facing.on_update(self._guarded(lambda _e: self._set_hand(facing=True)))
        self._f_camera = gui.add_folder("camera")
        with self._f_camera:
            self._button(gui, "body = picked link", lambda: self._set_camera(body=True))
            self._preset = gui.add_dropdown(
                "preset", (_NO_PRESET, *s.source.presets), initial_value=_NO_PRESET
            )
            self._preset.on_update(self._guarded(lambda _e: self._set_camera(preset=True)))
            self._fov = gui.add_vector2(
                "angles (rad)", (1.0, 0.75), min=(0.01, 0.01), max=(3.1, 3.1), step=0.01
            )
            self._button(gui, "set angles", lambda: self._set_camera(fov=True))
            self._optical = gui.add_dropdown("looks along", ("+z (optical)", "+x (body)"))
            self._optical.on_update(self._guarded(lambda _e: self._set_camera(optical=True)))
        self._f_drive = gui.add_folder("drive")
        with self._f_drive:
            self._drive = gui.add_dropdown("base", ("fixed", "omni", "differential", "floating"))
            self._drive.on_update(
                self._guarded(lambda _e: self._after(s.set_drive(self._drive.value), "drive set"))
            )
            self._forward = gui.add_dropdown("robot", tuple(FORWARDS))
            self._forward.on_update(self._guarded(lambda _e: self._set_forward()))
        self._button(gui, "remove this part", self._remove_part)
        with gui.add_folder("add a part", expand_by_default=False):
            self._new_name = gui.add_text("name", "")
            self._new_kind = gui.add_dropdown("kind", _NEW_KINDS)
            self._button(gui, "add at the picked link", self._add_part)

    def _build_states(self, gui: Any) -> None:
        holders = self._state_holders()
        self._state_part = gui.add_dropdown("states of", holders, initial_value=holders[0])
        self._state_part.on_update(self._guarded(lambda _e: self._show_sliders()))
        self._state_info = gui.add_markdown("")
        with gui.add_folder("set all joints"):
            self._button(gui, "lower limits", lambda: self._slide_to(0.0))
            self._button(gui, "middle", lambda: self._slide_to(0.5))
            self._button(gui, "upper limits", lambda: self._slide_to(1.0))
        self._slider_folder = gui.add_folder("joints")
        self._state_name = gui.add_text("state name", "park")
        self._button(gui, "save the state", self._save_state)
        self._saved_states = gui.add_dropdown("saved states", ("(none)",))
        self._button(gui, "show it", self._show_state)
        self._button(gui, "remove it", self._remove_state)

    def _build_check(self, gui: Any) -> None:
        self._problems = gui.add_markdown("")
        self._button(gui, "undo", lambda: self._after(self.session.undo(), "undone"))
        with gui.add_folder("self-collision matrix"):
            self._samples = gui.add_number("samples", 2000, min=100, max=1_000_000, step=100)
            self._button(gui, "generate collision matrix", lambda: self._collisions("generate"))
            self._button(gui, "audit the SRDF", lambda: self._collisions("audit"))
            self._progress = gui.add_progress_bar(0.0, visible=False)
            self._collision_text = gui.add_markdown(
                "The generated SRDF stays here until *save*, which writes it beside the spec "
                "(never over the robot's own SRDF)."
            )
        self._save_path = gui.add_text("save as", str(self.session.output))
        where = ", ".join(f"`{html.escape(str(f))}`" for f in self.session.fence.folders)
        gui.add_markdown(f"<small>save as writes inside {where} only</small>")
        self._button(gui, "save", self._save)

    # ------------------------------------------------------------------ selection
    def select(self, link: str) -> None:
        """Pick a link: highlighted in 3D, marked in the tree, chosen in the dropdown."""
        if link not in self.links:
            raise RobotSpecError(f"no link '{link}' in the robot", kind="link", name=link)
        with self._gui_lock:
            previous, self.selected = self.selected, link
            if self._link.value != link:
                self._link.value = link
            for body in (previous, link):
                if body is not None:
                    self._paint(body)
            self._draw_tree()
        part = self._groups.get(link)
        self.say(f"picked **{link}**" + (f" (in {part})" if part else ""))

    def _pick(self) -> str:
        if self.selected is None:
            raise RobotSpecError("pick a link first (click the robot, or choose it above)")
        return self.selected

    def _paint(self, body: str) -> None:
        colour = SELECTED_COLOUR if body == self.selected else self._colours.get(body, GREY)
        for h in self.viewer.visual_meshes.get(body, ()):
            h.color = colour

    def _draw_tree(self) -> None:
        """The tree in its parts' colours, the picked link red: buttons, or text if too many."""
        if self._tree_buttons:
            self._tree.content = self._legend
            for link, button in self._tree_buttons.items():
                c = SELECTED_COLOUR if link == self.selected else self._colours.get(link, GREY)
                if self._tree_colours.get(link) != c:
                    button.color = c
                    self._tree_colours[link] = c
            return
        out = [self._legend, "<div style='font-family:monospace;font-size:0.8em;line-height:1.45'>"]
        for r in self.rows:
            c = self._colours.get(r.link, GREY)
            style = "background:#fdd;font-weight:bold;" if r.link == self.selected else ""
            out.append(
                f"<div style='padding-left:{0.8 * r.depth:.1f}em;{style}'>"
                f"<span style='display:inline-block;width:0.7em;height:0.7em;"
                f"background:rgb{c};margin-right:0.3em'></span>{html.escape(r.link)}"
                + (f" <span style='color:#888'>({r.joint_type})</span>" if r.joint_type else "")
                + "</div>"
            )
        self._tree.content = "".join(out) + "</div>"

    # ------------------------------------------------------------------ state of the session
    def _on_snapshot(self, snap: Snapshot) -> None:
        with self._gui_lock:
            if (snap.version, snap.saved) <= self._shown:
                return  # every tab shows this page: never draw a state older than the one drawn
            self._shown = (snap.version, snap.saved)
            v = snap.validation
            n_q = len(snap.questions)
            self._status.content = (
                f"**{'✔ valid' if v.valid else '✖ invalid'}** · {len(v.errors)} errors · "
                f"{len(v.warnings)} warnings · {n_q} open questions · "
                f"{'saved' if snap.saved else 'not saved'} · checked in {v.seconds:.2f} s"
            )
            self._problems.content = (
                "\n".join(_problem_line(p) for p in v.problems) or "validate finds no problem"
            )
            if v.robot is not None:
                colours, groups, legend = colour_parts(v.robot)
                self._colours, self._groups = colours, groups
                self._legend = "".join(
                    f"<span style='display:inline-block;width:0.8em;height:0.8em;"
                    f"background:rgb{e.colour};margin:0 0.3em'></span>{html.escape(e.name)} "
                    for e in legend
                    if e.kind != "overlay"
                )
                with self.server.atomic():
                    for body in self.viewer.visual_meshes:
                        self._paint(body)
                self.viewer.draw_overlays(v.robot)  # tool frames, cameras, drive as now edited
            parts = self.session.parts()
            if tuple(self._part.options) != parts:
                self._part.options = parts
            holders = self._state_holders()
            if tuple(self._state_part.options) != holders:
                self._state_part.options = holders
            self._draw_tree()
            self._show_questions(snap.questions)
            self._show_part_info()
            self._show_saved_states()
            self.shown_version = snap.version

    def _show_questions(self, questions: tuple[Question, ...]) -> None:
        if questions == self._questions_shown:
            return
        self._questions_shown = questions
        for h in self._q_handles:
            h.remove()
        self._q_handles = []
        gui = self.server.gui
        self._q_intro.content = (
            f"{len(questions)} guesses of the draft to check: keep each, or choose another answer."
            if questions
            else "Every guess of the draft is answered."
        )
        with self._q_folder:
            for q in questions:
                text = gui.add_markdown(
                    f"**{html.escape(q.id)}**: {html.escape(q.guess)}  \n"
                    f"<small>why: {html.escape(q.reason)}</small>"
                )
                choice = gui.add_dropdown(f"answer {q.id}", q.choices, initial_value=q.choices[0])
                button = gui.add_button(f"apply to {q.id}")

                def answer(_e: Any, q: Question = q, choice: Any = choice) -> None:
                    v = self.session.answer(q.id, str(choice.value))
                    self._after(v, f"{q.id}: {choice.value}")

                button.on_click(self._guarded(answer))
                self._q_handles += [text, choice, button]

    # ------------------------------------------------------------------ parts
    def _select_part(self, part: str) -> None:
        kind = part.partition(".")[0]
        self._f_chain.visible = kind in ("chains", "torso", "neck")
        self._f_hand.visible = kind == "manipulators"
        self._f_camera.visible = kind == "sensors"
        self._f_drive.visible = kind == "drive"
        self._show_part_info()

    def _show_part_info(self) -> None:
        part = str(self._part.value)
        if part not in self.session.parts():
            return
        d = self.session.draft()
        kind, _, name = part.partition(".")
        lines: list[str] = []
        if kind in ("chains", "torso", "neck"):
            c = next((c for c in d.chains if c.name == name), None) if kind == "chains" else None
            c = c or getattr(d, part, None)
            if c is not None:
                lines.append(f"{c.role} **{c.root or '?'} → {c.tip or '?'}**")
                if c.group:
                    lines.append(f"SRDF group {c.group}")
                if c.manipulator:
                    lines.append(f"carries {c.manipulator}")
                self._kind.value = c.role if c.role in ("arm", "leg", "chain") else "chain"
                self._side.value = c.side or "by position"
        elif kind == "manipulators":
            m = next(m for m in d.manipulators if m.name == name)
            lines.append(f"root **{m.root}**, tool frame **{m.tool_frame}**")
            if m.thumb and m.finger:
                lines.append(f"thumb → {m.thumb.tip}, finger → {m.finger.tip}")
            elif m.thumb and m.fingers:
                named = ", ".join(f"{k} → {f.tip}" for k, f in m.fingers.items())
                lines.append(f"thumb → {m.thumb.tip}, {named}")
        elif kind == "sensors":
            cam = next(c for c in d.cameras if c.name == name)
            what = cam.preset or (cam.field_of_view and f"angles {cam.field_of_view}") or "?"
            lines.append(f"camera on **{cam.body}**, {what}")
            self._preset.value = cam.preset or _NO_PRESET
        elif kind == "drive" and d.drive is not None:
            facing = next((k for k, v in FORWARDS.items() if v == (d.forward or (1, 0, 0))), None)
            lines.append(f"base: **{d.drive.type}**; the robot {facing or d.forward}")
            self._drive.value = d.drive.type
            if facing is not None:
                self._forward.value = facing
        lines += [_problem_line(p) for p in self.session.validation.at(part)]
        self._part_info.content = "  \n".join(lines)

    def _part_name(self) -> str:
        return str(self._part.value)

    def _set_chain(
        self, *, root: str | None = None, tip: str | None = None, kind: str | None = None
    ) -> None:
        part = self._part_name()
        v = self.session.set_chain(part, root=root, tip=tip, kind=kind)
        self._after(v, f"{part} changed")

    def _set_side(self) -> None:
        side = str(self._side.value)
        part = self._part_name()
        v = self.session.set_chain(part, side=None if side == "by position" else side)
        self._after(v, f"{part}: side {side}")

    def _set_hand(
        self,
        *,
        tool: bool = False,
        root: bool = False,
        thumb: bool = False,
        finger: bool = False,
        generic: bool = False,
        facing: bool = False,
        named: bool = False,
    ) -> None:
        part = self._part_name()
        name = part.removeprefix("manipulators.")
        m = next((m for m in self.session.draft().manipulators if m.name == name), None)
        if m is None or not part.startswith("manipulators."):
            raise RobotSpecError(f"choose a manipulator as the part first (not {part})")
        kw: dict[str, Any] = {}
        if tool:
            kw["tool_frame"] = self._pick()
        if root:
            kw["root"] = self._pick()
        if thumb:
            kw["thumb"] = (m.root, self._pick())
        if finger:
            kw["finger"] = (m.root, self._pick())
        if facing:
            kw["facing"] = FACINGS[str(self._facing.value)]
        if named:
            kw["named"] = (str(self._finger_name.value), self._pick())
        v = self.session.set_manipulator(part, generic=generic, **kw)
        self._after(v, f"{part} changed")

    def _set_camera(
        self, *, body: bool = False, preset: bool = False, fov: bool = False, optical: bool = False
    ) -> None:
        part = self._part_name()
        kw: dict[str, Any] = {}
        if body:
            kw["body"] = self._pick()
        if preset:
            if self._preset.value == _NO_PRESET:
                return
            kw["preset"] = str(self._preset.value)
        if fov:
            h, w = self._fov.value
            kw["field_of_view"] = (float(h), float(w))
        if optical:
            kw["optical"] = str(self._optical.value).startswith("+z")
        self._after(self.session.set_camera(part, **kw), f"{part} changed")

    def _set_forward(self) -> None:
        choice = str(self._forward.value)
        axis = FORWARDS[choice]
        v = self.session.set_forward(None if axis == (1.0, 0.0, 0.0) else axis)
        self._after(v, f"the robot {choice}")

    def _remove_part(self) -> None:
        part = self._part_name()
        if part == "drive":
            raise RobotSpecError("the drive cannot be removed; choose 'fixed' for none")
        self._after(self.session.remove(part), f"{part} removed")
        self._part.value = self.session.parts()[0]
        self._select_part(str(self._part.value))

    def _add_part(self) -> None:
        name = str(self._new_name.value).strip()
        kind = str(self._new_kind.value)
        link = self._pick()
        s = self.session
        if kind in ("torso", "neck"):
            v, part = s.add_chain(kind, link, link), kind
        elif not name:
            raise RobotSpecError("give the new part a name")
        elif kind == "manipulator":
            v, part = s.add_manipulator(name, link, link), f"manipulators.{name}"
        elif kind == "camera":
            v, part = s.add_camera(name, link), f"sensors.{name}"
        else:
            v, part = s.add_chain(name, link, link, kind), f"chains.{name}"
        self._part.value = part
        self._select_part(part)
        self._after(v, f"{part} added at {link}; now pick its other links")

    # ------------------------------------------------------------------ states
    def _state_holders(self) -> tuple[str, ...]:
        parts = [p for p in self.session.parts() if p.split(".")[0] not in ("drive", "sensors")]
        return ("robot", *parts)

    def _show_sliders(self) -> None:
        part = str(self._state_part.value)
        joints = self.session.part_joints(part)
        with self._gui_lock:
            for h in self._sliders.values():
                h.remove()
            self._sliders = {}
            gui = self.server.gui
            with self._slider_folder:
                for j in joints:
                    lo, hi = self.session.joint_range(j)
                    step = max((hi - lo) / 200.0, 1e-4)
                    now = float(np.clip(self._joint_value(j), lo, hi))
                    sl = gui.add_slider(j, min=lo, max=hi, step=step, initial_value=now)
                    sl.on_update(self._guarded(lambda _e: self._preview()))
                    self._sliders[j] = sl
            self._state_info.content = (
                f"{len(joints)} joints of {part}" if joints else f"{part} moves no joint"
            )
            self._show_saved_states()
        self._preview()

    def _joint_value(self, joint: str) -> float:
        """The joint's position in the pose shown (the default pose until a slider moves)."""
        world = self.viewer.robot.world
        if not world.has_connection(joint):
            return 0.0
        return float(self.viewer.q[world.get_connection_by_name(joint).dofs[0]])

    def _show_saved_states(self) -> None:
        part = str(self._state_part.value)
        names = tuple(self.session.part_states(part)) if part in self._state_holders() else ()
        options = names or ("(none)",)
        if tuple(self._saved_states.options) != options:
            self._saved_states.options = options

    def _preview(self) -> None:
        """Pose the robot at the sliders' values (the pose stays when another part is chosen)."""
        values = {j: float(s.value) for j, s in self._sliders.items()}
        world = self.viewer.robot.world
        q = self.viewer.q.copy()
        for j, value in values.items():
            if world.has_connection(j):
                q[world.get_connection_by_name(j).dofs[0]] = value
        self.viewer.q = np.asarray(q, dtype=np.float64)
        self.viewer.update(self.viewer.q)

    def _slide_to(self, fraction: float) -> None:
        if not self._sliders:
            self._show_sliders()
        for j, sl in self._sliders.items():
            lo, hi = self.session.joint_range(j)
            sl.value = lo + fraction * (hi - lo)
        self._preview()

    def _save_state(self) -> None:
        part = str(self._state_part.value)
        if not self._sliders:
            self._show_sliders()
        name = str(self._state_name.value).strip()
        values = {j: float(s.value) for j, s in self._sliders.items()}
        self._after(self.session.set_state(part, name, values), f"state {name} of {part} saved")

    def _show_state(self) -> None:
        part, name = str(self._state_part.value), str(self._saved_states.value)
        values = self.session.part_states(part).get(name)
        if values is None:
            raise RobotSpecError(f"{part} has no saved state '{name}'")
        for j, value in values.items():
            if j in self._sliders:
                self._sliders[j].value = value
        self._state_name.value = name
        self._preview()

    def _remove_state(self) -> None:
        part, name = str(self._state_part.value), str(self._saved_states.value)
        self._after(self.session.remove_state(part, name), f"state {name} removed")

    # ------------------------------------------------------------------ checks and saving
    def _collisions(self, what: str) -> None:
        from robotspec.setup.collisions import audit_session, generate_matrix, plain_audit_report

        with self._busy_lock:
            if self._busy:
                raise RobotSpecError("the collision check is running; wait for it to finish")
            self._busy = True
        samples = int(self._samples.value)
        self._progress.visible = True
        self._progress.value = 0.0
        self._collision_text.content = f"{what}: running..."
        last = [0.0]

        def progress(done: int, total: int) -> None:
            now = time.monotonic()
            if now - last[0] > 0.2 or done >= total:
                last[0] = now
                self._progress.value = 100.0 * done / max(total, 1)

        def work() -> None:
            try:
                if what == "generate":
                    r = generate_matrix(self.session, samples=samples, progress=progress)
                    self._collision_text.content = r.summary
                else:
                    report = self._audit_report or plain_audit_report
                    ok, text = audit_session(
                        self.session, samples=samples, progress=progress, report=report
                    )
                    head = "every entry is right" if ok else "**some entries are wrong**"
                    self._collision_text.content = f"{head}\n\n```\n{text}\n```"
            except RobotSpecError as exc:
                self._collision_text.content = f"**error:** {html.escape(exc.message)}"
            except Exception as exc:  # noqa: BLE001 - a bug must not end the server
                traceback.print_exc(file=sys.stderr)
                self._collision_text.content = f"**internal error:** {type(exc).__name__}: {exc}"
            finally:
                self._progress.value = 100.0
                with self._busy_lock:
                    self._busy = False

        threading.Thread(target=work, name=f"setup-{what}", daemon=True).start()

    def _save(self) -> None:
        path = self.session.save(Path(str(self._save_path.value)).expanduser())
        self.say(f"saved **{html.escape(str(path))}**; `robotspec validate {path}` accepts it")
