"""The setup assistant's page: the robot in 3D, its tree, the questions, parts, states, checks.

Why on the view's viser server (:class:`~robotspec.render.viewer.RobotViewer` without its panel):
the robot is drawn, posed and coloured the way ``view`` and ``render`` draw it, and nothing beyond
the ``view`` extra is needed. Every control is server-side state shared by all tabs, so two tabs
see one assistant; every callback goes through :meth:`SetupPage._guarded`, so whatever a page
sends, the server answers with a message, never a crash. The page is this module (the robot,
the tree, the questions, the state drawn) and one module per tab over a shared base:
``page_parts``, ``page_states``, ``page_more``, ``page_check`` (with ``page_matrix`` and
``page_accepted``), ``page_base``.

viser is used as ``Any`` (as in the viewer): its API is large and its stubs must not decide the
package's strict typing.
"""

from __future__ import annotations

import html
import threading
from collections.abc import Callable
from typing import Any

from robotspec.errors import RobotSpecError
from robotspec.render.scene import GREY, colour_parts
from robotspec.render.viewer import RobotViewer
from robotspec.setup.access import PageAccess, start_guarded
from robotspec.setup.collisions import AuditReport
from robotspec.setup.edits import _facing
from robotspec.setup.page_accepted import AcceptedPart
from robotspec.setup.page_base import problem_line
from robotspec.setup.page_check import CheckTab
from robotspec.setup.page_clients import PICK_COLOUR, ClientsPart
from robotspec.setup.page_more import MoreTab
from robotspec.setup.page_parts import PartsTab
from robotspec.setup.page_states import StatesTab
from robotspec.setup.page_yaml import yaml_html
from robotspec.setup.questions import FACINGS, Question
from robotspec.setup.session import SetupSession, Snapshot
from robotspec.setup.tree import TreeRow, tree_rows

__all__ = ["SELECTED_COLOUR", "SetupPage"]

#: The picked link, drawn apart from every part colour (in its own tab's scene).
SELECTED_COLOUR = PICK_COLOUR
#: The page's brand colour (#0d47a1): viser draws buttons in a lighter shade of it, which white
#: text still reads on at 4.5:1 or more (viser's own blue gives 3.6:1, a lighter brand 3.4:1).
BRAND = (13, 71, 161)
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


class SetupPage(ClientsPart, PartsTab, StatesTab, MoreTab, AcceptedPart, CheckTab):
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
        self._gui_lock = threading.RLock()
        self._questions_shown: tuple[Question, ...] | None = None
        self._q_handles: list[Any] = []
        self._proposed: list[Any] = []
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

    # ------------------------------------------------------------------ building
    def _build(self) -> None:
        gui = self.server.gui
        # No logo (an image without text) nor share button (an unnamed icon, and a page for
        # one's own eyes only); buttons in a blue that white text reads on (4.5:1, WCAG AA).
        gui.configure_theme(show_logo=False, show_share_button=False, brand_color=BRAND)
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
        with panel.add_tab("YAML"):  # what save writes, the lines errors cite marked
            self._yaml = gui.add_html("")
        panel.dock_left()
        panel.set_width(300)
        self._status = gui.add_markdown("")
        self._message = gui.add_markdown("Pick a link in the robot or the tree.")
        # Above the tabs, so Ctrl+Z and Ctrl+Shift+Z (the page's script) find them on any tab.
        self._button(gui, "undo", lambda: self._stepped(back=True))
        self._button(gui, "redo", lambda: self._stepped(back=False))
        self._build_clients(gui)  # this tab's own link list, and who else is here
        tabs = gui.add_tab_group()
        with tabs.add_tab("Questions"):
            self._q_intro = gui.add_markdown("")
            self._q_folder = gui.add_folder("open questions")
        with tabs.add_tab("Parts"):
            self._build_parts(gui)
        with tabs.add_tab("States"):
            self._build_states(gui)
        with tabs.add_tab("Frames & more"):
            self._build_more(gui)
        with tabs.add_tab("Check & save"):
            self._build_check(gui)

    # ------------------------------------------------------------------ drawing
    def _paint(self, body: str) -> None:
        colour = self._colours.get(body, GREY)
        for h in self.viewer.visual_meshes.get(body, ()):
            h.color = colour

    def _draw_tree(self) -> None:
        """The tree in its parts' colours, the picked link red: buttons, or text if too many."""
        if self._tree_buttons:
            self._tree.content = self._legend
            for link, button in self._tree_buttons.items():
                c = self._colours.get(link, GREY)
                if self._tree_colours.get(link) != c:
                    button.color = c
                    self._tree_colours[link] = c
            return
        out = [self._legend, "<div style='font-family:monospace;font-size:0.8em;line-height:1.45'>"]
        for r in self.rows:
            c = self._colours.get(r.link, GREY)
            style = ""
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
            self._yaml.content = yaml_html(snap.text, v.problems)
            self._problems.content = (
                "\n".join(problem_line(p) for p in v.problems) or "validate finds no problem"
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
            self._show_pairs()
            self._show_acceptable(v)
            self._show_accepted()
            self._show_more()
            self.shown_version = snap.version

    def _show_questions(self, questions: tuple[Question, ...]) -> None:
        if questions == self._questions_shown:
            return
        self._questions_shown = questions
        for h in [*self._q_handles, *reversed(self._proposed)]:  # a frame's label first
            h.remove()
        self._q_handles, self._proposed = [], []
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
                if any(c in FACINGS for c in q.choices):  # the frame each answer proposes, drawn
                    choice.on_update(self._guarded(self._proposer(q, choice)))
                    self._propose(q, str(choice.value))
                button = gui.add_button(f"apply to {q.id}")

                def answer(_e: Any, q: Question = q, choice: Any = choice) -> None:
                    v = self.session.answer(q.id, str(choice.value))
                    self._after(v, f"{q.id}: {choice.value}")

                button.on_click(self._guarded(answer))
                self._q_handles += [text, choice, button]

    def _proposer(self, q: Question, choice: Any) -> Callable[[Any], None]:
        def propose(_event: Any) -> None:
            self._propose(q, str(choice.value))

        return propose

    def _propose(self, q: Question, choice: str) -> None:
        """Axes at the tool frame as ``choice`` would turn it (red: the way the tool faces)."""
        with self._gui_lock:
            for h in reversed(self._proposed):  # the label, then its frame
                h.remove()
            self._proposed = []
            m = next(
                (m for m in self.session.draft().manipulators if q.part.endswith(m.name)), None
            )
            if m is None or m.tool_frame not in self.links:
                return
            axis = FACINGS.get(choice)  # another answer turns the frame; keeping it, as it is
            x, y, z, w = _facing(axis) if axis is not None else m.front_facing
            size = float(self.viewer.scene.size)
            at = f"/robot/{m.tool_frame}/proposed"
            self._proposed = [
                self.server.scene.add_frame(
                    at, wxyz=(w, -x, -y, -z), axes_length=0.15 * size, axes_radius=0.006 * size
                ),
                self.server.scene.add_label(f"{at}/label", f"proposed: {choice} (red)"),
            ]
