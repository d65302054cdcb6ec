"""Structural checks of a URDF element tree, before any library interprets it.

Why separate from the loader: yourdfpy trusts its input (a missing ``<parent>`` is an
AttributeError, ``nan`` a valid limit, a dangling link name is logged and skipped), and after it
has parsed, line numbers are gone. Checking the lxml tree first lets every problem be reported with
its file and line, all at once, in the package's own error type.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from lxml import etree

from robotspec.errors import (
    DescriptionError,
    DuplicateNameError,
    NotFoundError,
    RobotSpecError,
    raise_collected,
)
from robotspec.files.xmlsafe import line_of

__all__ = ["JOINT_TYPES", "check_urdf_tree", "geometry_element", "parse_floats"]

JOINT_TYPES = ("fixed", "revolute", "continuous", "prismatic", "floating", "planar")


def parse_floats(
    text: str | None, count: int, what: str, el: etree._Element, file: str
) -> list[float]:
    """Parse exactly ``count`` finite numbers from an attribute value, or raise a located error."""
    if text is None:
        raise DescriptionError(f"{what} is missing", file=file, line=line_of(el))
    parts = text.replace(",", " ").split()
    if len(parts) != count:
        raise DescriptionError(
            f"{what} must have {count} number{'s' if count != 1 else ''}, got '{text}'",
            file=file,
            line=line_of(el),
        )
    out: list[float] = []
    for p in parts:
        try:
            v = float(p)
        except ValueError:
            raise DescriptionError(
                f"{what}: '{p}' is not a number", file=file, line=line_of(el)
            ) from None
        if not math.isfinite(v):
            raise DescriptionError(f"{what} must be finite, got '{p}'", file=file, line=line_of(el))
        out.append(v)
    return out


def _elements(root: etree._Element, tag: str) -> Iterator[etree._Element]:
    # Direct children only, like URDF parsers; comments and PIs are skipped by tag filtering.
    yield from root.iterfind(tag)


class _Collector:
    def __init__(self, file: str) -> None:
        self.file = file
        self.errors: list[RobotSpecError] = []

    def add(self, err: RobotSpecError) -> None:
        self.errors.append(err)

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


def check_urdf_tree(root: etree._Element, file: str) -> None:
    """Raise every structural problem of a URDF tree at once (a RobotSpecErrors if several)."""
    col = _Collector(file)
    if root.tag != "robot":
        raise DescriptionError(
            f"root element must be <robot>, got <{root.tag}>", file=file, line=line_of(root)
        )
    if not (root.get("name") or "").strip():
        col.error("<robot> has no name attribute", root, kind="robot")
    links: dict[str, int] = {}
    for el in _elements(root, "link"):
        name = el.get("name")
        if not name:
            col.error("<link> without a name", el, kind="link")
            continue
        if name in links:
            col.add(
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
        _check_link(el, name, col)
    if not links:
        col.error("the robot has no <link>", root, kind="link")
    joints: dict[str, etree._Element] = {}
    for el in _elements(root, "joint"):
        name = el.get("name")
        if not name:
            col.error("<joint> without a name", el, kind="joint")
            continue
        if name in joints:
            col.add(
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
        _check_joint(el, name, links, col)
    for name, el in joints.items():
        mimic = el.find("mimic")
        if mimic is not None:
            leader = mimic.get("joint")
            if not leader:
                col.error(f"joint '{name}': <mimic> has no joint attribute", mimic)
            elif leader not in joints:
                col.add(
                    NotFoundError(
                        "joint",
                        leader,
                        joints,
                        where=f"{_short(file)} (mimicked by joint '{name}')",
                        file=file,
                        line=line_of(mimic),
                    )
                )
            elif leader == name:
                col.error(f"joint '{name}' mimics itself", mimic, kind="joint", name=name)
    raise_collected(col.errors, summary=f"{_short(file)}: {len(col.errors)} problems")


def _short(file: str) -> str:
    return file.rsplit("/", 1)[-1]


def _check_origin(parent: etree._Element, col: _Collector, what: str) -> None:
    origin = parent.find("origin")
    if origin is None:
        return
    if origin.get("xyz") is not None:
        col.floats(origin, "xyz", 3, f"{what}: origin xyz")
    if origin.get("rpy") is not None:
        col.floats(origin, "rpy", 3, f"{what}: origin rpy")


def geometry_element(geom: etree._Element | None) -> etree._Element | None:
    """The shape element inside ``<geometry>``, skipping comments."""
    if geom is None:
        return None
    return next((c for c in geom if isinstance(c.tag, str)), None)


def _check_link(el: etree._Element, name: str, col: _Collector) -> None:
    inertial = el.find("inertial")
    if inertial is not None:
        mass = inertial.find("mass")
        if mass is not None:
            m = col.number(mass, "value", f"link '{name}': mass")
            if m is not None and m < 0:
                col.error(f"link '{name}': mass must not be negative, got {m}", mass)
    for kind in ("visual", "collision"):
        for shape in el.iterfind(kind):
            _check_origin(shape, col, f"link '{name}' {kind}")
            geom = shape.find("geometry")
            inner = geometry_element(geom)
            if inner is None:
                col.error(f"link '{name}': <{kind}> has no geometry", shape, kind="link", name=name)
                continue
            _check_geometry(inner, f"link '{name}' {kind}", col)


def _check_geometry(g: etree._Element, what: str, col: _Collector) -> None:
    tag = g.tag if isinstance(g.tag, str) else ""
    if tag == "box":
        size = col.floats(g, "size", 3, f"{what}: box size")
        if size is not None and min(size) < 0:
            col.error(f"{what}: box size must not be negative", g)
    elif tag in ("cylinder", "capsule"):
        r = col.number(g, "radius", f"{what}: {tag} radius", required=True)
        length = col.number(g, "length", f"{what}: {tag} length", required=True)
        if (r is not None and r < 0) or (length is not None and length < 0):
            col.error(f"{what}: {tag} dimensions must not be negative", g)
    elif tag == "sphere":
        r = col.number(g, "radius", f"{what}: sphere radius", required=True)
        if r is not None and r < 0:
            col.error(f"{what}: sphere radius must not be negative", g)
    elif tag == "mesh":
        if not (g.get("filename") or "").strip():
            col.error(f"{what}: mesh has no filename", g)
        scale = g.get("scale")
        if scale is not None and len(scale.replace(",", " ").split()) == 1:
            col.floats(g, "scale", 1, f"{what}: mesh scale")
        elif scale is not None:
            col.floats(g, "scale", 3, f"{what}: mesh scale")
    else:
        col.error(f"{what}: unknown geometry <{tag}>", g)


def _check_joint(el: etree._Element, name: str, links: dict[str, int], col: _Collector) -> None:
    jtype = el.get("type")
    if jtype not in JOINT_TYPES:
        col.add(
            DescriptionError(
                f"joint '{name}' has type '{jtype}'; expected one of {', '.join(JOINT_TYPES)}",
                file=col.file,
                line=line_of(el),
                kind="joint",
                name=name,
            )
        )
    for role in ("parent", "child"):
        ref = el.find(role)
        link = None if ref is None else ref.get("link")
        if not link:
            col.error(f"joint '{name}' has no <{role} link=...>", el, kind="joint", name=name)
        elif link not in links:
            col.add(
                NotFoundError(
                    "link",
                    link,
                    links,
                    where=f"{_short(col.file)} ({role} of joint '{name}')",
                    file=col.file,
                    line=line_of(ref if ref is not None else el),
                )
            )
    _check_origin(el, col, f"joint '{name}'")
    axis = el.find("axis")
    if axis is not None and axis.get("xyz") is not None:
        xyz = col.floats(axis, "xyz", 3, f"joint '{name}': axis")
        if xyz is not None and math.hypot(*xyz) < 1e-9 and jtype != "fixed":
            col.error(f"joint '{name}': axis must not be zero", axis, kind="joint", name=name)
    limit = el.find("limit")
    if jtype in ("revolute", "prismatic") and limit is None:
        col.error(f"{jtype} joint '{name}' has no <limit>", el, kind="joint", name=name)
    if limit is not None:
        lower = col.number(limit, "lower", f"joint '{name}': limit lower")
        upper = col.number(limit, "upper", f"joint '{name}': limit upper")
        vel = col.number(limit, "velocity", f"joint '{name}': limit velocity")
        eff = col.number(limit, "effort", f"joint '{name}': limit effort")
        if jtype in ("revolute", "prismatic") and lower is not None and upper is not None:
            if lower > upper:
                col.error(
                    f"joint '{name}': limit lower {lower:g} is greater than upper {upper:g}",
                    limit,
                    kind="joint",
                    name=name,
                )
        for value, label in ((vel, "velocity"), (eff, "effort")):
            if value is not None and value < 0:
                col.error(f"joint '{name}': limit {label} must not be negative", limit)
    mimic = el.find("mimic")
    if mimic is not None:
        col.number(mimic, "multiplier", f"joint '{name}': mimic multiplier")
        col.number(mimic, "offset", f"joint '{name}': mimic offset")
