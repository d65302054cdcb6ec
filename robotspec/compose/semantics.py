"""A part spec's semantics (chains, manipulators, sensors, states, ...) in the composed names.

Why on plain data: the composed spec is validated again as a whole (:class:`RobotSpec`) once all
parts are merged, so the renaming only has to rewrite names, field by field, and keep the YAML
positions (``marks``) of each renamed entry so errors still point into the part's own file.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from robotspec.compose.naming import PartNames
from robotspec.compose.urdf_merge import TreeFacts
from robotspec.files.yamlio import LocatedYaml

__all__ = ["NAMED_SECTIONS", "remap_marks", "rename_semantics"]

#: Spec sections whose keys are names global in the robot (so they get the prefix).
NAMED_SECTIONS = ("chains", "manipulators", "sensors", "states")


def _finger(f: Mapping[str, Any], n: PartNames) -> dict[str, Any]:
    return {**f, "root": n.link(f["root"]), "tip": n.link(f["tip"])}


def _chain_like(c: Mapping[str, Any], n: PartNames) -> dict[str, Any]:
    out = dict(c)
    for key in ("root", "tip", "pitch_body", "yaw_body"):
        if out.get(key) is not None:
            out[key] = n.link(out[key])
    if out.get("group") is not None:
        out["group"] = n.name(out["group"])
    if out.get("manipulator") is not None:
        out["manipulator"] = n.name(out["manipulator"])
    if "sensors" in out:
        out["sensors"] = [n.name(s) for s in out["sensors"]]
    if "states" in out:
        out["states"] = n.states(out["states"])
    return out


def rename_semantics(data: Mapping[str, Any], n: PartNames, facts: TreeFacts) -> dict[str, Any]:
    """The semantic sections of a part's spec data, renamed; files, name and root are dropped.

    A part's default velocity cap becomes per-joint caps on the part's commanded joints (where
    it tightens the URDF's limit), so it does not leak onto other parts' joints.
    """
    out: dict[str, Any] = {}
    for key in ("torso", "neck"):
        if data.get(key) is not None:
            out[key] = _chain_like(data[key], n)
    if "chains" in data:
        out["chains"] = {n.name(k): _chain_like(v, n) for k, v in data["chains"].items()}
    if "manipulators" in data:
        manips: dict[str, Any] = {}
        for k, m in data["manipulators"].items():
            mm = dict(m)
            mm["root"] = n.link(m["root"])
            mm["tool_frame"] = n.link(m["tool_frame"])
            for f in ("finger", "thumb"):
                if f in mm:
                    mm[f] = _finger(mm[f], n)
            if isinstance(mm.get("fingers"), Mapping):  # a hand's named fingers
                mm["fingers"] = {k: _finger(f, n) for k, f in mm["fingers"].items()}
            if "states" in mm:
                mm["states"] = n.states(mm["states"])
            manips[n.name(k)] = mm
        out["manipulators"] = manips
    if "sensors" in data:
        out["sensors"] = {
            n.name(k): {**s, "body": n.link(s["body"])} for k, s in data["sensors"].items()
        }
    if "states" in data:
        out["states"] = {n.name(k): n.joint_values(v) for k, v in data["states"].items()}
    limits = data.get("velocity_limits")
    if limits:
        joints = {n.joint(j): v for j, v in limits.get("joints", {}).items()}
        default = limits.get("default")
        if default is not None:
            for j in facts.driven_joints:
                if default < facts.velocity_limits.get(j, float("inf")):
                    joints.setdefault(n.joint(j), default)
        out["velocity_limits"] = {"joints": joints}
    if data.get("controlled_joints") is not None:
        out["controlled_joints"] = n.joints(data["controlled_joints"])
    collision = data.get("collision")
    if collision and collision.get("disabled_bodies"):
        out["collision"] = {"disabled_bodies": n.links(collision["disabled_bodies"])}
    if data.get("import_srdf_group_states"):
        out["import_srdf_group_states"] = True
    return out


def remap_marks(doc: LocatedYaml, n: PartNames) -> LocatedYaml:
    """A part document whose positions are keyed by the composed names of its entries."""

    def loc(path: tuple[str | int, ...]) -> tuple[str | int, ...]:
        if len(path) >= 2 and path[0] in NAMED_SECTIONS and isinstance(path[1], str):
            return (path[0], n.name(path[1]), *path[2:])
        return path

    def semantic(path: tuple[str | int, ...]) -> bool:
        # The part's files, name, root and drive are not the composed robot's: an error about
        # those must point at the composed spec, not at a part's line.
        return bool(path) and path[0] not in _NOT_CARRIED

    return LocatedYaml(
        data=doc.data,
        file=doc.file,
        marks={loc(k): v for k, v in doc.marks.items() if semantic(k)},
        key_marks={loc(k): v for k, v in doc.key_marks.items() if semantic(k)},
    )


_NOT_CARRIED = frozenset(
    {"robotspec", "name", "extends", "description", "parts", "root", "drive", "collision"}
)
