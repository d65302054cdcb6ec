"""One spec entry per SDT part kind for ``migrate sdt``: end effectors, cameras, velocity limits.

Why apart from :mod:`robotspec.interop.sdt.migrate`: that module runs SDT's class and lays out
the spec; each function here turns one kind of built SDT part (duck-typed, no SDT import) into
the YAML-ready data a spec writes for it, and notes what the spec cannot say.
"""

from __future__ import annotations

from typing import Any

from robotspec.interop.sdt.migrate_parts import finger_names, name_of, vector3

__all__ = ["camera_entry", "end_effector_entry", "velocity_limits"]


def _finger(f: Any) -> dict[str, str]:
    return {"root": name_of(f.root), "tip": name_of(f.tip)}


def end_effector_entry(
    part: Any, pname: str, names: dict[int, str], states: dict[str, Any], notes: list[str]
) -> dict[str, Any]:
    """A manipulator: two fingers a parallel gripper, more a hand, none (or one) generic.

    Only the orientation is written: SDT's ``front_facing_axis`` is its own derivation from
    it (docs/sdt.md says where SDT's derivation and robotspec's differ).
    """
    q = part.front_facing_orientation.to_np()
    m: dict[str, Any] = {
        "type": "generic",
        "root": name_of(part.root),
        "tool_frame": name_of(part.tool_frame),
        "front_facing_orientation": [float(x) for x in q[:4]],
        "states": states,
    }
    fingers = list(getattr(part, "fingers", []))
    if len(fingers) == 2:
        thumb = part.thumb
        (other,) = [f for f in fingers if f is not thumb]
        m.update(type="parallel_gripper", thumb=_finger(thumb), finger=_finger(other))
    elif len(fingers) > 2:
        thumb = part.thumb
        short = finger_names([names.get(id(f)) or name_of(f.root) for f in fingers])
        named: dict[str, Any] = {}
        for f, key in zip(fingers, short, strict=True):
            if f is thumb:
                continue
            key = key if key != "thumb" else name_of(f.root)
            while key in named:
                key += "_"
            named[key] = _finger(f)
        m.update(type="hand", thumb=_finger(thumb), fingers=named)
    elif fingers:
        notes.append(
            f"{pname}: one finger; a spec's hand has a thumb and another finger, so it "
            "is a generic manipulator"
        )
    return m


def camera_entry(part: Any) -> dict[str, Any]:
    """A camera sensor: its body, axis, field of view, heights and whether it is the default."""
    fov = part.field_of_view
    return {
        "type": "camera",
        "body": name_of(part.root),
        "forward_facing_axis": vector3(part.forward_facing_axis),
        "field_of_view": {
            "vertical": float(fov.vertical_angle),
            "horizontal": float(fov.horizontal_angle),
        },
        "minimal_height": float(part.minimal_height),
        "maximal_height": float(part.maximal_height),
        "default": bool(part.default_camera),
    }


def velocity_limits(
    robot: Any, before: dict[str, float | None], notes: list[str]
) -> dict[str, Any] | None:
    """The limits SDT's ``_setup_velocity_limits`` tightened, as ``velocity_limits:``.

    A limit SDT raises is noted and left as the URDF's (robotspec's limits only tighten); a
    mimic joint's limit is its leader's. The most common value is the default.
    """
    limits: dict[str, float] = {}
    for c in robot._one_dof_connections:
        after, was = c.raw_dof.limits.upper.velocity, before.get(name_of(c))
        if c.raw_dof.name.name != c.name.name or after is None or after == was:
            continue  # a mimic joint (its leader carries the limit), or unchanged
        if was is not None and after > was:
            notes.append(
                f"velocity limit of '{name_of(c)}': SDT raises it from {was} to {after}; "
                "robotspec's limits only tighten, so the URDF's stays"
            )
            continue
        limits[name_of(c)] = float(after)
    if not limits:
        return None
    values = list(limits.values())
    common = max(set(values), key=values.count)
    return {"default": common, "joints": {j: v for j, v in limits.items() if v != common}}
