"""Cross-checks of SRDF records: group cycles, references inside the file, names in the URDF.

Problems are returned, not raised: the compiler turns them into warnings (an SRDF often outlives
its URDF) while a spec that *uses* a stale name still fails on its own line.
"""

from __future__ import annotations

from collections.abc import Collection, Iterator

from robotspec.description.srdf import (
    DisabledCollision,
    EnabledCollision,
    Group,
    Srdf,
    SrdfNotFoundError,
)
from robotspec.errors import (
    RobotSpecError,
    SrdfError,
)

__all__ = ["by_line", "check_srdf_against", "check_srdf_references", "group_cycle_errors"]


def by_line(err: RobotSpecError) -> int:
    """Sort key: problems in file order, those without a line last."""
    return err.line if err.line is not None else 1 << 62


def group_cycle_errors(srdf: Srdf) -> list[RobotSpecError]:
    """One error per cycle of groups containing each other, at the cycle's first group."""
    by_name = {g.name: g for g in srdf.groups}
    order = {name: i for i, name in enumerate(by_name)}
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    found: dict[tuple[str, ...], Group] = {}

    # Depth-first with an explicit stack (a deep but valid subgroup chain must not recurse).
    for start_name in by_name:
        if start_name in state:
            continue
        path = [start_name]
        state[start_name] = 1
        stack: list[Iterator[str]] = [iter(by_name[start_name].subgroups)]
        while stack:
            sub = next(stack[-1], None)
            if sub is None:
                stack.pop()
                state[path.pop()] = 2
                continue
            if sub not in by_name:
                continue
            if state.get(sub) == 1:
                cycle = path[path.index(sub) :]
                first = min(range(len(cycle)), key=lambda i: order[cycle[i]])
                key = tuple(cycle[first:] + cycle[:first])
                found.setdefault(key, by_name[key[0]])
            elif sub not in state:
                state[sub] = 1
                path.append(sub)
                stack.append(iter(by_name[sub].subgroups))
    return [
        SrdfError(
            f"groups contain each other: {' -> '.join((*cycle, cycle[0]))}",
            file=srdf.file,
            line=group.line,
            kind="group",
            name=group.name,
        )
        for cycle, group in found.items()
    ]


def check_srdf_references(srdf: Srdf) -> list[RobotSpecError]:
    """The SRDF's references to groups it does not define, in file order.

    A group state without a group counts too: MoveIt needs the group to know what the state sets.
    ``parse_srdf_bytes`` raises these in strict mode; this lists them for files read leniently.
    """
    names = srdf.group_names
    where = srdf._where()
    out: list[RobotSpecError] = []

    def missing(name: str, role: str, line: int | None) -> None:
        out.append(
            SrdfNotFoundError(
                "group", name, names, where=f"{where} ({role})", file=srdf.file, line=line
            )
        )

    for g in srdf.groups:
        lines = g.subgroup_lines or (g.line,) * len(g.subgroups)
        for sub, line in zip(g.subgroups, lines, strict=False):
            if sub not in names:
                missing(sub, f"subgroup of group '{g.name}'", line)
    for s in srdf.group_states:
        if s.group is None:
            out.append(
                SrdfError(
                    f"group_state '{s.name}' has no group attribute",
                    file=srdf.file,
                    line=s.line,
                    kind="group_state",
                    name=s.name,
                )
            )
        elif s.group not in names:
            missing(s.group, f"group of group_state '{s.name}'", s.line)
    for e in srdf.end_effectors:
        if e.group not in names:
            missing(e.group, f"group of end_effector '{e.name}'", e.line)
        if e.parent_group is not None and e.parent_group not in names:
            missing(e.parent_group, f"parent_group of end_effector '{e.name}'", e.line)
    out.sort(key=by_line)
    return out


# --------------------------------------------------------------------------------------------
# Checking against the URDF


def check_srdf_against(
    srdf: Srdf, links: Collection[str], joints: Collection[str], *, urdf_name: str
) -> list[RobotSpecError]:
    """Every link and joint name the SRDF uses that the URDF lacks, in file order.

    Why virtual joints count as joints: MoveIt adds them to the robot model, so groups and group
    states may name them (HSRB's ``world_joint``). A virtual joint's ``parent_frame`` is outside
    the robot and is not checked. Identical messages on one line are reported once.
    """
    # Lists keep the URDF's order, so that equally close suggestions always come in one order.
    link_pool = list(dict.fromkeys(links))
    joint_pool = list(dict.fromkeys([*joints, *(v.name for v in srdf.virtual_joints)]))
    link_set, joint_set = set(link_pool), set(joint_pool)
    found: list[RobotSpecError] = []

    def need(kind: str, name: str, line: int | None) -> None:
        pool = link_pool if kind == "link" else joint_pool
        known = link_set if kind == "link" else joint_set
        if name not in known:
            found.append(
                SrdfNotFoundError(kind, name, pool, where=urdf_name, file=srdf.file, line=line)
            )

    def lines(own: tuple[int | None, ...], count: int, default: int | None) -> list[int | None]:
        return list(own) if len(own) == count else [default] * count

    for g in srdf.groups:
        for name, line in zip(g.joints, lines(g.joint_lines, len(g.joints), g.line), strict=True):
            need("joint", name, line)
        for name, line in zip(g.links, lines(g.link_lines, len(g.links), g.line), strict=True):
            need("link", name, line)
        for c in g.chains:
            need("link", c.base_link, c.line if c.line is not None else g.line)
            need("link", c.tip_link, c.line if c.line is not None else g.line)
    for s in srdf.group_states:
        state_lines = lines(s.joint_lines, len(s.joint_values), s.line)
        for (name, _), line in zip(s.joint_values, state_lines, strict=True):
            need("joint", name, line)
    for e in srdf.end_effectors:
        need("link", e.parent_link, e.line)
    for v in srdf.virtual_joints:
        need("link", v.child_link, v.line)
    for p in srdf.passive_joints:
        need("joint", p.name, p.line)
    for d in srdf.disable_default_collisions:
        need("link", d.link, d.line)
    pairs: list[DisabledCollision | EnabledCollision] = [
        *srdf.disabled_collisions,
        *srdf.enabled_collisions,
    ]
    for pair in pairs:
        need("link", pair.link1, pair.line)
        need("link", pair.link2, pair.line)
    seen: set[tuple[int | None, str]] = set()
    unique: list[RobotSpecError] = []
    for err in found:
        key = (err.line, err.message)
        if key not in seen:
            seen.add(key)
            unique.append(err)
    unique.sort(key=by_line)
    return unique
