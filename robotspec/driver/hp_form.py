"""A serial chain of a world in H/P form: joint axes ``H``, offsets ``P``, flange rotation.

Why a module: this is the one geometric step of exporting a RobotInfo (the general-robotics-
toolbox recipe, see :mod:`robotspec.driver.export`), and the step that refuses what H/P cannot
express (mimic joints, floating or planar joints, zero axes, a joint past the tip). The rest
of the export only converts limits and names.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robotspec.arrays import F64
from robotspec.errors import RobotInfoError
from robotspec.model.world import Body, Connection, ConnectionType, World

__all__ = ["HPForm", "clean", "hp_form", "refuse"]

#: H vectors and the flange rotation are cleaned of round-off below this (exact zeros read well).
_CLEAN_TOL = 1e-15


@dataclass(frozen=True)
class HPForm:
    """The chain ``root`` → ``flange`` as H/P: one ``h`` per movable joint, one ``p`` more.

    Attributes:
        h: unit joint axes in the root's frame at q = 0, one per movable joint.
        p: offsets, ``p[k]`` from joint ``k - 1`` to joint ``k`` (``p[0]`` from the root,
            ``p[n]`` to the flange), in the root's frame at q = 0 (metres).
        movable: the movable connections, root first.
        flange_rotation: the flange's orientation in the root's frame at q = 0.
    """

    h: tuple[F64, ...]
    p: tuple[F64, ...]
    movable: tuple[Connection, ...]
    flange_rotation: F64


def clean(v: F64) -> F64:
    """``v`` with round-off below 1e-15 set to exact zeros (and no ``-0.0``)."""
    out = np.where(np.abs(v) < _CLEAN_TOL, 0.0, v)
    return np.asarray(out + 0.0, dtype=np.float64)  # + 0.0 turns -0.0 into 0.0


def refuse(world: World, c: Connection, why: str) -> RobotInfoError:
    """The error for a joint the export cannot take, naming it and its line."""
    return RobotInfoError(
        f"joint '{c.name}' ({c.type.value}{', mimic' if c.is_mimic else ''}) {why}",
        file=world.source,
        line=c.line,
        kind="joint",
        name=c.name,
    )


def hp_form(world: World, root: Body, tip: Body, flange: Body) -> HPForm:
    """Walk ``root`` → ``tip`` → ``flange``: every origin moves ``P``, every joint adds an ``H``.

    Raises:
        RobotInfoError: a moving joint between ``tip`` and ``flange``, a mimic, floating or
            planar joint, a zero axis, or no movable joint at all.
        KinematicsError: ``root`` is not an ancestor of ``tip`` (or ``tip`` of ``flange``).
    """
    to_tip = world.compute_chain_of_connections(root, tip)
    after_tip = world.compute_chain_of_connections(tip, flange)
    for c in after_tip:
        if not c.is_fixed:
            raise refuse(world, c, f"moves the flange '{flange.name}' beyond the tip '{tip.name}'")
    r_acc = np.eye(3)
    p_list: list[F64] = [np.zeros(3)]
    h_list: list[F64] = []
    movable: list[Connection] = []
    for c in [*to_tip, *after_tip]:
        _check_joint(world, c, root, tip)
        origin = np.asarray(c.origin, dtype=np.float64)
        p_list[-1] = p_list[-1] + r_acc @ origin[:3, 3]
        r_acc = r_acc @ origin[:3, :3]
        if c.is_fixed:
            continue
        axis = r_acc @ np.asarray(c.axis, dtype=np.float64)
        norm = float(np.linalg.norm(axis))
        if not norm > 0.0:
            raise refuse(world, c, "has a zero axis")
        h_list.append(clean(axis / norm))
        p_list.append(np.zeros(3))
        movable.append(c)
    if not movable:
        raise RobotInfoError(
            f"the chain '{root.name}' -> '{tip.name}' has no movable joint",
            file=world.source,
            kind="chain",
            name=tip.name,
        )
    return HPForm(tuple(h_list), tuple(p_list), tuple(movable), clean(r_acc))


def _check_joint(world: World, c: Connection, root: Body, tip: Body) -> None:
    if c.is_mimic:
        assert c.mimic is not None
        raise refuse(
            world,
            c,
            f"mimics '{c.mimic.leader}' inside the chain '{root.name}' -> '{tip.name}'; "
            "a RobotInfo chain has no mimic joints (end the chain before it)",
        )
    if c.type in (ConnectionType.FLOATING, ConnectionType.PLANAR):
        raise refuse(world, c, "has no single axis; a RobotInfo chain is serial 1-DOF joints")
