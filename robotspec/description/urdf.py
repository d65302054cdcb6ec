"""Build a :class:`~robotspec.model.world.World` from a URDF or xacro file.

The pipeline is: read the file safely (``xmlsafe``; xacro first if it is one), check the element
tree with line numbers (``urdf_check``), let yourdfpy interpret the elements into its records, and
turn those into frozen world records. Mesh URIs are resolved through one
:class:`~robotspec.files.packages.PackageResolver`, so ``package://``, ``file://`` and relative
paths all stay inside the allowed roots.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from lxml import etree

from robotspec.errors import DescriptionError, RobotSpecError, missing_file, raise_collected
from robotspec.model.geometry import (
    Box,
    Capsule,
    Cylinder,
    GeometryShape,
    Mesh,
    Shape,
    Sphere,
    frozen_array,
)

if TYPE_CHECKING:
    from robotspec.files.packages import PackageResolver
from robotspec.description.mesh_report import MissingMesh, summarize_missing_meshes
from robotspec.description.urdf_check import check_urdf_tree, geometry_element, parse_floats
from robotspec.files.xmlsafe import line_of, parse_xml_bytes
from robotspec.model.world import Body, Connection, ConnectionType, DegreeOfFreedom, Mimic, World

__all__ = ["MeshPolicy", "is_xacro", "load_urdf", "read_description_xml", "world_from_urdf_xml"]

MeshPolicy = Literal["resolve", "report", "keep"]
"""``resolve``: every mesh URI must resolve to an existing file inside the allowed roots (an
error otherwise). ``report``: resolve what can be resolved and report the rest as warnings in
the caller's ``issues`` list (``Mesh.path`` is ``None`` for those). ``keep``: record URIs
unresolved, for kinematics-only use; consumers that need a mesh report it."""


def is_xacro(path: Path, data: bytes) -> bool:
    """A file is xacro when its name says so or its root declares the xacro namespace."""
    if path.suffix == ".xacro" or path.name.endswith(".urdf.xacro"):
        return True
    head = data[:4096]
    return b"xmlns:xacro" in head and b"<xacro:" in data


def read_description_xml(
    path: Path, resolver: PackageResolver, xacro_args: Mapping[str, str] | None = None
) -> etree._Element:
    """The URDF element tree of ``path``, running xacro first when the file is xacro."""
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise missing_file(path, DescriptionError) from None
    except IsADirectoryError:
        raise DescriptionError("is a directory, not a URDF file", file=str(path)) from None
    except OSError as exc:
        raise DescriptionError(f"cannot read file: {exc.strerror}", file=str(path)) from None
    if is_xacro(path, data):
        from robotspec.files.xacro import process_xacro

        # Xacro's input is checked as XML first (entities refused) and its output again.
        parse_xml_bytes(data, str(path))
        data = process_xacro(path, resolver, dict(xacro_args or {}))
    elif xacro_args:
        raise DescriptionError(
            "xacro arguments were given but the file is plain URDF", file=str(path)
        )
    return parse_xml_bytes(data, str(path))


def load_urdf(
    path: str | Path,
    *,
    resolver: PackageResolver | None = None,
    xacro_args: Mapping[str, str] | None = None,
    meshes: MeshPolicy = "resolve",
) -> World:
    """Load a URDF or xacro file into a world (the robot's own tree, no virtual joint)."""
    p = Path(path)
    from robotspec.files.packages import PackageResolver

    res = resolver or PackageResolver.create(p)
    root = read_description_xml(p, res, xacro_args)
    return world_from_urdf_xml(root, str(p), resolver=res, meshes=meshes)


def world_from_urdf_xml(
    root: etree._Element,
    file: str,
    *,
    resolver: PackageResolver | None = None,
    meshes: MeshPolicy = "keep",
    issues: list[RobotSpecError] | None = None,
    checked: bool = False,
) -> World:
    """Interpret a checked URDF element tree as a world; all problems are raised together.

    With ``meshes="report"``, meshes that do not resolve are kept as ``Mesh(path=None)`` and
    summarized into ``issues`` as warnings, one per missing package (never raised).
    ``checked=True`` skips :func:`check_urdf_tree` for a tree whose pieces were checked in their
    own files already (a composed robot's parts), where its line numbers would mislead.
    """
    import yourdfpy

    if not checked:
        check_urdf_tree(root, file)
    # yourdfpy's own loader strips comments before parsing; its element parser needs the same.
    etree.strip_tags(root, etree.Comment)
    try:
        robot = yourdfpy.URDF._parse_robot(xml_element=root)
    except (ValueError, TypeError, AttributeError, KeyError) as exc:
        # The tree passed our checks, so this is a construct we do not check for yet.
        raise DescriptionError(f"cannot interpret URDF: {exc}", file=file) from None
    link_el = {el.get("name"): el for el in root.iterfind("link")}
    joint_el = {el.get("name", ""): el for el in root.iterfind("joint")}
    problems: list[RobotSpecError] = []
    missing: list[MissingMesh] = []
    bodies: list[Body] = []
    body_index: dict[str, int] = {}
    base = Path(file).parent
    for link in robot.links:
        el = link_el[link.name]
        where = _Where(file, base, resolver, meshes, problems, missing, link.name)
        visuals = _shapes(link.visuals, el.iterfind("visual"), where)
        collisions = _shapes(link.collisions, el.iterfind("collision"), where)
        mass = None
        if link.inertial is not None and link.inertial.mass is not None:
            mass = float(link.inertial.mass)
        body_index[link.name] = len(bodies)
        bodies.append(
            Body(
                name=link.name,
                index=len(bodies),
                visuals=visuals,
                collisions=collisions,
                mass=mass,
                line=line_of(el),
            )
        )
    raise_collected(problems)
    if missing and issues is not None:
        issues.extend(summarize_missing_meshes(missing))
    joints = {j.name: j for j in robot.joints}
    leaders = _resolve_mimics(joints, joint_el, file)
    dofs: list[DegreeOfFreedom] = []
    own_dofs: dict[str, tuple[int, ...]] = {}
    for j in robot.joints:
        jtype = ConnectionType(j.type)
        if j.name in leaders or jtype.dof_count == 0:
            continue
        start = len(dofs)
        for sfx in jtype.dof_suffixes:
            lower, upper, vel, eff = _limits(j, jtype)
            dofs.append(
                DegreeOfFreedom(
                    name=j.name + sfx,
                    index=len(dofs),
                    connection=j.name,
                    lower=lower if jtype.dof_count == 1 else -math.inf,
                    upper=upper if jtype.dof_count == 1 else math.inf,
                    velocity=vel,
                    effort=eff,
                )
            )
        own_dofs[j.name] = tuple(range(start, len(dofs)))
    connections: list[Connection] = []
    for j in robot.joints:
        jtype = ConnectionType(j.type)
        mimic = None
        dof_idx = own_dofs.get(j.name, ())
        if j.name in leaders:
            leader, mult, off = leaders[j.name]
            mimic = Mimic(leader=leader, multiplier=mult, offset=off)
            dof_idx = own_dofs.get(leader, ())
            if len(dof_idx) != 1:
                problems.append(
                    DescriptionError(
                        f"joint '{j.name}' mimics '{leader}', a {joints[leader].type} joint; "
                        "only revolute, continuous and prismatic joints can be mimicked",
                        file=file,
                        line=line_of(joint_el[j.name]),
                        kind="joint",
                        name=j.name,
                    )
                )
                continue
        axis = np.array([1.0, 0.0, 0.0]) if j.axis is None else np.asarray(j.axis, float)
        axis = axis / np.linalg.norm(axis) if jtype is not ConnectionType.FIXED else axis
        origin = np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=np.float64)
        connections.append(
            Connection(
                name=j.name,
                index=len(connections),
                type=jtype,
                parent=body_index[j.parent],
                child=body_index[j.child],
                origin=frozen_array(origin),
                axis=(float(axis[0]), float(axis[1]), float(axis[2])),
                dofs=dof_idx,
                mimic=mimic,
                line=line_of(joint_el[j.name]),
            )
        )
    raise_collected(problems)
    return World(robot.name, bodies, connections, dofs, source=file)


def _limits(j: Any, jtype: ConnectionType) -> tuple[float, float, float, float]:
    lim = j.limit
    lower, upper = -math.inf, math.inf
    vel, eff = math.inf, math.inf
    if lim is not None:
        if jtype in (ConnectionType.REVOLUTE, ConnectionType.PRISMATIC):
            lower = 0.0 if lim.lower is None else float(lim.lower)
            upper = 0.0 if lim.upper is None else float(lim.upper)
        # A velocity or effort limit of 0 means "not given" in many vendor files.
        if lim.velocity:
            vel = float(lim.velocity)
        if lim.effort:
            eff = float(lim.effort)
    return lower, upper, vel, eff


def _resolve_mimics(
    joints: Mapping[str, Any], joint_el: Mapping[str, etree._Element], file: str
) -> dict[str, tuple[str, float, float]]:
    """Map each mimic joint to its ultimate leader with composed multiplier and offset."""
    out: dict[str, tuple[str, float, float]] = {}
    for name, j in joints.items():
        # URDF parsers ignore <mimic> on joints that do not move on one axis (Talos's
        # grippers carry it on fixed joints); so does robotspec.
        if j.mimic is None or ConnectionType(j.type).dof_count != 1:
            continue
        mult, off = 1.0, 0.0
        current = name
        seen = {name}
        while (
            joints[current].mimic is not None
            and ConnectionType(joints[current].type).dof_count == 1
        ):
            m = joints[current].mimic
            m_mult = 1.0 if m.multiplier is None else float(m.multiplier)
            m_off = 0.0 if m.offset is None else float(m.offset)
            # q_current = m_mult * q_next + m_off, so compose outward-in.
            off = mult * m_off + off
            mult = mult * m_mult
            current = m.joint
            if current in seen:
                raise DescriptionError(
                    f"mimic joints form a cycle through joint '{name}'",
                    file=file,
                    line=line_of(joint_el[name]),
                    kind="joint",
                    name=name,
                )
            seen.add(current)
        out[name] = (current, mult, off)
    return out


@dataclass(frozen=True)
class _Where:
    """What resolving one link's meshes needs, and where its problems go.

    ``problems`` are errors (raised together); ``missing`` are meshes that did not resolve under
    the ``report`` policy, summarized into one warning per package once every link is read.
    """

    file: str
    base: Path
    resolver: PackageResolver | None
    meshes: MeshPolicy
    problems: list[RobotSpecError]
    missing: list[MissingMesh]
    body: str


def _shapes(records: list[Any], elements: Any, where: _Where) -> tuple[Shape, ...]:
    out: list[Shape] = []
    for rec, el in zip(records, elements, strict=True):
        geom_el = geometry_element(el.find("geometry"))
        assert geom_el is not None  # checked by check_urdf_tree
        geometry = _geometry(rec.geometry, geom_el, where)
        if geometry is None:
            continue
        origin = np.eye(4) if rec.origin is None else np.asarray(rec.origin, dtype=np.float64)
        rgba = None
        material = getattr(rec, "material", None)
        if material is not None and material.color is not None:
            c = material.color.rgba
            rgba = (float(c[0]), float(c[1]), float(c[2]), float(c[3]))
        out.append(
            Shape(
                geometry=geometry,
                origin=frozen_array(origin),
                name=rec.name,
                line=line_of(el),
                rgba=rgba,
            )
        )
    return tuple(out)


def _geometry(g: Any, el: etree._Element, where: _Where) -> GeometryShape | None:
    file, resolver, meshes = where.file, where.resolver, where.meshes
    if el.tag == "capsule":
        return Capsule(radius=float(el.get("radius", "nan")), length=float(el.get("length", "nan")))
    if g.box is not None:
        s = g.box.size
        return Box(size=(float(s[0]), float(s[1]), float(s[2])))
    if g.cylinder is not None:
        return Cylinder(radius=float(g.cylinder.radius), length=float(g.cylinder.length))
    if g.sphere is not None:
        return Sphere(radius=float(g.sphere.radius))
    uri = str(g.mesh.filename)
    scale_attr = el.get("scale")
    scale = (1.0, 1.0, 1.0)
    if scale_attr is not None:
        vals = parse_floats(
            scale_attr, len(scale_attr.replace(",", " ").split()), "mesh scale", el, file
        )
        scale = (vals[0], vals[0], vals[0]) if len(vals) == 1 else (vals[0], vals[1], vals[2])
    path: str | None = None
    if meshes != "keep":
        if resolver is None:
            raise ValueError("resolving meshes needs a PackageResolver")
        report = meshes == "report"
        try:
            resolved = resolver.resolve(uri, relative_to=where.base, file=file, line=line_of(el))
        except RobotSpecError as exc:
            if not report:
                where.problems.append(exc)
                return None
            where.missing.append(MissingMesh(uri=uri, body=where.body, error=exc))
            return Mesh(uri=uri, path=None, scale=scale)
        if not resolved.is_file():
            err = DescriptionError(
                f"mesh '{uri}' resolves to '{resolved}', which does not exist",
                file=file,
                line=line_of(el),
                kind="mesh",
                name=uri,
            )
            if not report:
                where.problems.append(err)
                return None
            where.missing.append(MissingMesh(uri=uri, body=where.body, error=err))
            return Mesh(uri=uri, path=None, scale=scale)
        path = str(resolved)
    return Mesh(uri=uri, path=path, scale=scale)
