"""What a picture of a compiled robot shows, independent of how it is drawn.

Why a scene layer: the offscreen PNG and the live browser view must show the same semantics
(chain colours, tool frames, camera frustums, drive axes, legend), so both read them from one
:class:`RobotScene` and differ only in how they put triangles and segments on a screen.

Colouring: each chain of ``robot.all_chains`` gets a palette colour for its bodies below its root
(the root belongs to the parent part: the arms' root is the torso's link); a manipulator's bodies
(the subtree of its root) get a lighter tint of its arm's colour; every other body is grey.
Later chains win a body claimed twice, so arms override the torso they hang from.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from robotspec.arrays import F64
from robotspec.errors import RobotSpecError
from robotspec.model.entities import ConnectionType
from robotspec.model.kinematics import Kinematics
from robotspec.render.meshes import MissingMeshPolicy, TriangleLibrary, Triangles
from robotspec.semantic import AbstractRobot, Camera

__all__ = [
    "AXIS_COLOURS",
    "FRUSTUM_COLOUR",
    "GREY",
    "PALETTE",
    "DRIVE_COLOUR",
    "LegendEntry",
    "Part",
    "RobotScene",
    "Segment",
    "build_scene",
    "camera_basis",
    "colour_parts",
    "drive_segments",
    "frustum_corners",
]

RGB = tuple[int, int, int]

#: Chain colours, chosen apart in chromaticity so a shaded pixel still tells its chain, and away
#: from the overlay colours below (tab10 without red, green and grey).
PALETTE: tuple[RGB, ...] = (
    (31, 119, 180),  # blue
    (255, 127, 14),  # orange
    (148, 103, 189),  # purple
    (227, 119, 194),  # pink
    (23, 190, 207),  # cyan
    (188, 189, 34),  # olive
    (140, 86, 75),  # brown
)
GREY: RGB = (150, 150, 150)
AXIS_COLOURS: tuple[RGB, RGB, RGB] = ((230, 30, 30), (20, 180, 20), (30, 60, 240))
FRUSTUM_COLOUR: RGB = (215, 180, 0)
DRIVE_COLOUR: RGB = (20, 20, 20)
_TINT = 0.45


@dataclass(frozen=True)
class LegendEntry:
    """One line of the legend: a name, its colour, and what kind of thing it names."""

    name: str
    colour: RGB
    kind: str  # chain | manipulator | overlay | other


@dataclass(frozen=True)
class Part:
    """Triangles of one visual element in its body's frame, with the colour they are drawn in."""

    body: str
    body_index: int
    triangles: Triangles
    colour: RGB
    group: str | None


@dataclass(frozen=True)
class Segment:
    """A 3D line of an overlay (world frame), its colour and a width class (1 thin, 2 bold)."""

    start: tuple[float, float, float]
    end: tuple[float, float, float]
    colour: RGB
    width: int = 1


@dataclass(frozen=True)
class RobotScene:
    """A robot's drawable content: coloured parts, the legend, and overlays at a configuration."""

    robot: AbstractRobot = field(repr=False)
    parts: tuple[Part, ...]
    legend: tuple[LegendEntry, ...]
    body_colours: dict[str, RGB] = field(repr=False)
    group_of_body: dict[str, str] = field(repr=False)
    kinematics: Kinematics = field(repr=False, compare=False)
    size: float
    skipped: tuple[RobotSpecError, ...] = ()

    def poses(self, q: F64) -> F64:
        """World poses (B, 4, 4) of every body at ``q``."""
        return self.kinematics.forward(q)

    def overlays(self, q: F64, poses: F64 | None = None) -> tuple[Segment, ...]:
        """Tool frames, camera frustums and the drive's axes as world segments at ``q``."""
        poses = self.poses(q) if poses is None else poses
        out: list[Segment] = []
        size = self.size
        axis_len = 0.08 * size
        for m in self.robot.manipulators:
            out += _axes(poses[m.tool_frame.index], axis_len, width=2)
        for cam in self.robot.cameras:
            out += _frustum(poses[cam.root.index], cam, 0.35 * size)
        out += drive_segments(self.robot, poses[self.robot.root.index], 0.25 * size)
        return tuple(out)


def _robot_size(robot: AbstractRobot, kin: Kinematics, parts: Sequence[Part]) -> float:
    """The largest extent of the robot in its default pose (m): overlays are sized by it."""
    poses = kin.forward(default_q(robot))
    pts = [p.triangles.transformed(poses[p.body_index]).vertices for p in parts]
    if not pts:
        return 1.0
    allp = np.concatenate(pts)
    return float(np.max(allp.max(axis=0) - allp.min(axis=0))) or 1.0


def default_q(robot: AbstractRobot) -> F64:
    """The configuration the robot is shown in without a state (MoveIt's default pose)."""
    return robot.world.default_configuration()


def colour_parts(robot: AbstractRobot) -> tuple[dict[str, RGB], dict[str, str], list[LegendEntry]]:
    """Each body's colour and part (chains, then hands tinted), and the legend of both.

    Shared by the scene and the setup assistant, which recolours the robot as its parts change.
    """
    world = robot.world
    colours: dict[str, RGB] = {}
    groups: dict[str, str] = {}
    legend: list[LegendEntry] = []
    chains = robot.all_chains
    # Arms take the first (most distinct) colours: they are what a reader looks for first.
    ranked = sorted(chains, key=lambda c: c.manipulator is None)
    chain_colour = {c.name: PALETTE[i % len(PALETTE)] for i, c in enumerate(ranked)}
    for chain in chains:
        colour = chain_colour[chain.name]
        legend.append(LegendEntry(chain.name, colour, "chain"))
        for b in chain.bodies:
            if b.name != chain.root.name:
                colours[b.name] = colour
                groups[b.name] = chain.name
    for j, m in enumerate(robot.manipulators):
        owner = next((c for c in robot.all_chains if c.manipulator is m), None)
        base = chain_colour[owner.name] if owner is not None else PALETTE[-1 - j % len(PALETTE)]
        tint = _tint(base)
        legend.append(LegendEntry(m.name, tint, "manipulator"))
        for b in world.subtree(m.root):
            colours[b.name] = tint
            groups[b.name] = m.name
    legend.append(LegendEntry("other links", GREY, "other"))
    if robot.manipulators:
        legend.append(LegendEntry("tool frame x y z", AXIS_COLOURS[0], "overlay"))
    if robot.cameras:
        legend.append(LegendEntry("camera frustum", FRUSTUM_COLOUR, "overlay"))
    if robot.drive is not None:
        legend.append(
            LegendEntry(f"drive ({robot.drive.type.value}) axes", DRIVE_COLOUR, "overlay")
        )
    return colours, groups, legend


def build_scene(
    robot: AbstractRobot,
    *,
    library: TriangleLibrary | None = None,
    on_missing_mesh: MissingMeshPolicy = "error",
    collision: bool = False,
) -> RobotScene:
    """Colour every visual element of the robot (or its collision elements) by its part."""
    lib = library if library is not None else TriangleLibrary()
    world = robot.world
    colours, groups, legend = colour_parts(robot)
    parts: list[Part] = []
    skipped: list[RobotSpecError] = []
    for body in world.bodies:
        shapes = body.collisions if collision else body.visuals
        for shape in shapes:
            try:
                tris = lib.shape(shape, body)
            except RobotSpecError as exc:
                if on_missing_mesh == "error":
                    raise
                skipped.append(exc.with_severity("warning"))
                continue
            parts.append(
                Part(
                    body=body.name,
                    body_index=body.index,
                    triangles=tris,
                    colour=colours.get(body.name, GREY),
                    group=groups.get(body.name),
                )
            )
    kin = Kinematics(world)
    return RobotScene(
        robot=robot,
        parts=tuple(parts),
        legend=tuple(legend),
        body_colours=colours,
        group_of_body=groups,
        kinematics=kin,
        size=_robot_size(robot, kin, parts),
        skipped=tuple(skipped),
    )


def _tint(c: RGB) -> RGB:
    r, g, b = (round(v + (255 - v) * _TINT) for v in c)
    return (r, g, b)


def _pt(p: F64) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))


def _axes(pose: F64, length: float, width: int = 1) -> list[Segment]:
    o = pose[:3, 3]
    return [
        Segment(_pt(o), _pt(o + length * pose[:3, k]), AXIS_COLOURS[k], width) for k in range(3)
    ]


def camera_basis(forward: Sequence[float]) -> tuple[F64, F64, F64]:
    """Forward, right and down unit vectors of a camera body, from its forward axis.

    Why this convention: an optical frame looks along +z with x right and y down; a ROS body
    frame looks along +x with y left and z up. The horizontal axis is the body axis least
    aligned with ``forward`` in that order of preference.
    """
    f = np.asarray(forward, dtype=np.float64)
    f = f / np.linalg.norm(f)
    if abs(f[2]) >= max(abs(f[0]), abs(f[1])):
        right, down = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    elif abs(f[0]) >= abs(f[1]):
        right, down = np.array([0.0, -1.0, 0.0]), np.array([0.0, 0.0, -1.0])
    else:
        right, down = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, -1.0])
    right = right - f * float(right @ f)
    right /= np.linalg.norm(right)
    down = np.cross(f, right)
    return f, right, down


def frustum_corners(pose: F64, cam: Camera, depth: float) -> tuple[F64, F64]:
    """The apex (3,) and the four far corners (4, 3) of a camera's view pyramid (world)."""
    f, right, down = camera_basis(cam.forward_facing_axis)
    th = math.tan(cam.field_of_view.horizontal_angle / 2.0)
    tv = math.tan(cam.field_of_view.vertical_angle / 2.0)
    local = np.array(
        [f + sx * th * right + sy * tv * down for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    )
    local *= depth
    corners = local @ pose[:3, :3].T + pose[:3, 3]
    return pose[:3, 3].copy(), corners


def _frustum(pose: F64, cam: Camera, depth: float) -> list[Segment]:
    apex, corners = frustum_corners(pose, cam, depth)
    out = [Segment(_pt(apex), _pt(c), FRUSTUM_COLOUR) for c in corners]
    out += [Segment(_pt(corners[k]), _pt(corners[(k + 1) % 4]), FRUSTUM_COLOUR) for k in range(4)]
    # The image's top edge drawn bold, so the frustum shows which way is up.
    out.append(Segment(_pt(corners[0]), _pt(corners[1]), FRUSTUM_COLOUR, 2))
    return out


def drive_directions(robot: AbstractRobot) -> tuple[list[F64], list[F64]]:
    """Translation directions and rotation axes of the drive, in the root body's frame."""
    from robotspec.model.kinematics import _in_plane_axes

    drive = robot.drive
    if drive is None:
        return [], []
    axis = np.asarray(drive.axis, dtype=np.float64)
    # The joint frame is the child's frame at zero motion; its axes are the drive's axes.
    if drive.type is ConnectionType.PLANAR:
        u, w = _in_plane_axes(drive.axis)
        return [u, w], [axis]
    if drive.type is ConnectionType.FLOATING:
        eye = list(np.eye(3))
        return eye, eye
    if drive.type is ConnectionType.PRISMATIC:
        return [axis], []
    return [], [axis]


def drive_segments(robot: AbstractRobot, pose: F64, length: float) -> list[Segment]:
    """Arrows along the drive's translations and arcs about its rotation axes, at ``pose``."""
    rot, o = pose[:3, :3], pose[:3, 3]
    out: list[Segment] = []
    moves, turns = drive_directions(robot)
    for d in moves:
        tip = o + length * (rot @ d)
        out.append(Segment(_pt(o), _pt(tip), DRIVE_COLOUR, 2))
        out += _arrowhead(o, tip, rot @ _perp(d), 0.15 * length)
    for a in turns:
        from robotspec.model.kinematics import _in_plane_axes

        u, w = _in_plane_axes(tuple(float(v) for v in a))
        r = 0.6 * length
        angles = np.linspace(0.0, 1.5 * math.pi, 19)
        pts = [o + rot @ (r * (math.cos(t) * u + math.sin(t) * w)) for t in angles]
        out += [
            Segment(_pt(a0), _pt(a1), DRIVE_COLOUR, 2) for a0, a1 in zip(pts, pts[1:], strict=False)
        ]
        tangent = rot @ (-math.sin(angles[-1]) * u + math.cos(angles[-1]) * w)
        out += _arrowhead(pts[-1] - 0.01 * tangent, pts[-1], rot @ a, 0.15 * length)
    return out


def _perp(d: F64) -> F64:
    ref = np.array([0.0, 0.0, 1.0]) if abs(d[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    p: F64 = np.cross(d, ref)
    return p / float(np.linalg.norm(p))


def _arrowhead(start: F64, tip: F64, side: F64, size: float) -> list[Segment]:
    d = tip - start
    d = d / (np.linalg.norm(d) or 1.0)
    s = side / (np.linalg.norm(side) or 1.0)
    a = tip - size * d + 0.5 * size * s
    b = tip - size * d - 0.5 * size * s
    return [Segment(_pt(tip), _pt(a), DRIVE_COLOUR, 2), Segment(_pt(tip), _pt(b), DRIVE_COLOUR, 2)]
