"""What the robot's own files state, for ``migrate sdt``: its drive and its arms' sides.

Why apart from :mod:`robotspec.interop.sdt.migrate`: an SDT class states parts, states and
hardware interfaces, but not how its base moves (the drive is what a test fixture adds) nor
which arm is left (SDT guesses it at run time, and for iCub 3 and Justin returns the right arm
for both). Those facts belong to the URDF and SRDF, so they are read here from robotspec's own
model of the files, without SDT: a migrated spec must state only what its sources state.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robotspec.model.entities import ConnectionType

if TYPE_CHECKING:
    from robotspec.description.srdf import Srdf
    from robotspec.model.world import World

__all__ = ["DriveFact", "arm_offsets", "drive_fact", "geometric_left"]

#: Two arms whose mean lateral positions differ by less than this (m) have no side.
SIDE_TOLERANCE = 1e-6


@dataclass(frozen=True)
class DriveFact:
    """The spec's ``drive:`` entry (None: leave it out) and why, when nothing states it."""

    spec: dict[str, Any] | None
    note: str | None = None


def drive_fact(world: World, srdf: Srdf | None, root: str, *, moves: bool) -> DriveFact:
    """The drive the files state for a robot rooted at ``root``; ``moves``: SDT gives it a base.

    In order: a planar or floating URDF joint above ``root`` and an SRDF virtual joint that
    moves the URDF's root are read by the compiler as they are, so the spec leaves ``drive``
    out; exactly two driven wheels (casters excluded) make a differential drive; anything else
    (legs, three or more wheels, nothing) states no drive, and the note says what to add. A
    class without a mobile base is fixed: a virtual joint that would move it is overruled.
    """
    from robotspec.spec.draft.base import wheel_joints

    above = world.parent_connection(root) if world.has_body(root) else None
    own = above is not None and above.type in (ConnectionType.PLANAR, ConnectionType.FLOATING)
    vj = None
    if srdf is not None and root == world.root.name:
        vj = next((v for v in srdf.virtual_joints if v.child_link == root), None)
    moving_vj = vj is not None and vj.type in ("planar", "floating")
    if not moves:
        if moving_vj and vj is not None and not own:
            return DriveFact(
                {"type": "fixed"},
                f"drive: SDT's class has no mobile base, but the SRDF's virtual joint "
                f"'{vj.name}' ({vj.type}) would move the robot; written fixed, as the class is",
            )
        if own and above is not None:
            return DriveFact(
                None,
                f"drive: SDT's class has no mobile base, but the URDF's joint '{above.name}' "
                f"({above.type.value}) moves the robot; the spec keeps the URDF's",
            )
        return DriveFact(None)
    if own or moving_vj:
        return DriveFact(None)  # the compiler reads it: planar is omni, floating is floating
    wheels = wheel_joints(world)
    names = ", ".join(f"'{c.name}'" for c in wheels)
    if len(wheels) == 2 and root == world.root.name:
        return DriveFact({"type": "differential"})
    found = f"{len(wheels)} wheel joints ({names})" if wheels else "no wheels"
    return DriveFact(
        None,
        f"drive: SDT's class gives the robot a mobile base, but its files do not say how it "
        f"moves ({found}, no planar or floating joint or SRDF virtual joint above '{root}'); "
        "none written: add `drive: {type: omni | differential | floating}` if it moves "
        "(to_sdt builds SDT's mobile base only for a robot with a drive)",
    )


def arm_offsets(
    world: World,
    root: str,
    arms: Sequence[tuple[str, str]],
    forward: tuple[float, float, float] = (1.0, 0.0, 0.0),
) -> list[float]:
    """Each arm's mean offset (m) along the robot's left, as :func:`robotspec.semantic.sides`.

    ``arms``: (root, tip) link names. The mean over the arm's bodies below its root, in
    ``root``'s frame, default pose; left is up (z) cross ``forward`` (+y for a robot facing +x),
    the same measure ``robotspec validate`` uses, so the two never disagree.
    """
    from robotspec.model.kinematics import Kinematics

    kin = Kinematics(world)
    q = world.default_configuration()
    left = np.array([-forward[1], forward[0], 0.0])
    out = []
    for a_root, a_tip in arms:
        chain = world.compute_chain_of_kinematic_structure_entities(a_root, a_tip)
        bodies = [b for b in chain if b.name != a_root] or [world.get_body_by_name(a_tip)]
        ys = [float(kin.pose(q, b.name, relative_to=root)[:3, 3] @ left) for b in bodies]
        out.append(float(np.mean(ys)))
    return out


def geometric_left(offsets: Sequence[float]) -> int | None:
    """The index of the left one of two arms by their offsets; None when they tie."""
    a, b = offsets
    if abs(a - b) < SIDE_TOLERANCE:
        return None
    return 0 if a > b else 1
