"""An SDT robot class (hand-written, one class per part) read back into a robotspec spec.

Why: a robot SDT already describes in code should not be described again by hand. SDT's own
steps build the parts on SDT's world of the robot's files (its ``from_world`` without the
collision rules, whose SRDF the caller gives instead), and every part, state, hardware
interface and velocity limit is read off the result into spec data. ``robotspec validate``
then checks what SDT's class only assumed; :func:`~robotspec.interop.sdt.to_sdt` turns the
spec back into SDT's classes.

What a spec cannot say is reported, one line each, in :attr:`Migration.notes`: an end effector
of a single finger (a generic manipulator; more than two fingers are a ``type: hand``), a velocity
limit SDT *raises* (robotspec's limits only tighten), a state of a kind robotspec has no name for.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robotspec.errors import RobotSpecError

__all__ = ["Migration", "import_class", "migrate_files", "render", "spec_from_sdt"]


@dataclass(frozen=True)
class Migration:
    """The spec (as YAML-ready data) and what it could not say."""

    spec: dict[str, Any]
    notes: tuple[str, ...]


def _snake(name: str) -> str:
    return re.sub(r"(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])", "_", name).lower()


def _part_name(part: Any, robot_class: type) -> str:
    """``PR2LeftGripper`` of robot ``PR2`` -> ``left_gripper``."""
    name = type(part).__name__
    prefix = robot_class.__name__
    if name.startswith(prefix) and len(name) > len(prefix):
        name = name[len(prefix) :]
    return _snake(name)


def _finger_names(names: list[str]) -> list[str]:
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


def _n(entity: Any) -> str:
    return str(entity.name.name)


def _vector(v: Any) -> list[float]:
    return [round(float(x), 9) + 0.0 for x in v.to_np()[:3]]


def _kind(part: Any, sdt: Any) -> str | None:
    for kind in ("MobileBase", "Torso", "Neck", "Arm", "EndEffector", "Finger", "Camera"):
        if isinstance(part, getattr(sdt.parts, kind)):
            return kind
    return "Sensor" if isinstance(part, sdt.parts.Sensor) else None


def _states(states: list[Any], notes: list[str], where: str) -> dict[str, Any]:
    """SDT joint states as spec states: on the joints that move (a mimic's leader).

    A value SDT sets on a mimic joint is the leader's ``(value - offset) / multiplier``. When
    SDT sets two mimics of one leader to values that disagree, the one within the leader's
    limits is kept and the disagreement noted.
    """
    out: dict[str, dict[str, float]] = {}
    for s in states:
        if s.state_type is None:
            notes.append(f"{where}: state '{_n(s)}' has no kind; left out")
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


def _build(cls: Any, world: Any) -> tuple[Any, dict[str, float | None]]:
    """SDT's ``from_world`` without its collision rules; the velocity limits before it."""
    root = world.get_body_in_branch_by_name(world.root, cls._get_root_body_name())
    before: dict[str, float | None] = {}
    with world.modify_world():
        robot = cls(root=root)
        robot.setup_robot_part_semantic_annotations()
        world.add_semantic_annotation_recursively(robot)
        for c in robot._one_dof_connections:
            before[_n(c)] = c.raw_dof.limits.upper.velocity
        for part in robot._robot_parts:
            part.setup_hardware_interfaces()
        robot._setup_velocity_limits()
    return robot, before


def spec_from_sdt(
    cls: type, world: Any, *, urdf: str, srdf: str | None = None, name: str | None = None
) -> Migration:
    """The spec of SDT robot class ``cls`` on ``world`` (SDT's world of the robot's files).

    ``urdf`` and ``srdf`` are written into the spec's ``description`` as given (paths or
    ``package://`` URIs, as the spec will find them). The world is changed: the robot is added.
    """
    from robotspec.interop.sdt import sdt_api

    sdt = sdt_api()
    if not (isinstance(cls, type) and issubclass(cls, sdt.parts.AbstractRobot)):
        raise RobotSpecError(
            f"{cls!r} is not an SDT robot class (a subclass of "
            "semantic_digital_twin.robots.robot_parts.AbstractRobot)",
            kind="class",
        )
    notes: list[str] = []
    try:
        robot, before = _build(cls, world)
    except Exception as exc:  # SDT's own lookups (a body its class names, a part it expects)
        raise RobotSpecError(
            f"SDT's class {cls.__name__} cannot be built on this robot's world: "
            f"{type(exc).__name__}: {exc}",
            kind="class",
            name=cls.__name__,
        ) from exc
    left = robot.get_left_arm_if_specified()
    right = robot.get_right_arm_if_specified()
    spec: dict[str, Any] = {"robotspec": 1, "name": name or cls.__name__}
    spec["description"] = {"urdf": urdf, **({"srdf": srdf} if srdf else {})}
    spec["root"] = _n(robot.root)
    chains: dict[str, Any] = {}
    manipulators: dict[str, Any] = {}
    sensors: dict[str, Any] = {}
    names = {id(p): _part_name(p, cls) for p in robot._robot_parts}
    for part in robot._robot_parts:
        kind = _kind(part, sdt)
        pname = names[id(part)]
        states = _states(part.setup_joint_states(), notes, pname)
        carried = [names[id(s)] for s in getattr(part, "sensors", [])]
        if kind == "MobileBase":
            spec["drive"] = {"type": "omni"}
        elif kind == "Torso":
            spec["torso"] = {"root": _n(part.root), "tip": _n(part.tip), "states": states}
        elif kind == "Neck":
            spec["neck"] = {
                "root": _n(part.root),
                "tip": _n(part.tip),
                "sensors": carried,
                "states": states,
            }
        elif kind == "Arm":
            chain: dict[str, Any] = {"root": _n(part.root), "tip": _n(part.tip)}
            if part.end_effector is not None:
                chain["manipulator"] = names[id(part.end_effector)]
            if part is left or part is right:
                chain["side"] = "left" if part is left else "right"
            chain.update({"sensors": carried, "states": states})
            chains[pname] = chain
        elif kind == "EndEffector":
            q = part.front_facing_orientation.to_np()
            m: dict[str, Any] = {
                "type": "generic",
                "root": _n(part.root),
                "tool_frame": _n(part.tool_frame),
                "front_facing_orientation": [float(x) for x in q[:4]],
                "front_facing_axis": _vector(part.front_facing_axis),
                "states": states,
            }
            fingers = list(getattr(part, "fingers", []))
            if len(fingers) == 2:
                thumb = part.thumb
                (other,) = [f for f in fingers if f is not thumb]
                m["type"] = "parallel_gripper"
                m["thumb"] = {"root": _n(thumb.root), "tip": _n(thumb.tip)}
                m["finger"] = {"root": _n(other.root), "tip": _n(other.tip)}
            elif len(fingers) > 2:
                thumb = part.thumb
                m["type"] = "hand"
                m["thumb"] = {"root": _n(thumb.root), "tip": _n(thumb.tip)}
                short = _finger_names([names.get(id(f)) or _n(f.root) for f in fingers])
                named: dict[str, Any] = {}
                for f, key in zip(fingers, short, strict=True):
                    if f is thumb:
                        continue
                    key = key if key != "thumb" else _n(f.root)
                    while key in named:
                        key += "_"
                    named[key] = {"root": _n(f.root), "tip": _n(f.tip)}
                m["fingers"] = named
            elif fingers:
                notes.append(
                    f"{pname}: one finger; a spec's hand has a thumb and another finger, so it "
                    "is a generic manipulator"
                )
            manipulators[pname] = m
        elif kind == "Camera":
            fov = part.field_of_view
            sensors[pname] = {
                "type": "camera",
                "body": _n(part.root),
                "forward_facing_axis": _vector(part.forward_facing_axis),
                "field_of_view": {
                    "vertical": float(fov.vertical_angle),
                    "horizontal": float(fov.horizontal_angle),
                },
                "minimal_height": float(part.minimal_height),
                "maximal_height": float(part.maximal_height),
                "default": bool(part.default_camera),
            }
        elif kind == "Sensor":
            sensors[pname] = {"type": "generic", "body": _n(part.root)}
    for key, value in (("chains", chains), ("manipulators", manipulators), ("sensors", sensors)):
        if value:
            spec[key] = value
    hardware = sorted(
        {_n(c) for c in robot.connections if getattr(c, "has_hardware_interface", False)}
    )
    if hardware:
        spec["controlled_joints"] = hardware
    limits: dict[str, float] = {}
    for c in robot._one_dof_connections:
        after, was = c.raw_dof.limits.upper.velocity, before.get(_n(c))
        if c.raw_dof.name.name != c.name.name or after is None or after == was:
            continue  # a mimic joint (its leader carries the limit), or unchanged
        if was is not None and after > was:
            notes.append(
                f"velocity limit of '{_n(c)}': SDT raises it from {was} to {after}; "
                "robotspec's limits only tighten, so the URDF's stays"
            )
            continue
        limits[_n(c)] = float(after)
    if limits:
        common = max(set(limits.values()), key=list(limits.values()).count)
        spec["velocity_limits"] = {
            "default": common,
            "joints": {j: v for j, v in limits.items() if v != common},
        }
    if srdf:
        spec["collision"] = {"use_srdf": True}
    return Migration(spec=_drop_empty(spec), notes=tuple(notes))


def _drop_empty(data: Any) -> Any:
    if isinstance(data, dict):
        return {k: _drop_empty(v) for k, v in data.items() if v not in ({}, [], None)}
    return data


# --------------------------------------------------------------------------- from files
def import_class(target: str) -> type:
    """``package.module:Class`` imported (the command's ``MODULE:CLASS``)."""
    import importlib

    module, _, name = target.partition(":")
    if not module or not name:
        raise RobotSpecError(
            f"'{target}' is not MODULE:CLASS (e.g. semantic_digital_twin.robots.pr2:PR2)",
            kind="class",
            name=target,
        )
    try:
        found = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError) as exc:
        raise RobotSpecError(f"cannot import '{target}': {exc}", kind="class", name=target) from exc
    if not isinstance(found, type):
        raise RobotSpecError(f"'{target}' is not a class", kind="class", name=target)
    return found


def migrate_files(
    target: str,
    urdf: str,
    *,
    srdf: str | None = None,
    folder: Path,
    package_paths: Sequence[str | Path] = (),
) -> Migration:
    """SDT class ``target`` (``MODULE:CLASS``) on the robot of ``urdf``, as a spec.

    The URDF (or xacro) is read by robotspec (package paths, a joint's default axis) and handed
    to SDT as a world built from robotspec's model, so SDT's parser and its package resolver
    are not needed. The spec names the files relative to ``folder``, where it will be written.
    """
    from robotspec.description.load import load_description
    from robotspec.interop.sdt import sdt_api
    from robotspec.interop.sdt.world import sdt_world

    sdt_api()  # SDT missing: say how to install it, before its class cannot be imported
    cls = import_class(target)
    world = load_description(urdf, package_paths=package_paths, base_folder=Path.cwd()).world
    sdt = sdt_world(world, drive="fixed")

    def named(file: str) -> str:
        if "://" in file:
            return file
        path = Path(file).resolve()
        return os.path.relpath(path, folder) if path.is_relative_to(folder) else str(path)

    return spec_from_sdt(cls, sdt, urdf=named(urdf), srdf=None if srdf is None else named(srdf))


def render(migration: Migration, *, source: str) -> str:
    """The spec as YAML, headed by where it came from and what it could not say."""
    import yaml

    head = [
        "# yaml-language-server: $schema=robotspec.schema.json",
        f"# Migrated from SDT's robot class {source} by `robotspec migrate sdt`.",
        "# Run `robotspec validate` on it: it checks what the class only assumed.",
        *(f"# NOTE: {n}" for n in migration.notes),
    ]
    return "\n".join(head) + "\n" + yaml.safe_dump(migration.spec, sort_keys=False)
