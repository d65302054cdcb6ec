"""Configurations for collision queries: the default pose, seeded random ones, named states.

Why MoveIt's rules: the collision matrix is compared with SRDFs written by MoveIt's Setup
Assistant, so "default" and "random" mean what they mean there. The default value of a joint is
0 when its limits allow it and the middle of its range otherwise; random values are uniform over
the limits, ``[-pi, pi]`` for an unbounded revolute (continuous) joint, and 0 for unbounded
translations and multi-DOF base joints (they move the whole robot rigidly, so self-collision
does not depend on them). Mimic joints follow their leader through the world's kinematics.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from robotspec.errors import CollisionError, NotFoundError
from robotspec.model.world import ConnectionType, World

if TYPE_CHECKING:
    from robotspec.semantic.robot import AbstractRobot

__all__ = [
    "default_configuration",
    "random_configurations",
    "sampling_bounds",
    "state_configuration",
]

F64 = NDArray[np.float64]


def sampling_bounds(world: World) -> tuple[F64, F64]:
    """Lower and upper bounds (D,) that random configurations are drawn from."""
    lo = np.zeros(len(world.degrees_of_freedom))
    hi = np.zeros(len(world.degrees_of_freedom))
    for d in world.degrees_of_freedom:
        conn = world.get_connection_by_name(d.connection)
        if d.is_bounded:
            lo[d.index], hi[d.index] = d.lower, d.upper
        elif conn.type in (ConnectionType.REVOLUTE, ConnectionType.CONTINUOUS):
            lo[d.index] = max(d.lower, -math.pi)
            hi[d.index] = min(d.upper, math.pi)
    return lo, hi


def default_configuration(world: World) -> F64:
    """MoveIt's default state: 0 where the limits allow it, else the middle of the range."""
    q = np.zeros(len(world.degrees_of_freedom))
    for d in world.degrees_of_freedom:
        if d.lower > 0.0 or d.upper < 0.0:
            if d.is_bounded:
                q[d.index] = (d.lower + d.upper) / 2.0
            else:
                q[d.index] = d.lower if math.isfinite(d.lower) else d.upper
    return q


def random_configurations(world: World, n: int, seed: int | np.random.Generator = 0) -> F64:
    """``n`` configurations (n, D) uniform over :func:`sampling_bounds`, reproducible by seed."""
    if n < 0:
        raise CollisionError(f"sample count must be >= 0, got {n}", kind="config")
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    lo, hi = sampling_bounds(world)
    out: F64 = lo + (hi - lo) * rng.random((n, len(lo)))
    return out


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
    q = default_configuration(world) if base is None else np.array(base, dtype=np.float64)
    for name in states:
        for joint, value in _state_values(robot, name).items():
            q[_dof_index(world, joint)] = value
    for joint, value in (values or {}).items():
        if not math.isfinite(value):
            raise CollisionError(f"joint '{joint}': value {value} is not finite", name=joint)
        q[_dof_index(world, joint)] = value
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
