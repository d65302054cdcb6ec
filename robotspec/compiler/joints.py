"""Joint-level checks: named joint states and velocity limits."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from robotspec.compiler.context import Build
from robotspec.description.srdf import GroupState
from robotspec.diagnostics import Loc
from robotspec.errors import SrdfError
from robotspec.exact import exact
from robotspec.model.world import Connection
from robotspec.semantic import JointState

__all__ = ["check_controlled", "check_states", "check_velocity", "srdf_state_values"]


def check_states(
    b: Build,
    loc: Loc,
    part: str,
    states: Mapping[str, Mapping[str, float]],
    allowed: set[str] | None,
) -> dict[str, JointState]:
    """Joint states: existing, actuated joints within limits, belonging to the part."""
    out: dict[str, JointState] = {}
    for state_name, values in states.items():
        ok = True
        for joint_name, value in values.items():
            jloc = (*loc, state_name, joint_name)
            c = b.joint(jloc, joint_name)
            if c is None:
                ok = False
                continue
            if c.is_fixed:
                b.diag.error(
                    jloc,
                    f"joint '{joint_name}' is fixed; a state can only set joints that move",
                    name=joint_name,
                )
                ok = False
                continue
            if c.mimic is not None:
                leader = c.mimic.leader
                b.diag.error(
                    jloc,
                    f"joint '{joint_name}' mimics '{leader}' (x{c.mimic.multiplier:g}"
                    f"{c.mimic.offset:+g}); set '{leader}' instead",
                    name=joint_name,
                    suggestions=(leader,),
                )
                ok = False
                continue
            if c.type.dof_count != 1:
                b.diag.error(
                    jloc,
                    f"joint '{joint_name}' has {c.type.dof_count} degrees of "
                    "freedom; states set 1-DOF joints",
                    name=joint_name,
                )
                ok = False
                continue
            dof = b.world.degrees_of_freedom[c.dofs[0]]
            if not math.isfinite(value):
                b.diag.error(jloc, f"value of '{joint_name}' must be finite", name=joint_name)
                ok = False
            elif not (dof.lower - 1e-9 <= value <= dof.upper + 1e-9):
                b.diag.error(
                    jloc,
                    f"{exact(value)} is outside the limits of '{joint_name}' "
                    f"[{exact(dof.lower)}, {exact(dof.upper)}]",
                    name=joint_name,
                )
                ok = False
            if allowed is not None and c.name not in allowed:
                b.diag.error(jloc, f"joint '{joint_name}' does not move {part}", name=joint_name)
                ok = False
        if ok:
            out[state_name] = JointState(
                name=state_name, part=part, joints=tuple((j, float(v)) for j, v in values.items())
            )
    return out


def check_velocity(b: Build, robot_joints: list[Connection]) -> dict[str, float]:
    """Per-DOF velocity caps; an unknown, fixed or mimic joint is an error."""
    vl = b.spec.velocity_limits
    one_dof = {c.name: c for c in robot_joints if c.is_1dof and c.is_active}
    caps: dict[str, float] = {}
    if vl.default is not None:
        caps = {b.world.degrees_of_freedom[c.dofs[0]].name: vl.default for c in one_dof.values()}
    for j, v in vl.joints.items():
        loc: Loc = ("velocity_limits", "joints", j)
        if j not in one_dof:
            c = b.world.get_connection_by_name(j) if b.world.has_connection(j) else None
            own = {r.name for r in robot_joints}
            if c is not None and c.mimic is not None:
                b.diag.error(
                    loc,
                    f"joint '{j}' mimics '{c.mimic.leader}'; limit the leader",
                    name=j,
                    suggestions=(c.mimic.leader,),
                )
            elif c is not None and c.name not in own and b.robot_root is not None:
                b.diag.error(
                    loc,
                    f"joint '{j}' is not a joint of robot '{b.spec.name}' (it is not below "
                    f"the root '{b.robot_root.name}'); limits apply to the robot's own joints",
                    name=j,
                )
            elif c is not None and c.is_fixed:
                b.diag.error(loc, f"joint '{j}' is fixed; it has no velocity to limit", name=j)
            elif c is not None:
                b.diag.error(
                    loc,
                    f"joint '{j}' has {c.type.dof_count} degrees of freedom; velocity limits "
                    "apply to 1-DOF joints",
                    name=j,
                )
            else:
                b.diag.not_found(loc, "actuated 1-DOF joint", j, one_dof, f"robot '{b.spec.name}'")
            continue
        dof = b.world.degrees_of_freedom[one_dof[j].dofs[0]]
        if v > dof.velocity:
            b.diag.warning(
                loc,
                f"{exact(v)} is above the URDF's velocity limit {exact(dof.velocity)} of "
                f"'{j}'; limits only tighten, so it has no effect",
            )
        caps[dof.name] = v
    return caps


def srdf_state_values(b: Build, gs: GroupState) -> dict[str, float]:
    """The 1-DOF values of an SRDF group state a spec imports, mimic joints taken out.

    Joints the URDF lacks are left out: the SRDF check warns about each at its own line, so the
    spec's ``import_srdf_group_states`` line does not collect one error per joint. MoveIt group
    states list mimic joints beside their leaders (Baxter's fingers); a spec state sets only
    leaders. A mimic value that agrees with its leader's is dropped silently; one
    that disagrees (or whose leader is absent) is dropped with a warning at the SRDF's line.
    """
    values = {j: v[0] for j, v in gs.joint_values if len(v) == 1}
    lines = dict(zip((j for j, _ in gs.joint_values), gs.joint_lines, strict=False))
    out: dict[str, float] = {}
    for name, value in values.items():
        if not b.world.has_connection(name):
            continue  # warned at the SRDF's line already; MoveIt ignores it the same way
        mimic = b.world.get_connection_by_name(name).mimic
        if mimic is None:
            out[name] = value
            continue
        leader = values.get(mimic.leader)
        if leader is not None and abs(mimic.multiplier * leader + mimic.offset - value) <= 1e-6:
            continue
        expected = "" if leader is None else f" ({mimic.multiplier * leader + mimic.offset:g})"
        b.diag.add(
            SrdfError(
                f"group_state '{gs.name}' sets joint '{name}' to {value:g}, but it mimics "
                f"'{mimic.leader}'{expected}; the value is ignored",
                file=b.srdf.file if b.srdf is not None else None,
                line=lines.get(name, gs.line),
                kind="joint",
                name=name,
                suggestions=(mimic.leader,),
                severity="warning",
            )
        )
    return out


def check_controlled(b: Build, robot_joints: list[Connection], names: Sequence[str]) -> None:
    """``controlled_joints``: each an actuated joint of the robot, or the reason it is not.

    A joint of the URDF that is a mimic, fixed or outside the robot is named as such (with the
    leader to control instead), not as "not found": the name is right, the choice is not.
    """
    active = {c.name for c in robot_joints if c.is_active}
    own = {c.name for c in robot_joints}
    for i, j in enumerate(names):
        if j in active:
            continue
        loc: Loc = ("controlled_joints", i)
        c = b.world.get_connection_by_name(j) if b.world.has_connection(j) else None
        if c is not None and c.mimic is not None:
            leader = c.mimic.leader
            b.diag.error(
                loc,
                f"'{j}' is a mimic joint of '{leader}' (x{exact(c.mimic.multiplier)}"
                f"{'+' if c.mimic.offset >= 0 else ''}{exact(c.mimic.offset)}): it has no "
                f"actuator of its own; control '{leader}' instead",
                name=j,
                suggestions=(leader,),
            )
        elif c is not None and c.is_fixed:
            b.diag.error(loc, f"joint '{j}' is fixed; only a moving joint is controlled", name=j)
        elif c is not None and c.name not in own and b.robot_root is not None:
            b.diag.error(
                loc,
                f"joint '{j}' is not a joint of robot '{b.spec.name}' (it is not below the root "
                f"'{b.robot_root.name}')",
                name=j,
            )
        else:
            b.diag.not_found(loc, "actuated joint", j, sorted(active), f"robot '{b.spec.name}'")
