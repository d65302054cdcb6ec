"""Named states to configuration vectors: ``left_arm.park``, ``park``, ``arm/neutral``.

Why in the semantic layer: a state name means something only through the robot's parts (a bare
name applies every part's state of that name) and its SRDF's group states. Collision checks,
pictures and the live view all start from here, over the world's one default pose
(:meth:`~robotspec.model.world.World.default_configuration`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING

import numpy as np

from robotspec.arrays import F64, real_number
from robotspec.errors import CollisionError, NotFoundError

if TYPE_CHECKING:
    from robotspec.model.world import World
    from robotspec.semantic.robot import AbstractRobot

__all__ = ["state_configuration"]


def state_configuration(
    robot: AbstractRobot,
    states: Iterable[str] = (),
    values: Mapping[str, float] | None = None,
    *,
    base: F64 | None = None,
) -> F64:
    """A configuration: ``base`` (default pose if omitted), then named states, then ``values``.

    A state is a robot joint state (``left_arm.park``), a bare state name that applies every
    part's state of that name (``park`` = both arms' park), or an SRDF group state
    (``arm/neutral`` or ``neutral`` when unambiguous). ``values`` set joints by name last.
    """
    world = robot.world
    q = world.default_configuration() if base is None else np.array(base, dtype=np.float64)
    if isinstance(states, str):  # one state's name, not its letters one by one
        states = (states,)
    for name in states:
        for joint, value in _state_values(robot, name).items():
            q[_dof_index(world, joint)] = value
    for joint, value in (values or {}).items():
        index = _dof_index(world, joint)

        def error(message: str, joint: str = joint) -> CollisionError:
            return CollisionError(message, name=joint)

        q[index] = real_number(value, f"joint '{joint}': value", error)
    return q


def _dof_index(world: World, joint: str) -> int:
    if world.has_connection(joint):
        c = world.get_connection_by_name(joint)
        if c.mimic is not None:
            raise CollisionError(
                f"joint '{joint}' mimics '{c.mimic.leader}'; set '{c.mimic.leader}' instead",
                kind="joint",
                name=joint,
                suggestions=(c.mimic.leader,),
            )
        if len(c.dofs) == 1:
            return c.dofs[0]
    return world.get_degree_of_freedom_by_name(joint).index


def _state_values(robot: AbstractRobot, name: str) -> dict[str, float]:
    states = robot.joint_states
    if name in states:
        return states[name].as_dict()
    merged: dict[str, float] = {}
    by_suffix = [s for key, s in states.items() if key.rsplit(".", 1)[-1] == name]
    for s in by_suffix:
        merged.update(s.as_dict())
    if by_suffix:
        return merged
    srdf = robot.srdf
    group_states = [] if srdf is None else list(srdf.group_states)
    group, _, state = name.rpartition("/")
    found = [g for g in group_states if g.name == state and (not group or g.group == group)]
    if len(found) > 1:
        choices = [f"{g.group}/{g.name}" for g in found]
        raise CollisionError(
            f"SRDF group state '{name}' exists for several groups; name one of "
            + ", ".join(f"'{c}'" for c in choices),
            kind="state",
            name=name,
            suggestions=choices,
        )
    if found:
        # Names the URDF lacks were already reported (as warnings) when the SRDF was checked.
        return {
            j: v[0]
            for j, v in found[0].joint_values
            if len(v) == 1 and robot.world.has_connection(j)
        }
    candidates = [
        *states,
        *{k.rsplit(".", 1)[-1] for k in states},
        *(f"{g.group}/{g.name}" for g in group_states),
    ]
    raise NotFoundError("joint state", name, candidates, where=f"robot '{robot.name}'")
