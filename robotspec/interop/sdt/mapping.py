"""A compiled robot read into SDT part recipes: the mapping between the two models, decided.

Why apart from :mod:`robotspec.interop.sdt.recipe` (the recipes as data): this is where every
choice about the mapping is made, without SDT: which part becomes which SDT kind, where each
part hangs, which joints get hardware interfaces, which states keep an SDT kind, what has no
place in SDT (``RobotRecipe.left_out``), and the description file's machine-independent name
the digest is made from.
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from robotspec.interop.sdt.base import base_body
from robotspec.interop.sdt.recipe import PartKind, PartRecipe, RobotRecipe, StateRecipe
from robotspec.semantic import Camera, Hand, KinematicChain, ParallelGripper

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot, JointState, Manipulator, Sensor

__all__ = ["STATE_KINDS", "portable_source", "robot_recipe"]

#: robotspec state name -> SDT's state kind (enum class in
#: ``semantic_digital_twin.datastructures.definitions``, member). SDT knows no other kinds.
STATE_KINDS: dict[str, tuple[str, str]] = {
    "park": ("StaticJointState", "PARK"),
    "open": ("GripperState", "OPEN"),
    "close": ("GripperState", "CLOSE"),
    "medium": ("GripperState", "MEDIUM"),
    "low": ("TorsoState", "LOW"),
    "mid": ("TorsoState", "MID"),
    "high": ("TorsoState", "HIGH"),
}


def _states(
    part: str, states: dict[str, JointState], left_out: list[str]
) -> tuple[StateRecipe, ...]:
    out = []
    for name, state in states.items():
        kind = STATE_KINDS.get(name.lower())
        if kind is None:
            left_out.append(
                f"state '{part}.{name}': SDT has no state kind for it "
                f"(it knows {', '.join(sorted(STATE_KINDS))})"
            )
            continue
        out.append(StateRecipe(name=name, kind=kind, joints=state.joints))
    return tuple(out)


def _camera(sensor: Sensor, default: bool) -> PartRecipe:
    if isinstance(sensor, Camera):
        fov = sensor.field_of_view
        return PartRecipe(
            kind="camera",
            name=sensor.name,
            root=sensor.root.name,
            forward_facing_axis=sensor.forward_facing_axis,
            field_of_view=(fov.vertical_angle, fov.horizontal_angle),
            minimal_height=sensor.minimal_height,
            maximal_height=sensor.maximal_height,
            default_camera=default,
        )
    return PartRecipe(kind="sensor", name=sensor.name, root=sensor.root.name)


def _end_effector(m: Manipulator, left_out: list[str]) -> PartRecipe:
    children: tuple[tuple[str, tuple[PartRecipe, ...]], ...] = ()
    if isinstance(m, (ParallelGripper, Hand)):
        # SDT: the first generic parameter is the thumb (HasTwoFingers, HasFingers).
        chains = (m.thumb, m.finger) if isinstance(m, ParallelGripper) else m.all_fingers
        fingers = tuple(
            PartRecipe(kind="finger", name=f.name, root=f.root.name, tip=f.tip.name) for f in chains
        )
        children = (("fingers", fingers),)
    return PartRecipe(
        kind="end_effector",
        name=m.name,
        root=m.root.name,
        tool_frame=m.tool_frame.name,
        front_facing_orientation=m.front_facing_orientation,
        front_facing_axis=m.front_facing_axis,
        states=_states(m.name, m.states, left_out),
        children=children,
    )


def _safe(name: str) -> str:
    return re.sub(r"\W", "_", name)


def portable_source(path: str | None) -> str:
    """The description file as a machine-independent name: ``package://pkg/rel`` or its name.

    Why: the recipe's digest names the generated classes, and those names travel (pickles,
    world histories); an absolute path would make them depend on where the files are installed.
    The nearest enclosing ROS package (a folder with ``package.xml``) gives a ``package://``
    URI, as a spec writes it; a file in no package is named by its description folder (the one
    above ``urdf/``) and its own name, else its name alone.
    """
    if not path:
        return ""
    from robotspec.files.package_search import declared_name, description_root

    file = Path(path)
    for folder in file.parents:
        if (folder / "package.xml").is_file():
            return f"package://{declared_name(folder)}/{file.relative_to(folder).as_posix()}"
    for root in description_root(file):
        return f"{root.name}/{file.relative_to(root).as_posix()}"
    return file.name


def robot_recipe(robot: AbstractRobot) -> RobotRecipe:
    """The SDT parts of a compiled robot (see the module docstring and docs/sdt.md).

    The mapping: the torso, neck and arms become SDT's ``Torso``, ``Neck`` and ``Arm``; a
    manipulator its arm's ``EndEffector`` (a parallel gripper ``HasTwoFingers[thumb,
    finger]``, a hand ``HasFingers[thumb, *fingers]``, or ``HasTwoFingers`` for a thumb and
    one finger); cameras ``Camera`` (other sensors ``Sensor``) on the neck or arm that carries
    them, else on the robot; a robot whose base moves gets a ``MobileBase`` rooted at its base
    body (:func:`.base.base_body`) holding the torso. Arms hang below the
    torso when there is one (one arm ``HasOneArm``, two ``HasLeftRightArm`` in robotspec's
    left/right order, more ``HasArms``). Hardware interfaces go on the controlled joints that
    move a chain (a spec's ``controlled_joints`` when it names them); states keep their SDT
    kind (park, open/close/medium, low/mid/high).
    """
    left_out: list[str] = []
    default_cam = robot.default_camera
    cam = {s.name: _camera(s, s is default_cam) for s in robot.sensors}
    chains = _Chains(robot, cam, left_out)
    torso = None if robot.torso is None else chains.part("torso", robot.torso)
    neck = None if robot.neck is None else chains.part("neck", robot.neck)
    arms: list[KinematicChain] = list(robot.arms)
    if len(arms) == 2:
        arms = [robot.left_arm, robot.right_arm]  # robotspec's sides: declared, else by position
    arm_parts = tuple(chains.part("arm", a) for a in arms)
    extra = _extra_hardware(robot, chains, arms)
    pairs = sorted(tuple(sorted(p)) for p in robot.disabled_collision_pairs)
    cfg = robot.default_collision_config
    return RobotRecipe(
        name=_safe(robot.name),
        root=robot.root.name,
        source=portable_source(robot.world.source),
        children=_top(robot, torso, neck, arm_parts, cam),
        disabled_pairs=tuple((a, b) for a, b in pairs),
        disabled_bodies=tuple(sorted(robot.disabled_collision_bodies)),
        buffer_zone_distance=cfg.buffer_zone_distance,
        violated_distance=cfg.violated_distance,
        collisions_disabled=cfg.disabled,
        extra_hardware_joints=extra,
        left_out=tuple(left_out),
    )


Slots = list[tuple[str, tuple[PartRecipe, ...]]]


class _Chains:
    """A robot's chains as part recipes; each controlled joint goes to the first chain it moves."""

    def __init__(
        self, robot: AbstractRobot, cam: dict[str, PartRecipe], left_out: list[str]
    ) -> None:
        self.robot, self.cam, self.left_out = robot, cam, left_out
        self.controlled = [c.name for c in robot.controlled_connections]
        self.claimed: set[str] = set()

    def hardware(self, chain: KinematicChain) -> tuple[str, ...]:
        """The controlled joints ``chain`` moves that no chain read before it claimed."""
        dofs = {d.index for d in chain.degrees_of_freedom}
        mine = []
        for name in self.controlled:
            c = self.robot.world.get_connection_by_name(name)
            if name not in self.claimed and dofs.intersection(c.dofs):
                self.claimed.add(name)
                mine.append(name)
        return tuple(mine)

    def part(self, kind: PartKind, chain: KinematicChain) -> PartRecipe:
        """``chain`` as a part of ``kind``, with its end effector and the cameras it carries."""
        slots: Slots = []
        if chain.manipulator is not None:
            slots.append(("end_effector", (_end_effector(chain.manipulator, self.left_out),)))
        if chain.sensors:
            slots.append(("sensors", tuple(self.cam.pop(s.name) for s in chain.sensors)))
        return PartRecipe(
            kind=kind,
            name=chain.name,
            root=chain.root.name,
            tip=chain.tip.name,
            hardware_joints=self.hardware(chain),
            states=_states(chain.name, chain.states, self.left_out),
            children=tuple(slots),
        )


def _extra_hardware(
    robot: AbstractRobot, chains: _Chains, arms: list[KinematicChain]
) -> tuple[str, ...]:
    """Controlled joints of no torso, neck or arm (kept on the robot); what SDT cannot hold noted.

    A chain that is neither keeps its joints' hardware interfaces; with the spec's
    ``controlled_joints``, every joint it names has one, wherever it is.
    """
    extra: list[str] = []
    for chain in robot.kinematic_chains:
        if chain is robot.neck or chain in robot.arms:
            continue
        extra.extend(chains.hardware(chain))
        chains.left_out.append(
            f"chain '{chain.name}': neither torso, neck nor arm; SDT has no kind for it"
        )
    for m in robot.manipulators:
        if not any(a.manipulator is m for a in arms):
            chains.left_out.append(
                f"manipulator '{m.name}': on no arm; SDT hangs end effectors on arms"
            )
    if robot.controlled_joint_names is not None:
        extra.extend(n for n in chains.controlled if n not in chains.claimed)
    return tuple(extra)


def _top(
    robot: AbstractRobot,
    torso: PartRecipe | None,
    neck: PartRecipe | None,
    arms: tuple[PartRecipe, ...],
    cam: dict[str, PartRecipe],
) -> tuple[tuple[str, tuple[PartRecipe, ...]], ...]:
    """The robot's own slots, as SDT's hand-written robots hang them.

    Arms and neck below the torso (on the robot without one); the torso on the mobile base
    when the base moves; cameras no chain carries on the robot.
    """
    upper: Slots = []
    if arms:
        upper.append(("arms", arms))
    if neck is not None:
        upper.append(("neck", (neck,)))
    body: Slots = upper
    if torso is not None:
        body = [("torso", (replace(torso, children=(*torso.children, *upper)),))]
    top: Slots = []
    if robot.drive is not None:
        base = PartRecipe(
            kind="mobile_base",
            name="mobile_base",
            root=base_body(robot.world, robot.root.name),
            children=tuple(s for s in body if s[0] == "torso"),
        )
        top.append(("mobile_base", (base,)))
        top.extend(s for s in body if s[0] != "torso")
    else:
        top.extend(body)
    if cam:
        top.append(("sensors", tuple(cam.values())))
    return tuple(top)
