"""Checks of the spec's parts: manipulators, cameras, chains and who carries which sensor."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from robotspec.compiler.context import AXIS_TOL, Build, moved_by, subtree_joints
from robotspec.compiler.joints import check_states
from robotspec.diagnostics import Loc
from robotspec.model.geometry import UNIT_TOL, unit_norm
from robotspec.model.world import Body
from robotspec.semantic import front_facing_axis_of
from robotspec.spec.models import (
    CameraSpec,
    ChainSpec,
    FingerSpec,
    GenericManipulatorSpec,
    HandSpec,
    ParallelGripperSpec,
)

__all__ = ["CameraValues", "camera_values", "chain_ends", "check_manipulator", "use_sensor"]


def check_manipulator(
    b: Build, name: str, m: ParallelGripperSpec | HandSpec | GenericManipulatorSpec
) -> tuple[Body, Body] | None:
    """Root, tool frame, fingers and axis of one manipulator; its (root, tool) when found."""
    loc: Loc = ("manipulators", name)
    root = b.body((*loc, "root"), m.root)
    tool = b.body((*loc, "tool_frame"), m.tool_frame)
    if root is not None and tool is not None and not b.world.is_ancestor(root, tool):
        b.diag.error(
            (*loc, "tool_frame"),
            f"tool frame '{tool.name}' is not below the manipulator root '{root.name}'",
            name=tool.name,
        )
    q = m.front_facing_orientation
    norm = unit_norm(q)
    if abs(norm - 1.0) > UNIT_TOL:
        b.diag.error(
            (*loc, "front_facing_orientation"),
            f"must be a unit quaternion [x, y, z, w], its norm is {norm:.4g}",
        )
    elif m.front_facing_axis is not None:
        axis = m.front_facing_axis
        if abs(unit_norm(axis) - 1.0) > AXIS_TOL:
            b.diag.error(
                (*loc, "front_facing_axis"),
                f"must be a unit vector, its norm is {unit_norm(axis):.4g}",
            )
        else:
            derived = front_facing_axis_of(q)
            if np.linalg.norm(np.subtract(axis, derived)) > AXIS_TOL:
                b.diag.error(
                    (*loc, "front_facing_axis"),
                    f"{list(axis)} disagrees with front_facing_orientation, whose axis "
                    f"(R^T x) is {[round(x, 6) for x in derived]}; omit the axis to derive it",
                )
    if isinstance(m, ParallelGripperSpec):
        for role in ("finger", "thumb"):
            f: FingerSpec = getattr(m, role)
            floc = (*loc, role)
            froot = b.body((*floc, "root"), f.root)
            ftip = b.body((*floc, "tip"), f.tip)
            if froot is not None and root is not None and not b.world.is_ancestor(root, froot):
                b.diag.error(
                    (*floc, "root"),
                    f"{role} root '{froot.name}' is not below the gripper root '{root.name}'",
                    name=froot.name,
                )
            b.chain_ok(floc, f"{role} of '{name}'", froot, ftip)
        if m.finger.root == m.thumb.root and m.finger.tip == m.thumb.tip:
            b.diag.error((*loc, "thumb"), "finger and thumb are the same chain")
    elif isinstance(m, HandSpec):
        _check_hand(b, name, m, root)
    if root is None or tool is None:
        return None
    allowed = moved_by(b.world, subtree_joints(b.world, root))
    b.add_states(
        name, check_states(b, (*loc, "states"), f"manipulator '{name}'", m.states, allowed)
    )
    return root, tool


def _check_hand(b: Build, name: str, m: HandSpec, root: Body | None) -> None:
    """A hand's thumb and fingers: found, below the hand's root, tips below roots, disjoint."""
    loc: Loc = ("manipulators", name)
    links: list[tuple[str, set[str]]] = []
    roles: list[tuple[Loc, str, FingerSpec]] = [((*loc, "thumb"), "thumb", m.thumb)]
    roles += [((*loc, "fingers", f), f"finger '{f}'", spec) for f, spec in m.fingers.items()]
    for floc, role, f in roles:
        froot = b.body((*floc, "root"), f.root)
        ftip = b.body((*floc, "tip"), f.tip)
        if froot is not None and root is not None:
            if froot.index == root.index or not b.world.is_ancestor(root, froot):
                b.diag.error(
                    (*floc, "root"),
                    f"{role} root '{froot.name}' is not below the hand root '{root.name}'"
                    + (
                        " (a finger starts at its first link past the palm)"
                        if froot.index == root.index
                        else ""
                    ),
                    name=froot.name,
                )
                continue
        if not b.chain_ok(floc, f"{role} of '{name}'", froot, ftip):
            continue
        assert froot is not None and ftip is not None
        own = {froot.name} | {
            b.world.bodies[c.child].name for c in b.world.compute_chain_of_connections(froot, ftip)
        }
        for other, theirs in links:
            shared = sorted(own & theirs)
            if shared:
                b.diag.error(
                    floc,
                    f"{role} of '{name}' shares links with the {other} ({', '.join(shared)}); "
                    "the fingers of a hand are disjoint chains",
                    name=shared[0],
                )
                break
        links.append((role, own))


@dataclass(frozen=True)
class CameraValues:
    """A camera's values after its preset and the spec's own fields are merged."""

    forward_facing_axis: tuple[float, float, float]
    horizontal: float
    vertical: float
    minimal_height: float
    maximal_height: float


def _floats(value: object, n: int) -> tuple[float, ...] | None:
    if isinstance(value, (list, tuple)) and len(value) == n:
        try:
            return tuple(float(x) for x in value)
        except (TypeError, ValueError):
            return None
    return None


def _float(value: object, default: float) -> float:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    return default


def camera_values(b: Build, name: str, s: CameraSpec) -> CameraValues | None:
    """Merge preset and spec; None (after recording why) when the camera is unusable."""
    loc: Loc = ("sensors", name)
    preset: Mapping[str, object] = {}
    preset_missing = False
    if s.preset is not None:
        if s.preset not in b.presets:
            b.diag.not_found(
                (*loc, "preset"), "camera preset", s.preset, b.presets, "templates/cameras.yaml"
            )
            preset_missing = True
        else:
            preset = b.presets[s.preset]
    fov_h = fov_v = None
    if s.field_of_view is not None:
        fov_h, fov_v = s.field_of_view.horizontal, s.field_of_view.vertical
    elif isinstance(preset.get("field_of_view"), Mapping):
        pf = preset["field_of_view"]
        assert isinstance(pf, Mapping)
        fov_h, fov_v = _float(pf.get("horizontal"), 0.0), _float(pf.get("vertical"), 0.0)
    ok = True
    if fov_h is None or fov_v is None:
        # An unknown preset was already reported; its missing values are not a second problem.
        if not preset_missing:
            b.diag.error(loc, f"camera '{name}' has no field_of_view (give it or a preset)")
        ok = False
    else:
        for key, a in (("horizontal", fov_h), ("vertical", fov_v)):
            if not (0.0 < a < math.pi):
                b.diag.error(
                    (*loc, "field_of_view", key), f"angle must lie in (0, pi) radians, got {a:g}"
                )
                ok = False
    axis3 = s.forward_facing_axis or _floats(preset.get("forward_facing_axis"), 3) or (0, 0, 1)
    axis = (float(axis3[0]), float(axis3[1]), float(axis3[2]))
    if abs(unit_norm(axis) - 1.0) > AXIS_TOL:
        b.diag.error(
            (*loc, "forward_facing_axis"),
            f"must be a unit vector, its norm is {unit_norm(axis):.4g}",
        )
        ok = False
    elif s.body.endswith("_optical_frame") and np.linalg.norm(np.subtract(axis, (0, 0, 1))) > 1e-6:
        b.diag.warning(
            (*loc, "forward_facing_axis"),
            f"'{s.body}' is an optical frame (REP 103), whose viewing axis is +z, "
            f"but the axis is {list(axis)}",
        )
    lo = (
        s.minimal_height
        if s.minimal_height is not None
        else _float(preset.get("minimal_height"), 0.0)
    )
    hi = (
        s.maximal_height
        if s.maximal_height is not None
        else _float(preset.get("maximal_height"), 1.0)
    )
    if lo > hi:
        b.diag.error(
            (*loc, "minimal_height"), f"minimal_height {lo:g} is greater than maximal_height {hi:g}"
        )
        ok = False
    if not ok or fov_h is None or fov_v is None:
        return None
    return CameraValues(axis, fov_h, fov_v, lo, hi)


def use_sensor(b: Build, loc: Loc, s_name: str, owner: str, used: dict[str, str]) -> None:
    """Record that ``owner`` carries sensor ``s_name``; a sensor has one carrier."""
    if s_name not in b.spec.sensors:
        b.diag.not_found(loc, "sensor", s_name, b.spec.sensors, "the spec's sensors")
    elif s_name in used:
        b.diag.error(loc, f"sensor '{s_name}' is already carried by {used[s_name]}")
    else:
        used[s_name] = owner


def chain_ends(b: Build, name: str, c: ChainSpec) -> tuple[Body, Body] | None:
    """A chain's (root, tip) from root/tip names or from its SRDF group's single chain."""
    loc: Loc = ("chains", name)
    if c.group is not None:
        if c.root is not None or c.tip is not None:
            b.diag.error(loc, "give either an SRDF group or root and tip, not both")
            return None
        if b.srdf is None:
            b.diag.error((*loc, "group"), "names an SRDF group, but the spec has no srdf")
            return None
        groups = {g.name: g for g in b.srdf.groups}
        if c.group not in groups:
            b.diag.not_found(
                (*loc, "group"),
                "SRDF group",
                c.group,
                groups,
                b.srdf.file.rsplit("/", 1)[-1] if b.srdf.file else "the SRDF",
            )
            return None
        group = groups[c.group]
        if len(group.chains) != 1:
            b.diag.error(
                (*loc, "group"),
                f"SRDF group '{c.group}' has {len(group.chains)} "
                "chains; a chain spec needs a group with exactly one <chain>",
            )
            return None
        base, tip = group.chains[0].base_link, group.chains[0].tip_link
        r, t = b.body((*loc, "group"), base), b.body((*loc, "group"), tip)
    else:
        if c.root is None or c.tip is None:
            b.diag.error(loc, "a chain needs root and tip, or an SRDF group")
            return None
        r, t = b.body((*loc, "root"), c.root), b.body((*loc, "tip"), c.tip)
    if r is None or t is None:
        return None
    return r, t
