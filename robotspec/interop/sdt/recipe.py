"""A compiled robot as SDT part recipes: plain data, no SDT import.

Why a recipe between the two models: SDT wires a robot by *classes* (one class per part, the
tree given by generic type parameters: ``Arm[Gripper]``, ``HasLeftRightArm[L, R]``), and its
world copy, pickles and ORM find those classes again by import path. A recipe is the
hashable, JSON-able description a class is generated from: the same robot gives equal
recipes, equal recipes give the same class (:mod:`robotspec.interop.sdt.classes`), and a
fresh process can rebuild a class from its stored recipe. Everything decided about the
mapping (which part becomes which SDT kind, which joints get hardware interfaces, which
states have an SDT kind) is decided here, testably, without SDT installed.
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from robotspec.interop.sdt.base import base_body
from robotspec.semantic import Camera, Hand, KinematicChain, ParallelGripper

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot, JointState, Manipulator, Sensor

__all__ = [
    "STATE_KINDS",
    "PartKind",
    "PartRecipe",
    "RobotRecipe",
    "StateRecipe",
    "portable_source",
    "robot_recipe",
]

PartKind = Literal[
    "mobile_base", "torso", "neck", "arm", "end_effector", "finger", "camera", "sensor"
]

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


@dataclass(frozen=True)
class StateRecipe:
    """A named joint state of a part with its SDT kind; joints in the spec's order."""

    name: str
    kind: tuple[str, str]
    joints: tuple[tuple[str, float], ...]


@dataclass(frozen=True)
class PartRecipe:
    """One SDT part: its kind, bodies, values, and the parts SDT hangs below it.

    ``children`` are SDT's slots, in the order the generic parameters take them: ``torso``,
    ``neck``, ``arms`` (left then right for two arms), ``end_effector``, ``fingers`` (thumb
    first), ``sensors``.
    """

    kind: PartKind
    name: str
    root: str
    tip: str | None = None
    tool_frame: str | None = None
    front_facing_orientation: tuple[float, float, float, float] | None = None
    front_facing_axis: tuple[float, float, float] | None = None
    forward_facing_axis: tuple[float, float, float] | None = None
    field_of_view: tuple[float, float] | None = None  # (vertical, horizontal), rad
    minimal_height: float | None = None
    maximal_height: float | None = None
    default_camera: bool = False
    hardware_joints: tuple[str, ...] = ()
    states: tuple[StateRecipe, ...] = ()
    children: tuple[tuple[str, tuple[PartRecipe, ...]], ...] = ()

    def slot(self, name: str) -> tuple[PartRecipe, ...]:
        """The parts in one of SDT's slots (empty when absent)."""
        return dict(self.children).get(name, ())

    def walk(self) -> list[PartRecipe]:
        """This part and every part below it, depth first."""
        out = [self]
        for _, parts in self.children:
            for p in parts:
                out.extend(p.walk())
        return out


@dataclass(frozen=True)
class RobotRecipe:
    """The robot: its root, its parts, and what the robot itself holds in SDT.

    ``extra_hardware_joints`` are controlled joints that move no part SDT has a kind for
    (set on the world after SDT's ``from_world``). ``left_out`` says, one line each, what of
    the robotspec robot has no place in SDT.
    """

    name: str
    root: str
    source: str
    children: tuple[tuple[str, tuple[PartRecipe, ...]], ...]
    disabled_pairs: tuple[tuple[str, str], ...]
    disabled_bodies: tuple[str, ...]
    buffer_zone_distance: float
    violated_distance: float
    collisions_disabled: bool
    extra_hardware_joints: tuple[str, ...] = ()
    left_out: tuple[str, ...] = field(default=(), compare=False)

    def slot(self, name: str) -> tuple[PartRecipe, ...]:
        """The parts in one of SDT's slots of the robot (empty when absent)."""
        return dict(self.children).get(name, ())

    def parts(self) -> list[PartRecipe]:
        """Every part, depth first."""
        return [q for _, ps in self.children for p in ps for q in p.walk()]

    def digest(self) -> str:
        """A short hash of the recipe's content: the suffix of its generated class names.

        A function of the robot, not of the machine: the recipe holds body, joint and part
        names, values and a portable ``source`` (:func:`portable_source`), no machine path, so
        the same spec gives the same digest wherever its files are installed.
        """
        data = asdict(self)
        data.pop("left_out")
        text = json.dumps(data, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:10]

    def to_json(self) -> dict[str, Any]:
        """The recipe as JSON data (what a fresh process rebuilds its classes from)."""
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RobotRecipe:
        """The inverse of :meth:`to_json`."""
        return cls(
            name=data["name"],
            root=data["root"],
            source=data["source"],
            children=_children_from_json(data["children"]),
            disabled_pairs=tuple((a, b) for a, b in data["disabled_pairs"]),
            disabled_bodies=tuple(data["disabled_bodies"]),
            buffer_zone_distance=float(data["buffer_zone_distance"]),
            violated_distance=float(data["violated_distance"]),
            collisions_disabled=bool(data["collisions_disabled"]),
            extra_hardware_joints=tuple(data["extra_hardware_joints"]),
            left_out=tuple(data["left_out"]),
        )


def _tuple_or_none(v: Any) -> Any:
    return None if v is None else tuple(v)


def _part_from_json(d: dict[str, Any]) -> PartRecipe:
    return PartRecipe(
        kind=d["kind"],
        name=d["name"],
        root=d["root"],
        tip=d["tip"],
        tool_frame=d["tool_frame"],
        front_facing_orientation=_tuple_or_none(d["front_facing_orientation"]),
        front_facing_axis=_tuple_or_none(d["front_facing_axis"]),
        forward_facing_axis=_tuple_or_none(d["forward_facing_axis"]),
        field_of_view=_tuple_or_none(d["field_of_view"]),
        minimal_height=d["minimal_height"],
        maximal_height=d["maximal_height"],
        default_camera=bool(d["default_camera"]),
        hardware_joints=tuple(d["hardware_joints"]),
        states=tuple(
            StateRecipe(
                name=s["name"],
                kind=(s["kind"][0], s["kind"][1]),
                joints=tuple((j, float(v)) for j, v in s["joints"]),
            )
            for s in d["states"]
        ),
        children=_children_from_json(d["children"]),
    )


def _children_from_json(data: Any) -> tuple[tuple[str, tuple[PartRecipe, ...]], ...]:
    return tuple((slot, tuple(_part_from_json(p) for p in parts)) for slot, parts in data)


# --------------------------------------------------------------------------- from a robot
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
    controlled = [c.name for c in robot.controlled_connections]
    explicit = robot.controlled_joint_names is not None
    claimed: set[str] = set()

    def hardware(chain: KinematicChain) -> tuple[str, ...]:
        dofs = {d.index for d in chain.degrees_of_freedom}
        mine = []
        for name in controlled:
            c = robot.world.get_connection_by_name(name)
            if name not in claimed and dofs.intersection(c.dofs):
                claimed.add(name)
                mine.append(name)
        return tuple(mine)

    def chain_part(kind: PartKind, chain: KinematicChain) -> PartRecipe:
        slots: list[tuple[str, tuple[PartRecipe, ...]]] = []
        if chain.manipulator is not None:
            slots.append(("end_effector", (_end_effector(chain.manipulator, left_out),)))
        if chain.sensors:
            slots.append(("sensors", tuple(cam.pop(s.name) for s in chain.sensors)))
        return PartRecipe(
            kind=kind,
            name=chain.name,
            root=chain.root.name,
            tip=chain.tip.name,
            hardware_joints=hardware(chain),
            states=_states(chain.name, chain.states, left_out),
            children=tuple(slots),
        )

    torso = None if robot.torso is None else chain_part("torso", robot.torso)
    neck = None if robot.neck is None else chain_part("neck", robot.neck)
    arms: list[KinematicChain] = list(robot.arms)
    if len(arms) == 2:
        arms = [robot.left_arm, robot.right_arm]  # robotspec's sides: declared, else by position
    arm_parts = tuple(chain_part("arm", a) for a in arms)
    extra: list[str] = []
    for chain in robot.kinematic_chains:
        if chain is robot.neck or chain in robot.arms:
            continue
        extra.extend(hardware(chain))  # its joints keep their hardware interfaces (on the robot)
        left_out.append(
            f"chain '{chain.name}': neither torso, neck nor arm; SDT has no kind for it"
        )
    for m in robot.manipulators:
        if not any(a.manipulator is m for a in arms):
            left_out.append(f"manipulator '{m.name}': on no arm; SDT hangs end effectors on arms")
    if explicit:  # every joint the spec names, wherever it is
        extra.extend(n for n in controlled if n not in claimed)
    # Torso and arms below it, as SDT's hand-written robots do; without a torso, on the robot.
    upper: list[tuple[str, tuple[PartRecipe, ...]]] = []
    if arm_parts:
        upper.append(("arms", arm_parts))
    if neck is not None:
        upper.append(("neck", (neck,)))
    top: list[tuple[str, tuple[PartRecipe, ...]]] = []
    if torso is not None:
        torso = replace(torso, children=(*torso.children, *upper))
        body_slots: list[tuple[str, tuple[PartRecipe, ...]]] = [("torso", (torso,))]
    else:
        body_slots = upper
    if robot.drive is not None:
        base = PartRecipe(
            kind="mobile_base",
            name="mobile_base",
            root=base_body(robot.world, robot.root.name),
            children=tuple(s for s in body_slots if s[0] == "torso"),
        )
        top.append(("mobile_base", (base,)))
        top.extend(s for s in body_slots if s[0] != "torso")
    else:
        top.extend(body_slots)
    if cam:
        top.append(("sensors", tuple(cam.values())))
    pairs = sorted(tuple(sorted(p)) for p in robot.disabled_collision_pairs)
    cfg = robot.default_collision_config
    return RobotRecipe(
        name=_safe(robot.name),
        root=robot.root.name,
        source=portable_source(robot.world.source),
        children=tuple(top),
        disabled_pairs=tuple((a, b) for a, b in pairs),
        disabled_bodies=tuple(sorted(robot.disabled_collision_bodies)),
        buffer_zone_distance=cfg.buffer_zone_distance,
        violated_distance=cfg.violated_distance,
        collisions_disabled=cfg.disabled,
        extra_hardware_joints=tuple(extra),
        left_out=tuple(left_out),
    )
