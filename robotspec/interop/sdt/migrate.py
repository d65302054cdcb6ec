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

Only what the class states is written (issue 32): the drive comes from the robot's files (SDT's
class only says the base moves; :mod:`~robotspec.interop.sdt.migrate_facts`), arm sides are the
geometry's (SDT's own guess kept as a note where it differs), hardware interfaces sit on the
joints that move (a mimic's leader, never the mimic), and values SDT derives (an end effector's
front-facing axis, computed from its orientation) are left for robotspec to derive.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robotspec.errors import RobotSpecError
from robotspec.interop.sdt.migrate_entries import (
    camera_entry,
    end_effector_entry,
    velocity_limits,
)
from robotspec.interop.sdt.migrate_facts import drive_fact
from robotspec.interop.sdt.migrate_parts import (
    base_root_note,
    build,
    forward_of,
    hardware_leaders,
    name_of,
    part_kind,
    part_name,
    side_notes,
    spec_states,
)
from robotspec.model.world import World
from robotspec.spec.sdt import SDT_ROBOT_CLASSES

if TYPE_CHECKING:
    from robotspec.description.load import Description
    from robotspec.description.srdf import Srdf

__all__ = ["Migration", "import_class", "migrate_files", "render", "spec_from_sdt"]


@dataclass(frozen=True)
class Migration:
    """The spec (as YAML-ready data) and what it could not say."""

    spec: dict[str, Any]
    notes: tuple[str, ...]


def spec_from_sdt(
    cls: type,
    world: Any,
    *,
    urdf: str,
    srdf: str | None = None,
    name: str | None = None,
    files: Description | World | None = None,
) -> Migration:
    """The spec of SDT robot class ``cls`` on ``world`` (SDT's world of the robot's files).

    ``urdf`` and ``srdf`` are written into the spec's ``description`` as given (paths or
    ``package://`` URIs, as the spec will find them). The world is changed: the robot is added.
    ``files``: robotspec's model of the same files (the drive and arm sides are read off it),
    or its world alone (a composed robot: no SRDF); loaded from ``urdf`` and ``srdf``
    (``ROS_PACKAGE_PATH`` for packages) when not given.
    """
    from robotspec.interop.sdt import sdt_api

    sdt = sdt_api()
    robot, before = _built(sdt, cls, world)
    if files is None:
        from robotspec.description.load import load_description

        files = load_description(urdf, srdf=srdf)
    model, model_srdf = (files, None) if isinstance(files, World) else (files.world, files.srdf)
    notes: list[str] = []
    spec, forward = _head(sdt, cls, robot, (urdf, srdf), name, (model, model_srdf), notes)
    names = {id(p): part_name(p, cls) for p in robot._robot_parts}
    groups = _parts(sdt, robot, names, spec, notes)
    notes.extend(side_notes(robot, groups["chains"], names, model, spec["root"], forward))
    spec.update((key, value) for key, value in groups.items() if value)
    hardware = hardware_leaders(robot, notes)
    if hardware:
        spec["controlled_joints"] = hardware
    limits = velocity_limits(robot, before, notes)
    if limits is not None:
        spec["velocity_limits"] = limits
    if srdf:
        spec["collision"] = {"use_srdf": True}
    return Migration(spec=_drop_empty(spec), notes=tuple(notes))


def _built(sdt: Any, cls: type, world: Any) -> tuple[Any, dict[str, float | None]]:
    """SDT's class set up on ``world`` (:func:`.migrate_parts.build`), or why it cannot be."""
    if not (isinstance(cls, type) and issubclass(cls, sdt.parts.AbstractRobot)):
        raise RobotSpecError(
            f"{cls!r} is not an SDT robot class (a subclass of "
            "semantic_digital_twin.robots.robot_parts.AbstractRobot)",
            kind="class",
        )
    try:
        return build(cls, world)
    except Exception as exc:  # SDT's own lookups (a body its class names, a part it expects)
        raise RobotSpecError(
            f"SDT's class {cls.__name__} cannot be built on this robot's world: "
            f"{type(exc).__name__}: {exc}",
            kind="class",
            name=cls.__name__,
        ) from exc


def _head(
    sdt: Any,
    cls: type,
    robot: Any,
    description: tuple[str, str | None],
    name: str | None,
    files: tuple[World, Srdf | None],
    notes: list[str],
) -> tuple[dict[str, Any], tuple[float, float, float]]:
    """The spec's robot-level keys (name, SDT class, files, root, forward, drive) and forward.

    What the class says of its base goes here: which way it faces, and, from the files, how it
    moves (:func:`.migrate_facts.drive_fact`); where it roots its mobile base, when that is
    not the base body ``to_sdt`` derives (:func:`.base.base_body`), is a note.
    """
    (urdf, srdf), (model, model_srdf) = description, files
    spec: dict[str, Any] = {"robotspec": 1, "name": name or cls.__name__}
    if SDT_ROBOT_CLASSES.get(cls.__name__) == cls.__module__.rpartition(".")[2] and (
        cls.__module__.startswith("semantic_digital_twin.robots.")
    ):  # SDT's own class: to_sdt's robot is an instance of it (coraplex's motions apply)
        spec["sdt"] = {"class": cls.__name__}
    spec["description"] = {"urdf": urdf, **({"srdf": srdf} if srdf else {})}
    spec["root"] = name_of(robot.root)
    base = next((p for p in robot._robot_parts if part_kind(p, sdt) == "MobileBase"), None)
    forward = (1.0, 0.0, 0.0) if base is None else forward_of(base)
    if forward != (1.0, 0.0, 0.0):
        spec["forward"] = list(forward)
    drive = drive_fact(model, model_srdf, spec["root"], moves=base is not None)
    if drive.spec is not None:
        spec["drive"] = drive.spec
    if drive.note is not None:
        notes.append(drive.note)
    if base is not None:
        notes.extend(base_root_note(base, model, spec["root"]))
    return spec, forward


def _parts(
    sdt: Any, robot: Any, names: dict[int, str], spec: dict[str, Any], notes: list[str]
) -> dict[str, dict[str, Any]]:
    """Every part of the built robot as its spec entry.

    The torso and neck go into ``spec``; the rest is returned as its ``chains``,
    ``manipulators`` and ``sensors``.
    """
    out: dict[str, dict[str, Any]] = {"chains": {}, "manipulators": {}, "sensors": {}}
    for part in robot._robot_parts:
        kind = part_kind(part, sdt)
        pname = names[id(part)]
        states = spec_states(part.setup_joint_states(), notes, pname)
        carried = [names[id(s)] for s in getattr(part, "sensors", [])]
        if kind in ("Torso", "Neck", "Arm"):
            ends = {"root": name_of(part.root), "tip": name_of(part.tip)}
        if kind == "Torso":
            spec["torso"] = {**ends, "states": states}
        elif kind == "Neck":
            spec["neck"] = {**ends, "sensors": carried, "states": states}
        elif kind == "Arm":
            tool = part.end_effector
            held = {} if tool is None else {"manipulator": names[id(tool)]}
            out["chains"][pname] = {**ends, **held, "sensors": carried, "states": states}
        elif kind == "EndEffector":
            entry = end_effector_entry(part, pname, names, states, notes)
            out["manipulators"][pname] = entry
        elif kind == "Camera":
            out["sensors"][pname] = camera_entry(part)
        elif kind == "Sensor":
            out["sensors"][pname] = {"type": "generic", "body": name_of(part.root)}
    return out


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
    files = load_description(urdf, srdf=srdf, package_paths=package_paths, base_folder=Path.cwd())
    sdt = sdt_world(files.world, drive="fixed")

    def named(file: str) -> str:
        if "://" in file:
            return file
        path = Path(file).resolve()
        return os.path.relpath(path, folder) if path.is_relative_to(folder) else str(path)

    return spec_from_sdt(
        cls, sdt, urdf=named(urdf), srdf=None if srdf is None else named(srdf), files=files
    )


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
