"""The page's *frames & more* tab: extra frames and their rotation, other sensors, passive joints.

Why a tab of its own: these are what a spec says beyond the draft's parts (``setup/edits_more.py``
and ``setup/passive.py``), each a small form. Every form has a note under its inputs where a
refused input says why (a quaternion that is not a unit one, a name taken, a joint that does not
move), besides the message line, so the reason stands where the person typed.
"""

from __future__ import annotations

import html
from collections.abc import Callable
from typing import Any

from robotspec.errors import RobotSpecError
from robotspec.setup.edits_more import ROTATIONS, parse_numbers
from robotspec.setup.page_base import PageBase

__all__ = ["MoreTab", "at_input"]

NO_FRAME = "(no extra frame)"
NEW_SENSOR = "(a new sensor)"
NO_JOINT = "(no moving joint)"


def at_input(note: Any, action: Callable[[], None]) -> Callable[[], None]:
    """``action``, whose refusal is also written in ``note`` (under the inputs it concerns)."""

    def run() -> None:
        try:
            action()
        except RobotSpecError as exc:
            near = f" (did you mean {', '.join(exc.suggestions)}?)" if exc.suggestions else ""
            note.content = f"<small>**refused:** {html.escape(exc.message)}{near}</small>"
            raise
        note.content = ""

    return run


def _options(handle: Any, options: tuple[str, ...]) -> None:
    if tuple(handle.options) != options:
        handle.options = options


class MoreTab(PageBase):
    """The frames & more tab of :class:`~robotspec.setup.page.SetupPage`."""

    def _build_more(self, gui: Any) -> None:
        with gui.add_folder("frames"):
            gui.add_markdown(
                "<small>Frames the URDF lacks (a tool frame), fixed to a link: "
                "`description.frames`. Turn one by roll-pitch-yaw (rad, fixed axes, as in URDF) "
                "or a quaternion [x, y, z, w].</small>"
            )
            self._frame_pick = gui.add_dropdown("frame", (NO_FRAME,))
            self._frame_pick.on_update(self._guarded(lambda _e: self._show_frame()))
            self._frame_info = gui.add_markdown("")
            self._rot_kind = gui.add_dropdown("rotation as", ROTATIONS)
            self._rot_values = gui.add_text("rotation values", "0, 0, 0")
            self._frame_xyz = gui.add_text("position xyz (m)", "0, 0, 0")
            self._frame_name = gui.add_text("new frame name", "")
            self._frame_note = gui.add_markdown("")
            note = self._frame_note
            self._button(gui, "set the rotation", at_input(note, self._rotate))
            self._button(gui, "set the position", at_input(note, self._move_frame))
            self._button(gui, "add a frame at the picked link", at_input(note, self._add_frame))
            self._button(gui, "remove this frame", at_input(note, self._remove_frame))
        with gui.add_folder("other sensors"):
            gui.add_markdown(
                "<small>Sensors that are not cameras (a lidar, an IMU, a force-torque sensor): "
                "`type: generic` on a link, with a free-form kind.</small>"
            )
            self._gs_pick = gui.add_dropdown("sensor", (NEW_SENSOR,))
            self._gs_pick.on_update(self._guarded(lambda _e: self._show_sensor()))
            self._gs_info = gui.add_markdown("")
            self._gs_name = gui.add_text("new sensor name", "")
            self._gs_kind = gui.add_text("sensor kind", "lidar")
            self._gs_carrier = gui.add_dropdown("sensor carried by", self.session.carriers())
            self._gs_carrier.on_update(self._guarded(lambda _e: self._carry_sensor()))
            self._gs_note = gui.add_markdown("")
            note = self._gs_note
            self._button(gui, "add a sensor at the picked link", at_input(note, self._add_sensor))
            self._button(gui, "sensor body = picked link", at_input(note, self._sensor_body))
            self._button(gui, "set the kind", at_input(note, self._sensor_kind))
            self._button(gui, "remove this sensor", at_input(note, self._remove_sensor))
        with gui.add_folder("passive joints"):
            gui.add_markdown(
                "<small>Joints that move but have no motor (a caster, a spring), as MoveIt's "
                "assistant sets them: the SRDF's `passive_joint`, kept until save.</small>"
            )
            self._pj_pick = gui.add_dropdown("joint", (NO_JOINT,))
            self._pj_note = gui.add_markdown("")
            self._button(
                gui, "make it passive", at_input(self._pj_note, lambda: self._passive(True))
            )
            self._button(
                gui, "make it actuated", at_input(self._pj_note, lambda: self._passive(False))
            )
            self._pj_list = gui.add_markdown("")

    # ------------------------------------------------------------------ shown after each change
    def _show_more(self) -> None:
        """The forms' lists as the spec now says (called with every new state)."""
        s = self.session
        _options(self._frame_pick, tuple(s.frames()) or (NO_FRAME,))
        _options(self._gs_pick, (NEW_SENSOR, *s.generic_sensors()))
        _options(self._gs_carrier, s.carriers())
        self._show_frame()
        self._show_sensor()
        self._show_passive()

    def _show_frame(self) -> None:
        f = self.session.frames().get(str(self._frame_pick.value))
        if f is None:
            self._frame_info.content = "<small>the spec has no extra frame yet</small>"
            return
        rot = (
            f"rpy {f['rpy']}"
            if "rpy" in f
            else f"quaternion {f['quaternion']}"
            if "quaternion" in f
            else "no rotation"
        )
        self._frame_info.content = html.escape(
            f"on {f.get('parent')}, at {f.get('xyz', [0, 0, 0])}, {rot}"
        )

    def _show_sensor(self) -> None:
        name = str(self._gs_pick.value)
        g = self.session.generic_sensors().get(name)
        if g is None:
            self._gs_info.content = "<small>name a new sensor, pick its link, add it</small>"
            return
        kind = g.get("kind") or "no kind given"
        carrier = self.session.sensor_carrier(f"sensors.{name}")
        self._gs_info.content = html.escape(f"on {g.get('body')}, {kind}, carried by {carrier}")
        self._gs_carrier.value = carrier

    def _show_passive(self) -> None:
        from robotspec.setup.passive import passive_rows

        rows = passive_rows(self.session)
        _options(self._pj_pick, tuple(r.joint for r in rows) or (NO_JOINT,))
        shown = [f"{html.escape(r.joint)}{' ✋' if r.by_hand else ''}" for r in rows if r.passive]
        self._pj_list.content = (
            "passive: " + ", ".join(shown) if shown else "<small>no joint is passive</small>"
        )

    # ------------------------------------------------------------------ actions
    def _frame(self) -> str:
        name = str(self._frame_pick.value)
        if name == NO_FRAME:
            raise RobotSpecError("the spec has no extra frame: add one at a picked link first")
        return name

    def _rotate(self) -> None:
        frame, kind = self._frame(), str(self._rot_kind.value)
        values = parse_numbers(str(self._rot_values.value)) if kind != "none" else []
        self._after(self.session.set_frame_rotation(frame, kind, values), f"{frame}: rotation set")

    def _move_frame(self) -> None:
        frame = self._frame()
        xyz = parse_numbers(str(self._frame_xyz.value))
        self._after(self.session.set_frame_position(frame, xyz), f"{frame}: moved")

    def _add_frame(self) -> None:
        name, link = str(self._frame_name.value), self._pick()
        xyz = parse_numbers(str(self._frame_xyz.value))
        v = self.session.add_frame(name, link, xyz)
        self._frame_pick.value = name.strip()
        self._show_frame()
        self._after(v, f"frame {html.escape(name.strip())} added on {html.escape(link)}")

    def _remove_frame(self) -> None:
        frame = self._frame()
        self._after(self.session.remove(f"frames.{frame}"), f"frame {frame} removed")

    def _sensor(self) -> str:
        name = str(self._gs_pick.value)
        if name == NEW_SENSOR:
            raise RobotSpecError("choose a sensor first (or add one at the picked link)")
        return name

    def _add_sensor(self) -> None:
        name, link = str(self._gs_name.value).strip(), self._pick()
        v = self.session.add_generic_sensor(name, link, str(self._gs_kind.value))
        self._gs_pick.value = name
        self._show_sensor()
        self._after(v, f"sensor {html.escape(name)} added on {html.escape(link)}")

    def _sensor_body(self) -> None:
        name, link = self._sensor(), self._pick()
        self._after(self.session.set_generic_sensor(name, body=link), f"{name} on {link}")

    def _sensor_kind(self) -> None:
        name, kind = self._sensor(), str(self._gs_kind.value)
        self._after(self.session.set_generic_sensor(name, kind=kind), f"{name}: kind set")

    def _remove_sensor(self) -> None:
        name = self._sensor()
        self._after(self.session.remove_generic_sensor(name), f"sensor {name} removed")

    def _carry_sensor(self) -> None:
        name = str(self._gs_pick.value)
        if name == NEW_SENSOR:
            return
        part, carrier = f"sensors.{name}", str(self._gs_carrier.value)
        if carrier != self.session.sensor_carrier(part):
            self._after(self.session.set_sensor_carrier(part, carrier), f"{name} on {carrier}")

    def _passive(self, passive: bool) -> None:
        from robotspec.setup.passive import set_passive

        joint = str(self._pj_pick.value)
        if joint == NO_JOINT:
            raise RobotSpecError("the robot has no moving joint to choose (or the spec has errors)")
        said = set_passive(self.session, joint, passive=passive)
        self._after(self.session.validation, html.escape(said))
