"""One walk over a URDF element tree: every element checked, with its line, and made a record.

Why one walk: the URDF was once read three times (a checker, yourdfpy's private element parser,
and a walk that zipped the two to recover line numbers). This walk reads every attribute the
world needs exactly once, refuses what a URDF parser would silently accept (``nan`` limits, a
dangling link name, a missing ``<parent>``), and keeps each element's line for the messages and
the records. All problems of a file are raised together, in the package's own error types.

The records follow the URDF specification's defaults the way urdfdom and yourdfpy read them:
an absent ``<origin>`` is the identity, an absent ``<axis>`` is ``1 0 0``, an absent ``<mimic>``
multiplier is 1 and offset 0, a ``<mass>`` without ``value`` is 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from lxml import etree

from robotspec.errors import (
    DescriptionError,
    DuplicateNameError,
    NotFoundError,
    RobotSpecError,
    raise_collected,
)
from robotspec.exact import exact
from robotspec.files.xmlsafe import line_of
from robotspec.model.geometry import Matrix
from robotspec.model.rotations import rpy_to_matrix

__all__ = [
    "JOINT_TYPES",
    "MESH_SCALE",
    "JointRecord",
    "LinkRecord",
    "ShapeRecord",
    "UrdfRecords",
    "check_urdf_tree",
    "geometry_element",
    "parse_floats",
    "walk_urdf",
]

JOINT_TYPES = ("fixed", "revolute", "continuous", "prismatic", "floating", "planar")
#: The sizes a mesh scale factor may have (its sign mirrors). Why bounds: ``1e308`` overflows
#: every vertex to infinity and ``1e-300`` collapses a mesh to a point (every distance zero);
#: real robots use 0.001 (millimetres to metres) to 1, and a factor of a million either way
#: covers any unit.
MESH_SCALE = (1e-6, 1e6)


@dataclass(frozen=True, slots=True)
class ShapeRecord:
    """A ``<visual>`` or ``<collision>``: its shape element, pose, name and colour."""

    element: etree._Element
    shape: etree._Element
    origin: Matrix
    name: str | None
    rgba: tuple[float, float, float, float] | None
    #: The shape's numbers: box size, (radius, length), (radius,), or the mesh scale.
    values: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class LinkRecord:
    """A ``<link>``."""

    name: str
    element: etree._Element
    mass: float | None
    visuals: tuple[ShapeRecord, ...]
    collisions: tuple[ShapeRecord, ...]


@dataclass(frozen=True, slots=True)
class JointRecord:
    """A ``<joint>``; limits are ``None`` where the file gives none."""

    name: str
    element: etree._Element
    type: str
    parent: str
    child: str
    origin: Matrix
    axis: tuple[float, float, float]
    lower: float | None
    upper: float | None
    velocity: float | None
    effort: float | None
    #: (leader joint, multiplier, offset), or None.
    mimic: tuple[str, float, float] | None
    #: Whether the joint has a ``<limit>`` element at all.
    has_limit: bool


@dataclass(frozen=True, slots=True)
class UrdfRecords:
    """Everything of a URDF the world is built from, in file order."""

    name: str
    links: tuple[LinkRecord, ...]
    joints: tuple[JointRecord, ...]


def parse_floats(
    text: str | None, count: int, what: str, el: etree._Element, file: str
) -> list[float]:
    """Parse exactly ``count`` finite numbers from an attribute value, or raise a located error."""
    if text is None:
        raise DescriptionError(f"{what} is missing", file=file, line=line_of(el))
    parts = (text.replace(",", " ") if "," in text else text).split()
    if len(parts) == count:  # the common case, checked at once
        try:
            fast = [float(p) for p in parts]
        except ValueError:
            fast = []
        if fast and all(map(math.isfinite, fast)):
            return fast
    if len(parts) != count:
        shown = text if len(text) <= 80 else f"{text[:80]}..."
        raise DescriptionError(
            f"{what} must have {count} number{'s' if count != 1 else ''}, got '{shown}'",
            file=file,
            line=line_of(el),
        )
    out: list[float] = []
    for p in parts:
        try:
            v = float(p)
        except ValueError:
            shown = p if len(p) <= 40 else f"{p[:40]}..."
            raise DescriptionError(
                f"{what}: '{shown}' is not a number", file=file, line=line_of(el)
            ) from None
        if not math.isfinite(v):
            raise DescriptionError(f"{what} must be finite, got '{p}'", file=file, line=line_of(el))
        out.append(v)
    return out


def geometry_element(geom: etree._Element | None) -> etree._Element | None:
    """The shape element inside ``<geometry>``, skipping comments."""
    if geom is None:
        return None
    return next((c for c in geom if isinstance(c.tag, str)), None)


def _children(el: etree._Element) -> dict[str, etree._Element]:
    """The first child element of each tag (what ``find`` returns), in one pass."""
    out: dict[str, etree._Element] = {}
    for child in el:
        tag = child.tag
        if isinstance(tag, str) and tag not in out:
            out[tag] = child
    return out


_IDENTITY = np.eye(4)
_IDENTITY.setflags(write=False)


class _Walk:
    """The walk's state: the file and the problems found so far."""

    def __init__(self, file: str) -> None:
        self.file = file
        self.errors: list[RobotSpecError] = []

    def error(
        self, message: str, el: etree._Element, *, kind: str | None = None, name: str | None = None
    ) -> None:
        self.errors.append(
            DescriptionError(message, file=self.file, line=line_of(el), kind=kind, name=name)
        )

    def floats(self, el: etree._Element, attr: str, count: int, what: str) -> list[float] | None:
        try:
            return parse_floats(el.get(attr), count, what, el, self.file)
        except DescriptionError as exc:
            self.errors.append(exc)
            return None

    def number(
        self, el: etree._Element, attr: str, what: str, *, required: bool = False
    ) -> float | None:
        if el.get(attr) is None:
            if required:
                self.error(f"{what} is missing", el)
            return None
        got = self.floats(el, attr, 1, what)
        return None if got is None else got[0]

    def origin(self, el: etree._Element | None, what: str) -> Matrix:
        if el is None:
            return _IDENTITY
        xyz = (0.0, 0.0, 0.0)
        rpy = (0.0, 0.0, 0.0)
        if el.get("xyz") is not None:
            got = self.floats(el, "xyz", 3, f"{what}: origin xyz")
            xyz = (got[0], got[1], got[2]) if got else xyz
        if el.get("rpy") is not None:
            got = self.floats(el, "rpy", 3, f"{what}: origin rpy")
            rpy = (got[0], got[1], got[2]) if got else rpy
        if rpy == (0.0, 0.0, 0.0):
            t = np.array(
                [
                    [1.0, 0.0, 0.0, xyz[0]],
                    [0.0, 1.0, 0.0, xyz[1]],
                    [0.0, 0.0, 1.0, xyz[2]],
                    [0.0, 0.0, 0.0, 1.0],
                ]
            )
        else:
            t = np.eye(4)
            t[:3, :3] = rpy_to_matrix(*rpy)
            t[:3, 3] = xyz
        t.setflags(write=False)
        return t

    # ------------------------------------------------------------------------ links
    def link(self, el: etree._Element, name: str) -> LinkRecord:
        mass = None
        inertial = _children(el).get("inertial")
        if inertial is not None:
            mass_el = inertial.find("mass")
            if mass_el is not None:
                m = self.number(mass_el, "value", f"link '{name}': mass")
                if m is not None and m < 0:
                    self.error(f"link '{name}': mass must not be negative, got {m}", mass_el)
                mass = 0.0 if m is None else m
        shapes: dict[str, list[ShapeRecord]] = {"visual": [], "collision": []}
        for shape_el in el:
            out = shapes.get(shape_el.tag) if isinstance(shape_el.tag, str) else None
            if out is not None:
                rec = self.shape(shape_el, str(shape_el.tag), name)
                if rec is not None:
                    out.append(rec)
        return LinkRecord(name, el, mass, tuple(shapes["visual"]), tuple(shapes["collision"]))

    def shape(self, el: etree._Element, kind: str, link: str) -> ShapeRecord | None:
        what = f"link '{link}' {kind}"
        parts = _children(el)
        origin = self.origin(parts.get("origin"), what)
        inner = geometry_element(parts.get("geometry"))
        if inner is None:
            self.error(f"link '{link}': <{kind}> has no geometry", el, kind="link", name=link)
            return None
        values = self.geometry(inner, what)
        rgba = None
        if kind == "visual":
            material = parts.get("material")
            color = None if material is None else material.find("color")
            if color is not None and color.get("rgba") is None:
                rgba = (1.0, 1.0, 1.0, 1.0)  # urdfdom's default colour: opaque white
            elif color is not None:
                got = self.floats(color, "rgba", 4, f"{what}: material color rgba")
                if got is not None:
                    rgba = (got[0], got[1], got[2], got[3])
        if values is None:
            return None
        return ShapeRecord(el, inner, origin, el.get("name"), rgba, values)

    def geometry(self, g: etree._Element, what: str) -> tuple[float, ...] | None:
        tag = g.tag if isinstance(g.tag, str) else ""
        before = len(self.errors)
        values: tuple[float, ...] = ()
        if tag == "box":
            size = self.floats(g, "size", 3, f"{what}: box size")
            if size is not None and min(size) < 0:
                self.error(f"{what}: box size must not be negative", g)
            values = tuple(size or ())
        elif tag in ("cylinder", "capsule"):
            r = self.number(g, "radius", f"{what}: {tag} radius", required=True)
            length = self.number(g, "length", f"{what}: {tag} length", required=True)
            if (r is not None and r < 0) or (length is not None and length < 0):
                self.error(f"{what}: {tag} dimensions must not be negative", g)
            values = (r or 0.0, length or 0.0)
        elif tag == "sphere":
            r = self.number(g, "radius", f"{what}: sphere radius", required=True)
            if r is not None and r < 0:
                self.error(f"{what}: sphere radius must not be negative", g)
            values = (r or 0.0,)
        elif tag == "mesh":
            if not (g.get("filename") or "").strip():
                self.error(f"{what}: mesh has no filename", g)
            scale = g.get("scale")
            values = (1.0, 1.0, 1.0)
            if scale is not None:
                one = len(scale.replace(",", " ").split()) == 1
                got = self.floats(g, "scale", 1 if one else 3, f"{what}: mesh scale")
                if got is not None and not all(
                    MESH_SCALE[0] <= abs(v) <= MESH_SCALE[1] for v in got
                ):
                    self.error(
                        f"{what}: mesh scale '{scale}' is out of range (each factor's size must "
                        f"be between {MESH_SCALE[0]:g} and {MESH_SCALE[1]:g})",
                        g,
                    )
                elif got is not None:
                    values = (got[0], got[0], got[0]) if one else (got[0], got[1], got[2])
        else:
            self.error(f"{what}: unknown geometry <{tag}>", g)
        return None if len(self.errors) > before else values

    # ----------------------------------------------------------------------- joints
    def joint(self, el: etree._Element, name: str, links: dict[str, int]) -> JointRecord | None:
        before = len(self.errors)
        jtype = el.get("type")
        if jtype not in JOINT_TYPES:
            self.errors.append(
                DescriptionError(
                    f"joint '{name}' has type '{jtype}'; expected one of {', '.join(JOINT_TYPES)}",
                    file=self.file,
                    line=line_of(el),
                    kind="joint",
                    name=name,
                )
            )
        parts = _children(el)
        ends = self.joint_ends(el, name, parts, links)
        origin = self.origin(parts.get("origin"), f"joint '{name}'")
        axis = (1.0, 0.0, 0.0)
        axis_el = parts.get("axis")
        if axis_el is not None and axis_el.get("xyz") is not None:
            xyz = self.floats(axis_el, "xyz", 3, f"joint '{name}': axis")
            if xyz is not None:
                if math.hypot(*xyz) < 1e-9 and jtype != "fixed":
                    self.error(
                        f"joint '{name}': axis must not be zero", axis_el, kind="joint", name=name
                    )
                axis = (xyz[0], xyz[1], xyz[2])
        limit = parts.get("limit")
        if jtype in ("revolute", "prismatic") and limit is None:
            self.error(f"{jtype} joint '{name}' has no <limit>", el, kind="joint", name=name)
        lower, upper, vel, eff = self.joint_limit(limit, name, jtype)
        mimic = None
        mimic_el = parts.get("mimic")
        if mimic_el is not None:
            mult = self.number(mimic_el, "multiplier", f"joint '{name}': mimic multiplier")
            off = self.number(mimic_el, "offset", f"joint '{name}': mimic offset")
            mimic = (
                mimic_el.get("joint") or "",
                1.0 if mult is None else mult,
                0.0 if off is None else off,
            )
        if len(self.errors) > before or jtype is None:
            return None
        return JointRecord(
            name,
            el,
            jtype,
            ends[0],
            ends[1],
            origin,
            axis,
            lower,
            upper,
            vel,
            eff,
            mimic,
            limit is not None,
        )

    def joint_ends(
        self, el: etree._Element, name: str, parts: dict[str, etree._Element], links: dict[str, int]
    ) -> list[str]:
        """The joint's parent and child links, each present and a link of the file."""
        ends: list[str] = []
        for role in ("parent", "child"):
            ref = parts.get(role)
            link = None if ref is None else ref.get("link")
            if not link:
                self.error(f"joint '{name}' has no <{role} link=...>", el, kind="joint", name=name)
            elif link not in links:
                self.errors.append(
                    NotFoundError(
                        "link",
                        link,
                        links,
                        where=f"{_short(self.file)} ({role} of joint '{name}')",
                        file=self.file,
                        line=line_of(ref if ref is not None else el),
                    )
                )
            else:
                ends.append(link)
        return ends

    def joint_limit(
        self, limit: etree._Element | None, name: str, jtype: str | None
    ) -> tuple[float | None, float | None, float | None, float | None]:
        """``<limit>``'s lower, upper, velocity and effort (None where absent), checked."""
        if limit is None:
            return None, None, None, None
        lower = self.number(limit, "lower", f"joint '{name}': limit lower")
        upper = self.number(limit, "upper", f"joint '{name}': limit upper")
        vel = self.number(limit, "velocity", f"joint '{name}': limit velocity")
        eff = self.number(limit, "effort", f"joint '{name}': limit effort")
        if jtype in ("revolute", "prismatic") and lower is not None and upper is not None:
            if lower > upper:
                self.error(
                    f"joint '{name}': limit lower {exact(lower)} is greater than upper "
                    f"{exact(upper)}",
                    limit,
                    kind="joint",
                    name=name,
                )
        for value, label in ((vel, "velocity"), (eff, "effort")):
            if value is not None and value < 0:
                self.error(f"joint '{name}': limit {label} must not be negative", limit)
        return lower, upper, vel, eff

    def mimics(self, joints: dict[str, etree._Element]) -> None:
        for name, el in joints.items():
            mimic = el.find("mimic")
            if mimic is None:
                continue
            leader = mimic.get("joint")
            if not leader:
                self.error(f"joint '{name}': <mimic> has no joint attribute", mimic)
            elif leader not in joints:
                self.errors.append(
                    NotFoundError(
                        "joint",
                        leader,
                        joints,
                        where=f"{_short(self.file)} (mimicked by joint '{name}')",
                        file=self.file,
                        line=line_of(mimic),
                    )
                )
            elif leader == name:
                self.error(f"joint '{name}' mimics itself", mimic, kind="joint", name=name)


def walk_urdf(root: etree._Element, file: str) -> UrdfRecords:
    """The records of a URDF tree; every problem is raised at once (a RobotSpecErrors if many)."""
    walk = _Walk(file)
    if root.tag != "robot":
        raise DescriptionError(
            f"root element must be <robot>, got <{root.tag}>", file=file, line=line_of(root)
        )
    robot_name = (root.get("name") or "").strip()
    if not robot_name:
        walk.error("<robot> has no name attribute", root, kind="robot")
    links: dict[str, int] = {}
    link_records: list[LinkRecord] = []
    for el in root.iterfind("link"):
        name = el.get("name")
        if not name:
            walk.error("<link> without a name", el, kind="link")
            continue
        if name in links:
            walk.errors.append(
                DuplicateNameError(
                    f"link '{name}' is defined twice (first on line {links[name]})",
                    file=file,
                    line=line_of(el),
                    kind="link",
                    name=name,
                )
            )
            continue
        links[name] = line_of(el) or 0
        link_records.append(walk.link(el, name))
    if not links:
        walk.error("the robot has no <link>", root, kind="link")
    joints: dict[str, etree._Element] = {}
    joint_records: list[JointRecord] = []
    for el in root.iterfind("joint"):
        name = el.get("name")
        if not name:
            walk.error("<joint> without a name", el, kind="joint")
            continue
        if name in joints:
            walk.errors.append(
                DuplicateNameError(
                    f"joint '{name}' is defined twice (first on line {line_of(joints[name])})",
                    file=file,
                    line=line_of(el),
                    kind="joint",
                    name=name,
                )
            )
            continue
        joints[name] = el
        record = walk.joint(el, name, links)
        if record is not None:
            joint_records.append(record)
    walk.mimics(joints)
    raise_collected(walk.errors, summary=f"{_short(file)}: {len(walk.errors)} problems")
    return UrdfRecords(robot_name, tuple(link_records), tuple(joint_records))


def check_urdf_tree(root: etree._Element, file: str) -> None:
    """Raise every structural problem of a URDF tree at once (a RobotSpecErrors if several)."""
    walk_urdf(root, file)


def _short(file: str) -> str:
    return file.rsplit("/", 1)[-1]
