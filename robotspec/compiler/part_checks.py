"""Checks that compare parts of a spec with each other: copy-paste, defaults, carriers, lenses.

Why a module of its own: each check here reads two or more parts at once (two chains over the
same links, two manipulators on one tool frame, two default cameras), where the first pass checks
one part at a time. Policy: an error when the spec is provably wrong (two arms over the same
links; two default cameras, of which the first would win silently), a warning when it is only
suspicious (a camera frame named like a laser).
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from robotspec.compiler.context import Build
from robotspec.compiler.parts import CameraValues
from robotspec.diagnostics import Loc
from robotspec.model.geometry import Mesh
from robotspec.model.world import Body
from robotspec.spec.models import CameraSpec

__all__ = ["check_parts", "non_camera_hint"]

#: Words in a frame's (or its mesh file's) name that say it is not a camera.
_NOT_CAMERA = {
    "laser": "a laser scanner",
    "lidar": "a lidar",
    "scan": "a laser scanner",
    "scanner": "a laser scanner",
    "hokuyo": "a Hokuyo laser scanner",
    "urg": "a Hokuyo laser scanner",
    "sick": "a SICK laser scanner",
    "velodyne": "a Velodyne lidar",
    "ouster": "an Ouster lidar",
    "rplidar": "a lidar",
    "sonar": "a sonar",
    "imu": "an IMU",
    "gyro": "an IMU",
    "accelerometer": "an IMU",
    "inertial": "an IMU",
}


def _words(text: str) -> list[str]:
    return [w for w in re.split(r"[^a-z]+", text.lower()) if w]


def non_camera_hint(body: Body) -> str | None:
    """Why ``body`` looks like a laser or IMU frame (its name or mesh file), else None."""
    for w in _words(body.name):
        if w in _NOT_CAMERA:
            return f"its name says {_NOT_CAMERA[w]} ('{w}')"
    for shape in body.visuals:
        if isinstance(shape.geometry, Mesh):
            file = shape.geometry.uri.rsplit("/", 1)[-1]
            for w in _words(file.rsplit(".", 1)[0]):
                if w in _NOT_CAMERA:
                    return f"its mesh '{file}' is {_NOT_CAMERA[w]}"
    return None


def check_parts(b: Build, cameras: Mapping[str, CameraValues]) -> None:
    """Every cross-part check; problems go to ``b.diag``."""
    _duplicate_chains(b)
    _duplicate_tools(b)
    _cameras(b, cameras)
    _uncarried_sensors(b)


def _duplicate_chains(b: Build) -> None:
    spec = b.spec
    seen: dict[tuple[str, str], tuple[str, Loc]] = {}
    parts: list[tuple[str, Loc, str | None, str | None]] = []
    if spec.torso is not None:
        parts.append(("the torso", ("torso",), spec.torso.root, spec.torso.tip))
    if spec.neck is not None:
        parts.append(("the neck", ("neck",), spec.neck.root, spec.neck.tip))
    for name, c in spec.chains.items():
        root, tip = c.root, c.tip
        if c.group is not None and b.srdf is not None:
            group = next((g for g in b.srdf.groups if g.name == c.group), None)
            if group is not None and len(group.chains) == 1:
                root, tip = group.chains[0].base_link, group.chains[0].tip_link
        parts.append((f"chain '{name}'", ("chains", name), root, tip))
    for what, loc, root, tip in parts:
        if root is None or tip is None:
            continue
        key = (root, tip)
        if key in seen:
            other, _ = seen[key]
            b.diag.error(
                loc,
                f"{what} has the same links as {other} ('{root}' -> '{tip}'); a copy-paste? "
                "give each part its own root and tip",
                name=root,
            )
        else:
            seen[key] = (what, loc)


def _duplicate_tools(b: Build) -> None:
    by_tool: dict[str, str] = {}
    for name, m in b.spec.manipulators.items():
        if m.tool_frame in by_tool:
            b.diag.error(
                ("manipulators", name, "tool_frame"),
                f"manipulators '{by_tool[m.tool_frame]}' and '{name}' share the tool frame "
                f"'{m.tool_frame}'; one gripper has one tool frame",
                name=m.tool_frame,
            )
        else:
            by_tool[m.tool_frame] = name


def _cameras(b: Build, cameras: Mapping[str, CameraValues]) -> None:
    by_body: dict[str, str] = {}
    default: str | None = None
    for name, s in b.spec.sensors.items():
        if not isinstance(s, CameraSpec):
            continue
        loc: Loc = ("sensors", name)
        if s.body in by_body:
            b.diag.warning(
                (*loc, "body"),
                f"cameras '{by_body[s.body]}' and '{name}' are on the same frame '{s.body}' "
                "(a copy-paste?)",
                name=s.body,
            )
        else:
            by_body[s.body] = name
        if s.default:
            if default is not None:
                file, line, _ = b.loaded.position(("sensors", default, "default"))
                at = f" ({file.rsplit('/', 1)[-1]}:{line})" if line is not None else ""
                b.diag.error(
                    (*loc, "default"),
                    f"cameras '{default}'{at} and '{name}' are both the default camera; the "
                    "first would win silently: mark one",
                    name=name,
                )
            else:
                default = name
        v = cameras.get(name)
        if v is not None and v.vertical > v.horizontal:
            b.diag.warning(
                (*loc, "field_of_view") if s.field_of_view is not None else loc,
                f"the field of view is taller than wide (vertical {v.vertical:g} > horizontal "
                f"{v.horizontal:g} rad): swapped? a landscape image is wider than tall",
            )
        if b.world.has_body(s.body):
            hint = non_camera_hint(b.world.get_body_by_name(s.body))
            if hint is not None:
                b.diag.warning(
                    (*loc, "body"),
                    f"'{s.body}' is declared as a camera, but {hint}; declare it as "
                    "type: generic with a kind",
                    name=s.body,
                )


def _uncarried_sensors(b: Build) -> None:
    spec = b.spec
    carried = {s for c in spec.chains.values() for s in c.sensors}
    if spec.neck is not None:
        carried.update(spec.neck.sensors)
    for name in spec.sensors:
        if name not in carried:
            b.diag.warning(
                ("sensors", name),
                f"sensor '{name}' is on no chain (no chain and no neck carries it)",
            )
