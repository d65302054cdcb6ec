"""The page's states tab: a slider per joint of a part, named states saved, shown, removed."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from robotspec.errors import RobotSpecError
from robotspec.setup.page_base import PageBase

__all__ = ["StatesTab"]


class StatesTab(PageBase):
    """The states tab of :class:`~robotspec.setup.page.SetupPage`."""

    _sliders: dict[str, Any]

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
                    sl.on_update(self._guarded(self._slider_moved(j)))
                    self._sliders[j] = sl
            self._state_info.content = (
                f"{len(joints)} joints of {part}" if joints else f"{part} moves no joint"
            )
            self._show_saved_states()
        self._preview()

    def _slider_moved(self, joint: str) -> Callable[[Any], None]:
        def moved(_event: Any) -> None:
            self._slid(joint)

        return moved

    def _slid(self, joint: str) -> None:
        """A slider moved or its box typed in: a value past the joint's limits is refused."""
        slider = self._sliders.get(joint)
        if slider is None:
            return
        lo, hi = self.session.joint_range(joint)
        typed = float(slider.value)
        if not np.isfinite(typed) or not lo <= typed <= hi:
            slider.value = float(np.clip(np.nan_to_num(typed, nan=lo), lo, hi))
            self._preview()
            raise RobotSpecError(
                f"{joint}: {typed:g} is outside its limits [{lo:g}, {hi:g}] (the URDF's); "
                f"set to {float(slider.value):g}",
                kind="joint",
                name=joint,
            )
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
