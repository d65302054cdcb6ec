"""The page's parts tab: a part's root, tip, kind, hand, camera, drive; parts added, removed.

Each control calls one method of the session with the picked link; the tab only reads the
session's draft to show the chosen part.
"""

from __future__ import annotations

import html
from typing import Any

from robotspec.errors import RobotSpecError
from robotspec.setup.page_base import PageBase, problem_line
from robotspec.setup.questions import FACINGS, FORWARDS

__all__ = ["PartsTab"]

_NEW_KINDS = ("arm", "leg", "chain", "torso", "neck", "manipulator", "camera")
#: The axes a camera may look along in its body's frame (its ``forward_facing_axis``).
LOOKS = {
    "+z (optical)": (0.0, 0.0, 1.0),
    "+x (body)": (1.0, 0.0, 0.0),
    "-x": (-1.0, 0.0, 0.0),
    "+y": (0.0, 1.0, 0.0),
    "-y": (0.0, -1.0, 0.0),
    "-z": (0.0, 0.0, -1.0),
}
_NO_PRESET = "(angles below)"
#: Why a gripper with one jaw given is not written as one (yet, or ever: one moving jaw).
_HALF_GRIPPER = (
    "nothing written until its {lack} tip is picked too: a parallel_gripper has two moving "
    "jaws, each a chain with a joint (the compiler refuses an empty one). A gripper with one "
    "moving jaw against a fixed one (the SO-100's) stays type: generic (no fingers): its "
    "tool frame and states say what it does"
)


class PartsTab(PageBase):
    """The parts tab of :class:`~robotspec.setup.page.SetupPage`."""

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
            self._optical = gui.add_dropdown("looks along", tuple(LOOKS))
            self._optical.on_update(self._guarded(lambda _e: self._set_camera(optical=True)))
            # The chain (or neck) it moves with: answers validate's "is on no chain".
            self._carrier = gui.add_dropdown("carried by", s.carriers())
            self._carrier.on_update(self._guarded(lambda _e: self._set_carrier()))
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
            axis = (0.0, 0.0, 1.0) if cam.optical else cam.axis or (1.0, 0.0, 0.0)
            looks = next((k for k, v in LOOKS.items() if v == axis), str(list(axis)))
            lines.append(f"camera on **{cam.body}**, {what}, looking along {looks}")
            if looks in LOOKS:
                self._optical.value = looks
            self._preset.value = cam.preset or _NO_PRESET
            carriers, carrier = self.session.carriers(), self.session.sensor_carrier(part)
            if tuple(self._carrier.options) != carriers:
                self._carrier.options = carriers
            self._carrier.value = carrier
            lines.append(f"carried by {carrier}")
        elif kind == "drive" and d.drive is not None:
            facing = next((k for k, v in FORWARDS.items() if v == (d.forward or (1, 0, 0))), None)
            lines.append(f"base: **{d.drive.type}**; the robot {facing or d.forward}")
            self._drive.value = d.drive.type
            if facing is not None:
                self._forward.value = facing
        origin = self.session.part_origin(part)
        if origin is not None:
            lines.append(f"defined in `{html.escape(origin)}`: edit it there")
        lines += [problem_line(p) for p in self.session.validation.at(part)]
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
        m = next(m for m in self.session.draft().manipulators if m.name == name)
        if (m.thumb is None) != (m.finger is None) and not m.fingers:
            have, lack = ("thumb", "finger") if m.finger is None else ("finger", "thumb")
            self._after(v, f"{part}: {have} kept; {_HALF_GRIPPER.format(lack=lack)}")
            return
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
            looks = str(self._optical.value)
            v = self.session.set_camera_axis(part, LOOKS[looks])
            self._after(v, f"{part} looks along {looks}")
            return
        self._after(self.session.set_camera(part, **kw), f"{part} changed")

    def _set_carrier(self) -> None:
        part, carrier = self._part_name(), str(self._carrier.value)
        if carrier == self.session.sensor_carrier(part):
            return
        self._after(self.session.set_sensor_carrier(part, carrier), f"{part} on {carrier}")

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
