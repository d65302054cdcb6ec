"""``robotspec view``: the compiled robot live in a browser (viser), with its semantics drawn.

Why viser: it serves a three.js client from a pip wheel (no node, no display on the server), so
a robot on a headless machine can be looked at from any browser; yourdfpy already supports it.
The scene is the same :class:`~robotspec.render.scene.RobotScene` the PNG is drawn from, so the
colours and overlays agree. Every body is one scene node posed in the world frame; a slider
change recomputes forward kinematics once and moves the nodes.

viser is imported through ``importlib`` and used as ``Any``: its API is large and changes between
releases, and the package's strict typing must not depend on its stubs.
"""

from __future__ import annotations

import contextlib
import io
import math
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.errors import RobotSpecError, ServiceError
from robotspec.extras import VISER, require
from robotspec.model.world import ConnectionType
from robotspec.render.meshes import MissingMeshPolicy, TriangleLibrary
from robotspec.render.scene import (
    FRUSTUM_COLOUR,
    RobotScene,
    build_scene,
    camera_basis,
    drive_segments,
)
from robotspec.semantic import AbstractRobot

__all__ = ["RobotViewer", "slider_range"]


_COLLISION_COLOUR = (90, 200, 90)
_COLLIDING_COLOUR = (230, 20, 20)


def slider_range(robot: AbstractRobot, dof: int) -> tuple[float, float]:
    """The range a joint's slider spans: its limits, else one turn or two metres each way."""
    d = robot.world.degrees_of_freedom[dof]
    if d.is_bounded:
        return float(d.lower), float(d.upper)
    conn = robot.world.get_connection_by_name(d.connection)
    turn = conn.type in (ConnectionType.REVOLUTE, ConnectionType.CONTINUOUS) or d.name.endswith(
        ("/theta", "/roll", "/pitch", "/yaw")
    )
    half = math.pi if turn else 2.0
    return max(float(d.lower), -half), min(float(d.upper), half)


def _wxyz(rot: F64) -> tuple[float, float, float, float]:
    """A unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method)."""
    m = rot
    t = float(np.trace(m))
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = ((m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s)
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = ((m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s)
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = ((m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s)
    w, x, y, z = (float(v) for v in q)
    return (w, x, y, z)


class RobotViewer:
    """A viser server showing one robot; sliders, a state menu and collision toggles.

    Starts serving on construction; :meth:`stop` ends it. ``port=0`` picks a free port, and a
    taken port moves to the next free one (``url`` tells which). ``controls=False`` serves the
    robot without the viewer's panel (the setup assistant brings its own).
    """

    def __init__(
        self,
        robot: AbstractRobot,
        q: F64,
        *,
        host: str = "127.0.0.1",
        port: int = 8080,
        on_missing_mesh: MissingMeshPolicy = "error",
        controls: bool = True,
    ) -> None:
        self.robot = robot
        self._controls = controls
        library = TriangleLibrary()
        self.scene: RobotScene = build_scene(
            robot, library=library, on_missing_mesh=on_missing_mesh
        )
        self.collision_scene: RobotScene = build_scene(
            robot, library=library, on_missing_mesh="skip", collision=True
        )
        self.skipped: tuple[RobotSpecError, ...] = self.scene.skipped
        self.q = np.array(q, dtype=np.float64)
        self._lock = threading.Lock()
        self._checker: Any = None
        self._checker_error: str | None = None
        viser: Any = require(VISER, "robotspec view")
        try:
            # viser prints a banner of its own; the command prints the one URL that matters.
            with contextlib.redirect_stdout(io.StringIO()):
                self.server: Any = viser.ViserServer(host=host, port=port, verbose=False)
        except OSError as exc:
            raise ServiceError(
                f"cannot serve the view on {host}:{port}: {exc.strerror or exc}",
                kind="service",
                name=f"{host}:{port}",
            ) from None
        self.host = host
        self.port = int(self.server.get_port())
        self._nodes: dict[int, Any] = {}
        self._overlays: list[Any] = []
        self._collision_meshes: dict[str, list[Any]] = {}
        #: Each body's visual mesh handles (the setup assistant recolours and clicks them).
        self.visual_meshes: dict[str, list[Any]] = {}
        self._sliders: dict[int, Any] = {}
        self._show_pairs: Any = None
        self._build()
        self.update(self.q)

    @property
    def url(self) -> str:
        """Where to point a browser."""
        shown = "localhost" if self.host in ("0.0.0.0", "::", "127.0.0.1") else self.host
        return f"http://{shown}:{self.port}"

    # ------------------------------------------------------------------------ building
    def _node(self, body_index: int) -> Any:
        node = self._nodes.get(body_index)
        if node is None:
            name = self.robot.world.bodies[body_index].name
            node = self.server.scene.add_frame(f"/robot/{name}", show_axes=False)
            self._nodes[body_index] = node
        return node

    def _build(self) -> None:
        s = self.server.scene
        size = self.scene.size
        s.set_up_direction("+z")
        # Start from the front-right, above, like the picture's iso view, the robot filling it.
        centre = np.array([0.0, 0.0, 0.45 * size])
        cam = self.server.initial_camera
        cam.look_at = tuple(float(v) for v in centre)
        cam.position = tuple(float(v) for v in centre + np.array([1.2, -1.2, 0.7]) * size)
        s.add_grid("/ground", width=2 * size, height=2 * size, cell_size=0.1 * size)
        world = self.robot.world
        for k, part in enumerate(self.scene.parts):
            self._node(part.body_index)
            t = part.triangles
            handle = s.add_mesh_simple(
                f"/robot/{part.body}/visual_{k}",
                t.vertices,
                t.faces,
                color=part.colour,
                flat_shading=True,
                side="double",
            )
            self.visual_meshes.setdefault(part.body, []).append(handle)
        for k, part in enumerate(self.collision_scene.parts):
            self._node(part.body_index)
            t = part.triangles
            handle = s.add_mesh_simple(
                f"/robot/{part.body}/collision_{k}",
                t.vertices,
                t.faces,
                color=_COLLISION_COLOUR,
                opacity=0.5,
                side="double",
                visible=False,
            )
            self._collision_meshes.setdefault(part.body, []).append(handle)
        self.draw_overlays(self.robot)
        if self._controls:
            self._build_gui(world)

    def draw_overlays(self, robot: AbstractRobot) -> None:
        """Tool frames, camera frustums and the drive's arrows of ``robot``, replacing any drawn.

        ``robot`` may be another compilation of the same robot (the setup assistant's after each
        change): its parts are placed by body name on this view's nodes, so an edited tool frame
        or camera moves where it now is; a body this view's world lacks is skipped.
        """
        s = self.server.scene
        size = self.scene.size
        for handle in self._overlays:
            handle.remove()
        self._overlays = []
        world = self.robot.world

        def node(name: str) -> bool:
            if not world.has_body(name):
                return False
            self._node(world.get_body_by_name(name).index)
            return True

        for m in robot.manipulators:
            if node(m.tool_frame.name):
                self._overlays.append(
                    s.add_frame(
                        f"/robot/{m.tool_frame.name}/tool_frame",
                        axes_length=0.08 * size,
                        axes_radius=0.004 * size,
                    )
                )
        for cam in robot.cameras:
            if not node(cam.root.name):
                continue
            f, right, down = camera_basis(cam.forward_facing_axis)
            # viser's frustum looks along +z with x right and y down (OpenCV), like an optical
            # frame; rotate it onto the camera's own axes.
            rot = np.stack([right, down, f], axis=1)
            fov = cam.field_of_view
            aspect = math.tan(fov.horizontal_angle / 2) / math.tan(fov.vertical_angle / 2)
            self._overlays.append(
                s.add_camera_frustum(
                    f"/robot/{cam.root.name}/frustum_{cam.name}",
                    fov=fov.vertical_angle,
                    aspect=aspect,
                    scale=0.15 * size,
                    color=FRUSTUM_COLOUR,
                    wxyz=_wxyz(rot),
                )
            )
        if robot.drive is not None and node(robot.root.name):
            segs = drive_segments(robot, np.eye(4), 0.25 * size)
            pts = np.array([[seg.start, seg.end] for seg in segs], dtype=np.float64)
            self._overlays.append(
                s.add_line_segments(
                    f"/robot/{robot.root.name}/drive",
                    pts,
                    colors=(20, 20, 20),
                    thickness=4.0,
                    thickness_units="screen",
                )
            )
        self.update(self.q)

    def _build_gui(self, world: Any) -> None:
        gui = self.server.gui
        rows = [
            f'<span style="display:inline-block;width:0.9em;height:0.9em;'
            f'background:rgb{e.colour};border:1px solid #444;margin-right:0.4em"></span>{e.name}'
            for e in self.scene.legend
        ]
        gui.add_html(
            f"<div style='font-size:0.85em;line-height:1.5'><b>{self.robot.name}</b><br>"
            + "<br>".join(rows)
            + "</div>"
        )
        names = ["(default pose)", *self.robot.joint_states]
        dropdown = gui.add_dropdown("joint state", tuple(names), initial_value=names[0])
        dropdown.on_update(lambda _: self._apply_state(str(dropdown.value)))
        show_col = gui.add_checkbox("collision geometry", initial_value=False)
        show_pairs = gui.add_checkbox("colliding pairs", initial_value=False)
        self._pairs_text = gui.add_markdown("")
        show_col.on_update(lambda _: self._show_collision(bool(show_col.value)))
        show_pairs.on_update(lambda _: self._toggle_pairs(bool(show_pairs.value)))
        self._show_pairs = show_pairs
        self._show_col = show_col
        seen: set[int] = set()
        groups: list[tuple[str, list[int]]] = []
        for chain in self.robot.all_chains:
            dofs = [d.index for d in chain.degrees_of_freedom if d.index not in seen]
            seen.update(dofs)
            groups.append((chain.name, dofs))
        for m in self.robot.manipulators:
            dofs = sorted(
                {
                    d
                    for b in world.subtree(m.root)
                    for c in [world.parent_connection(b)]
                    if c is not None and c.is_active
                    for d in c.dofs
                }
                - seen
            )
            seen.update(dofs)
            groups.append((m.name, dofs))
        rest = [d.index for d in world.degrees_of_freedom if d.index not in seen]
        groups.append(("other joints", rest))
        for title, dofs in groups:
            if not dofs:
                continue
            with gui.add_folder(title, expand_by_default=title != "other joints"):
                for d in dofs:
                    self._slider(gui, d)

    def _slider(self, gui: Any, dof: int) -> None:
        lo, hi = slider_range(self.robot, dof)
        name = self.robot.world.degrees_of_freedom[dof].name
        value = float(np.clip(self.q[dof], lo, hi))
        step = max((hi - lo) / 500.0, 1e-4)
        slider = gui.add_slider(name, min=lo, max=hi, step=step, initial_value=value)
        self._sliders[dof] = slider

        def moved(_: Any) -> None:
            with self._lock:
                self.q[dof] = float(slider.value)
                q = self.q.copy()
            self.update(q)

        slider.on_update(moved)

    # ------------------------------------------------------------------------ updates
    def update(self, q: F64) -> None:
        """Move every body node to its pose at ``q`` (and refresh colliding pairs if shown)."""
        poses = self.scene.poses(q)
        with self.server.atomic():
            for idx, node in self._nodes.items():
                pose = poses[idx]
                node.position = tuple(float(v) for v in pose[:3, 3])
                node.wxyz = _wxyz(pose[:3, :3])
        if self._show_pairs is not None and self._show_pairs.value:
            self._refresh_pairs(q)

    def _apply_state(self, name: str) -> None:
        from robotspec.semantic.states import state_configuration

        states = () if name.startswith("(") else (name,)
        q = state_configuration(self.robot, states)
        with self._lock:
            self.q = q
        for dof, slider in self._sliders.items():
            lo, hi = slider_range(self.robot, dof)
            # Setting a slider fires its callback; each call sets one joint, all converge.
            slider.value = float(np.clip(q[dof], lo, hi))
        self.update(q)

    def _show_collision(self, on: bool) -> None:
        for handles in self._collision_meshes.values():
            for h in handles:
                h.visible = on

    def _toggle_pairs(self, on: bool) -> None:
        if on:
            self._refresh_pairs(self.q.copy())
        else:
            self._pairs_text.content = ""
            self._colour_colliding(set())

    def _refresh_pairs(self, q: F64) -> None:
        checker = self._collision_checker()
        if checker is None:
            self._pairs_text.content = f"collision checking unavailable: {self._checker_error}"
            return
        pairs = checker.colliding_pairs(q)
        bodies = {b for p in pairs for b in p}
        self._colour_colliding(bodies)
        if pairs:
            lines = "\n".join(f"- {a} / {b}" for a, b in pairs)
            self._pairs_text.content = f"**in collision: {len(pairs)} pairs**\n\n{lines}"
        else:
            self._pairs_text.content = "collision-free"

    def _collision_checker(self) -> Any:
        if self._checker is None and self._checker_error is None:
            from robotspec.collision import SelfCollisionChecker

            try:
                checker = SelfCollisionChecker.from_robot(self.robot, on_missing_mesh="skip")
                checker.geometry  # noqa: B018 - build now, so errors show here
                self._checker = checker
            except RobotSpecError as exc:
                self._checker_error = exc.message
        return self._checker

    def _colour_colliding(self, bodies: set[str]) -> None:
        for body, handles in self._collision_meshes.items():
            colour = _COLLIDING_COLOUR if body in bodies else _COLLISION_COLOUR
            for h in handles:
                h.color = colour
                h.visible = bool(self._show_col.value) or body in bodies

    # ------------------------------------------------------------------------ lifetime
    def wait(self, until: Callable[[], bool] | None = None) -> None:
        """Block until ``until()`` is true (forever by default; Ctrl-C raises)."""
        while until is None or not until():
            time.sleep(0.2)

    def stop(self) -> None:
        """Stop serving."""
        self.server.stop()
