"""Reading SDT's built parts for ``migrate sdt``: names, kinds, states, interfaces, sides.

Why apart from :mod:`robotspec.interop.sdt.migrate`: these read one aspect each of an SDT robot
built by its own class (duck-typed, so this module imports no SDT), and each decides what the
class really states: a mimic's state or hardware interface belongs to its leader, SDT's guess
of the arms' sides yields to the geometry, a mobile base rooted off the base body is noted.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

from robotspec.interop.sdt.base import base_body
from robotspec.interop.sdt.migrate_facts import arm_offsets, geometric_left

if TYPE_CHECKING:
    from robotspec.model.world import World

__all__ = [
    "base_root_note",
    "build",
    "finger_names",
    "forward_of",
    "hardware_leaders",
    "part_kind",
    "name_of",
    "part_name",
    "side_notes",
    "spec_states",
    "vector3",
]


def _snake(name: str) -> str:
    return re.sub(r"(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])", "_", name).lower()


def part_name(part: Any, robot_class: type) -> str:
    """``PR2LeftGripper`` of robot ``PR2`` -> ``left_gripper``."""
    name = type(part).__name__
    prefix = robot_class.__name__
    if name.startswith(prefix) and len(name) > len(prefix):
        name = name[len(prefix) :]
    return _snake(name)


def finger_names(names: list[str]) -> list[str]:
    """Finger part names without the words all share (``left_hand_index`` -> ``index``)."""
    words = [n.split("_") for n in names]
    if len(words) < 2:
        return names
    lead = 0
    while all(len(w) > lead + 1 and w[lead] == words[0][lead] for w in words):
        lead += 1
    trail = 0
    while all(len(w) > lead + trail + 1 and w[-1 - trail] == words[0][-1 - trail] for w in words):
        trail += 1
    return ["_".join(w[lead : len(w) - trail]) for w in words]


def name_of(entity: Any) -> str:
    """An SDT entity's name without its prefix (the URDF's own name)."""
    return str(entity.name.name)


def vector3(v: Any) -> list[float]:
    """An SDT vector as three plain floats (rounded to 1e-9, no negative zero)."""
    return [round(float(x), 9) + 0.0 for x in v.to_np()[:3]]


def part_kind(part: Any, sdt: Any) -> str | None:
    """The SDT part class an SDT part is an instance of, by name; None for none of them."""
    for kind_name in ("MobileBase", "Torso", "Neck", "Arm", "EndEffector", "Finger", "Camera"):
        if isinstance(part, getattr(sdt.parts, kind_name)):
            return kind_name
    return "Sensor" if isinstance(part, sdt.parts.Sensor) else None


def spec_states(states: list[Any], notes: list[str], where: str) -> dict[str, Any]:
    """SDT joint states as spec states: on the joints that move (a mimic's leader).

    A value SDT sets on a mimic joint is the leader's ``(value - offset) / multiplier``. When
    SDT sets two mimics of one leader to values that disagree, the one within the leader's
    limits is kept and the disagreement noted.
    """
    out: dict[str, dict[str, float]] = {}
    for s in states:
        if s.state_type is None:
            notes.append(f"{where}: state '{name_of(s)}' has no kind; left out")
            continue
        candidates: dict[str, list[float]] = {}
        dofs: dict[str, Any] = {}
        for c, value in zip(s.connections, s.target_values, strict=True):
            leader = str(c.raw_dof.name.name)
            dofs[leader] = c.raw_dof
            candidates.setdefault(leader, []).append((float(value) - c.offset) / c.multiplier + 0.0)
        joints: dict[str, float] = {}
        for leader, values in candidates.items():
            limits = dofs[leader].limits
            lo, hi = limits.lower.position, limits.upper.position
            inside = [
                v
                for v in values
                if (lo is None or v >= lo - 1e-9) and (hi is None or v <= hi + 1e-9)
            ]
            joints[leader] = (inside or values)[0]
            if len(set(values)) > 1:
                notes.append(
                    f"{where}.{s.state_type.name.lower()}: SDT sets joints that follow "
                    f"'{leader}' to disagreeing values (as {sorted(set(values))} of it); "
                    f"kept {joints[leader]}"
                )
        out[s.state_type.name.lower()] = joints
    return out


def build(cls: Any, world: Any) -> tuple[Any, dict[str, float | None]]:
    """SDT's ``from_world`` without its collision rules; the velocity limits before it."""
    root = world.get_body_in_branch_by_name(world.root, cls._get_root_body_name())
    before: dict[str, float | None] = {}
    with world.modify_world():
        robot = cls(root=root)
        robot.setup_robot_part_semantic_annotations()
        world.add_semantic_annotation_recursively(robot)
        for c in robot._one_dof_connections:
            before[name_of(c)] = c.raw_dof.limits.upper.velocity
        for part in robot._robot_parts:
            part.setup_hardware_interfaces()
        robot._setup_velocity_limits()
    return robot, before


def forward_of(base: Any) -> tuple[float, float, float]:
    """The way SDT's mobile base faces (its ``forward_axis``), as the spec's ``forward``."""
    x, y, z = (round(float(v), 9) + 0.0 for v in base.forward_axis.to_np()[:3])
    return (x, y, z)


def base_root_note(base: Any, world: World, root: str) -> list[str]:
    """A note when SDT's mobile base starts at a body other than the robot's base body.

    Why: a spec names no mobile base; ``to_sdt`` roots it at the base body the files give
    (:func:`.base.base_body`), which is the body SDT's wheeled classes name. Where SDT's class
    names another (iCub 3: a hip), the note says so; the spec does not copy it.
    """
    ours = base_body(world, root)
    if name_of(base.root) == ours:
        return []
    return [
        f"mobile base: SDT's class roots it at '{name_of(base.root)}'; to_sdt roots it at the "
        f"robot's base body '{ours}' (the root, or the body welded below it that carries the "
        "base's collision geometry); a spec names no mobile base"
    ]


def hardware_leaders(robot: Any, notes: list[str]) -> list[str]:
    """The joints SDT gives hardware interfaces, a mimic's moved to its leader (with a note).

    Why: a mimic joint has no actuator of its own; the interface SDT puts on it controls its
    leader's degree of freedom, so the spec names the leader (``validate`` refuses a mimic).
    """
    own: set[str] = set()
    mimics: dict[str, str] = {}
    for c in robot.connections:
        if not getattr(c, "has_hardware_interface", False):
            continue
        dof = getattr(c, "raw_dof", None)
        leader = name_of(c) if dof is None else str(dof.name.name)
        if leader == name_of(c):
            own.add(leader)
        else:
            mimics[name_of(c)] = leader
    for mimic, leader in sorted(mimics.items()):
        if leader not in own:
            own.add(leader)
            notes.append(
                f"hardware interface of '{mimic}': it follows '{leader}' (a mimic has no "
                f"actuator of its own); written on '{leader}'"
            )
    return sorted(own)


def _sdt_side(robot: Any, which: str) -> Any:
    """SDT's own left or right arm, or None where SDT cannot tell (its guess may raise)."""
    try:
        return getattr(robot, f"get_{which}_arm_if_specified")()
    except (AssertionError, AttributeError, IndexError, KeyError, ValueError):  # SDT's guess
        return None


def side_notes(
    robot: Any,
    chains: dict[str, Any],
    names: dict[int, str],
    world: World,
    root: str,
    forward: tuple[float, float, float],
) -> list[str]:
    """Sides of two arms by geometry (left: at +y of the root); SDT's where they differ.

    The geometry's sides are what robotspec derives, so no ``side`` is written; SDT's guess,
    where it differs, is a note. Only where the arms tie (side by side on the forward axis)
    are SDT's sides written, as the class states them.
    """
    arms = [p for p in robot._robot_parts if names.get(id(p)) in chains]
    if len(arms) != 2:
        return []
    left, right = _sdt_side(robot, "left"), _sdt_side(robot, "right")
    ends = [(name_of(a.root), name_of(a.tip)) for a in arms]
    geo = geometric_left(arm_offsets(world, root, ends, forward))
    label = [names[id(a)] for a in arms]
    if geo is None:
        if left is None or right is None or left is right:
            return [f"sides: arms '{label[0]}' and '{label[1]}' tie; declare `side` on one"]
        for a, lab in zip(arms, label, strict=True):
            chains[lab]["side"] = "left" if a is left else "right"
        return [f"sides: arms '{label[0]}' and '{label[1]}' tie in position; SDT's kept"]
    geo_left, geo_right = arms[geo], arms[1 - geo]
    if left is geo_left and right is geo_right:
        return []
    said = ", ".join(
        f"{side} '{names[id(a)]}'" if a is not None else f"no {side} arm"
        for side, a in (("left", left), ("right", right))
    )
    return [
        f"sides: SDT's class returns {said}; by geometry (the arm at +y of '{root}' is left) "
        f"'{names[id(geo_left)]}' is left and '{names[id(geo_right)]}' right: the spec keeps "
        "the geometry's"
    ]
