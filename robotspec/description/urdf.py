"""Build a :class:`~robotspec.model.world.World` from a URDF or xacro file.

The pipeline is: read the file safely (bounded, ``xmlsafe``; xacro first if it is one), walk the
element tree once (``urdf_walk``: every element checked with its line and made a record), and turn
those records into frozen world records. Mesh URIs are resolved through one
:class:`~robotspec.files.packages.PackageResolver`, so ``package://``, ``file://`` and relative
paths all stay inside the allowed roots.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Literal

from lxml import etree

from robotspec.errors import DescriptionError, RobotSpecError, raise_collected
from robotspec.model.geometry import (
    Box,
    Capsule,
    Cylinder,
    GeometryShape,
    Mesh,
    Shape,
    Sphere,
)

if TYPE_CHECKING:
    from robotspec.files.packages import PackageResolver
from robotspec.description.mesh_report import MissingMesh, summarize_missing_meshes
from robotspec.description.urdf_walk import JointRecord, ShapeRecord, UrdfRecords, walk_urdf
from robotspec.files.limits import limits
from robotspec.files.reading import read_bounded
from robotspec.files.xmlsafe import line_of, parse_xml_bytes, undeclared_prefixes
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
    cap = limits()
    data = read_bounded(
        path,
        cap=cap.max_urdf_bytes,
        cap_name="max_urdf_bytes",
        what="a URDF file",
        error_type=DescriptionError,
    )
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
    """Interpret a URDF element tree as a world; all problems are raised together.

    With ``meshes="report"``, meshes that do not resolve are kept as ``Mesh(path=None)`` and
    summarized into ``issues`` as warnings, one per missing package (never raised).
    ``checked=True`` marks a tree whose pieces were checked in their own files already (a
    composed robot's parts): its problems are still found, but reported without lines, which
    would point into the joined tree rather than a file.
    """
    try:
        records = walk_urdf(root, file)
    except RobotSpecError as exc:
        if checked:
            raise exc.located(file=file, line=None) from None
        raise
    problems: list[RobotSpecError] = []
    missing: list[MissingMesh] = []
    bodies = _bodies(records, file, resolver, meshes, problems, missing)
    raise_collected(problems)
    if missing and issues is not None:
        issues.extend(summarize_missing_meshes(missing))
    undeclared = _undeclared_prefixes(root, file)
    if undeclared is not None and issues is not None:
        issues.append(undeclared)
    joints = {j.name: j for j in records.joints}
    leaders = _resolve_mimics(joints, file)
    dofs, own_dofs = _dofs(records, leaders)
    body_index = {b.name: b.index for b in bodies}
    connections = _connections(records, leaders, own_dofs, body_index, file, problems)
    raise_collected(problems)
    return World(records.name, bodies, connections, dofs, source=file)


def _bodies(
    records: UrdfRecords,
    file: str,
    resolver: PackageResolver | None,
    meshes: MeshPolicy,
    problems: list[RobotSpecError],
    missing: list[MissingMesh],
) -> list[Body]:
    """One body per link, with its shapes (meshes resolved as ``meshes`` says)."""
    bodies: list[Body] = []
    base = Path(file).parent
    for link in records.links:
        where = _Where(file, base, resolver, meshes, problems, missing, link.name)
        bodies.append(
            Body(
                name=link.name,
                index=len(bodies),
                visuals=_shapes(link.visuals, where),
                collisions=_shapes(link.collisions, where),
                mass=link.mass,
                line=line_of(link.element),
            )
        )
    return bodies


def _undeclared_prefixes(root: etree._Element, file: str) -> RobotSpecError | None:
    """The warning for XML prefixes used without a declaration (Drake's), if any."""
    undeclared = undeclared_prefixes(root)
    if not undeclared:
        return None
    names = ", ".join(f"'{p}:'" for p in undeclared)
    return DescriptionError(
        f"XML prefix{'es' if len(undeclared) > 1 else ''} {names} used without a "
        "declaration (as Drake writes them); read as extensions URDF does not use",
        file=file,
        line=line_of(root),
        kind="xml",
        name=undeclared[0],
        severity="warning",
    )


def _dofs(
    records: UrdfRecords, leaders: Mapping[str, tuple[str, float, float]]
) -> tuple[list[DegreeOfFreedom], dict[str, tuple[int, ...]]]:
    """The degrees of freedom of every moving joint that mimics none, and each joint's own."""
    dofs: list[DegreeOfFreedom] = []
    own_dofs: dict[str, tuple[int, ...]] = {}
    for j in records.joints:
        jtype = _TYPES[j.type]
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
    return dofs, own_dofs


def _connections(
    records: UrdfRecords,
    leaders: Mapping[str, tuple[str, float, float]],
    own_dofs: Mapping[str, tuple[int, ...]],
    body_index: Mapping[str, int],
    file: str,
    problems: list[RobotSpecError],
) -> list[Connection]:
    """One connection per joint; a mimic joint moves with its leader's one degree of freedom."""
    joints = {j.name: j for j in records.joints}
    connections: list[Connection] = []
    for j in records.joints:
        jtype = _TYPES[j.type]
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
                        line=line_of(j.element),
                        kind="joint",
                        name=j.name,
                    )
                )
                continue
        x, y, z = j.axis
        if jtype is not ConnectionType.FIXED:  # the walk refused zero axes of moving joints
            norm = math.sqrt(x * x + y * y + z * z)
            x, y, z = x / norm, y / norm, z / norm
        connections.append(
            Connection(
                name=j.name,
                index=len(connections),
                type=jtype,
                parent=body_index[j.parent],
                child=body_index[j.child],
                origin=j.origin,
                axis=(x, y, z),
                dofs=dof_idx,
                mimic=mimic,
                line=line_of(j.element),
            )
        )
    return connections


_TYPES = {t.value: t for t in ConnectionType}


def _limits(j: JointRecord, jtype: ConnectionType) -> tuple[float, float, float, float]:
    lower, upper = -math.inf, math.inf
    vel, eff = math.inf, math.inf
    if j.has_limit:
        if jtype in (ConnectionType.REVOLUTE, ConnectionType.PRISMATIC):
            lower = 0.0 if j.lower is None else j.lower
            upper = 0.0 if j.upper is None else j.upper
        # A velocity or effort limit of 0 means "not given" in many vendor files.
        if j.velocity:
            vel = j.velocity
        if j.effort:
            eff = j.effort
    return lower, upper, vel, eff


def _resolve_mimics(
    joints: Mapping[str, JointRecord], file: str
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
        while True:
            record = joints.get(current)
            if record is None or record.mimic is None:
                break
            if ConnectionType(record.type).dof_count != 1:
                break
            leader, m_mult, m_off = record.mimic
            # q_current = m_mult * q_next + m_off, so compose outward-in.
            off = mult * m_off + off
            mult = mult * m_mult
            current = leader
            if current in seen:
                raise DescriptionError(
                    f"mimic joints form a cycle through joint '{name}'",
                    file=file,
                    line=line_of(j.element),
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


def _shapes(records: tuple[ShapeRecord, ...], where: _Where) -> tuple[Shape, ...]:
    out: list[Shape] = []
    for rec in records:
        geometry = _geometry(rec, where)
        if geometry is None:
            continue
        out.append(
            Shape(
                geometry=geometry,
                origin=rec.origin,
                name=rec.name,
                line=line_of(rec.element),
                rgba=rec.rgba,
            )
        )
    return tuple(out)


def _geometry(rec: ShapeRecord, where: _Where) -> GeometryShape | None:
    el, v = rec.shape, rec.values
    if el.tag == "capsule":
        return Capsule(radius=v[0], length=v[1])
    if el.tag == "box":
        return Box(size=(v[0], v[1], v[2]))
    if el.tag == "cylinder":
        return Cylinder(radius=v[0], length=v[1])
    if el.tag == "sphere":
        return Sphere(radius=v[0])
    file, resolver, meshes = where.file, where.resolver, where.meshes
    uri = el.get("filename") or ""
    scale = (v[0], v[1], v[2])
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
            return Mesh(uri=uri, path=None, scale=scale, problem=exc)
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
            return Mesh(uri=uri, path=None, scale=scale, problem=err)
        path = str(resolved)
    return Mesh(uri=uri, path=path, scale=scale)
