"""Welding the parts' URDF trees into one: names claimed, clashes reported, materials merged.

Each part's tree is renamed (:class:`PartNames`) and welded to its parent part's link; the mesh
packages of every part stay pinned to that part's own folders.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from robotspec.compose.naming import PartNames
from robotspec.compose.parts import Part
from robotspec.compose.srdf_merge import rename_srdf
from robotspec.compose.urdf_merge import (
    rename_tree,
    weld,
)
from robotspec.description.srdf import Srdf
from robotspec.diagnostics import Diagnostics, Loc
from robotspec.errors import RobotSpecError
from robotspec.files.packages import PackageResolver
from robotspec.model.geometry import UNIT_TOL, unit_norm
from robotspec.spec.models import AttachSpec

__all__ = ["ComposedPart", "Joiner", "pin_packages"]


@dataclass(frozen=True)
class ComposedPart:
    """One part as it ended up in the composed robot."""

    name: str
    names: PartNames
    file: Path
    root_link: str
    weld_joint: str | None
    links: tuple[str, ...]
    joints: tuple[str, ...]


def pin_packages(part: Part, meshes: Sequence[etree._Element], joined: PackageResolver) -> None:
    """Write a mesh's absolute path when the joined search path finds its package elsewhere."""
    same: dict[str, bool] = {}
    for mesh in meshes:
        uri = mesh.get("filename", "")
        if not uri.startswith("package://"):
            continue
        package = uri[len("package://") :].split("/", 1)[0]
        if package not in same:
            try:
                mine: Path | None = part.resolver.find_package(package)
            except RobotSpecError:
                mine = None  # unresolvable for the part too: the world builder reports it
            try:
                theirs: Path | None = joined.find_package(package)
            except RobotSpecError:
                theirs = None
            same[package] = mine is None or mine == theirs
        if same[package]:
            continue
        try:
            mesh.set("filename", str(part.resolver.resolve(uri, relative_to=part.file.parent)))
        except RobotSpecError:
            continue


def _materials(part: Part, n: PartNames, used: dict[str, bytes]) -> tuple[dict[str, str], set[str]]:
    """Composed material names, and the part's materials an earlier part defined identically.

    Material names are global in a URDF: a clash with a different colour gets the part's name
    as well as its prefix.
    """
    out: dict[str, str] = {}
    duplicate: set[str] = set()
    for el in part.tree.iterfind("material"):
        own = el.get("name")
        if not own:
            continue
        body = b"".join(etree.tostring(c, with_tail=False) for c in el)
        composed = n.name(own)
        if composed in used:
            if used[composed] == body:
                duplicate.add(own)
            else:
                composed = f"{part.name}_{composed}"
        out[own] = composed
        used.setdefault(composed, body)
    for el in part.tree.iter("material"):
        own = el.get("name")
        if own and own not in out:
            out[own] = n.name(own)
    return out, duplicate


def _claim(
    kind: str, names: Sequence[str], owner: dict[str, str], part: str
) -> dict[str, dict[str, list[str]]]:
    """Record ``part`` as owner of ``names``; return the clashes (other part -> kind -> names)."""
    clashes: dict[str, dict[str, list[str]]] = {}
    for name in names:
        other = owner.get(name)
        if other is not None and other != part:
            clashes.setdefault(other, {}).setdefault(kind, []).append(name)
        else:
            owner[name] = part
    return clashes


def _report_clashes(
    clashes: Sequence[dict[str, dict[str, list[str]]]], part: str, diag: Diagnostics, loc: Loc
) -> None:
    """One error per pair of parts, listing the clashing names by kind (a few of each)."""
    merged: dict[str, dict[str, list[str]]] = {}
    for c in clashes:
        for other, kinds in c.items():
            for kind, names in kinds.items():
                merged.setdefault(other, {}).setdefault(kind, []).extend(names)
    for other, kinds in merged.items():
        parts = []
        for kind, names in kinds.items():
            shown = ", ".join(f"'{n}'" for n in names[:3])
            more = f" and {len(names) - 3} more" if len(names) > 3 else ""
            parts.append(f"{kind}{'s' if len(names) > 1 else ''} {shown}{more}")
        first = next(iter(kinds.values()))[0]
        diag.error(
            loc,
            f"part '{part}' and part '{other}' both have {'; '.join(parts)}; "
            f"give part '{part}' a (different) prefix",
            name=first,
            kind="clash",
        )


@dataclass
class Joiner:
    """The robot tree being joined, and who owns each name so far."""

    name: str
    diag: Diagnostics
    parts: Mapping[str, Part]
    robot: etree._Element = field(init=False)
    names_of: dict[str, PartNames] = field(default_factory=dict)
    owners: dict[str, dict[str, str]] = field(default_factory=dict)  # kind -> name -> part
    materials: dict[str, bytes] = field(default_factory=dict)
    srdfs: list[Srdf] = field(default_factory=list)
    meshes: list[tuple[Part, list[etree._Element]]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.robot = etree.Element("robot")
        self.robot.set("name", self.name)

    def _parent_link(self, name: str, attach: AttachSpec) -> str | None:
        """The composed name of the link ``attach`` names, or None after reporting why not."""
        loc: Loc = ("parts", name, "attach")
        if attach.part not in self.names_of:
            return None  # its parent failed to weld; that error is reported already
        parent = self.parts[attach.part]
        if attach.link not in parent.facts.links:
            self.diag.not_found(
                (*loc, "link"),
                "link",
                attach.link,
                parent.facts.links,
                f"part '{attach.part}' ({parent.file.name})",
            )
            return None
        if attach.rpy is not None and attach.quaternion is not None:
            self.diag.error(loc, "give rpy or quaternion, not both")
            return None
        if attach.quaternion is not None and abs(unit_norm(attach.quaternion) - 1) > UNIT_TOL:
            self.diag.error((*loc, "quaternion"), "must be a unit quaternion")
            return None
        return self.names_of[attach.part].link(attach.link)

    def _claim_names(self, name: str, n: PartNames, part: Part, weld_joint: str | None) -> None:
        """Own the part's names; one error per other part that already has some of them."""
        links = [n.link(x) for x in part.facts.links if x not in n.merged_links]
        joints = [n.joint(x) for x in part.facts.joints]
        kinds = {"link": links, "joint": [*joints, *([weld_joint] if weld_joint else [])]}
        if part.srdf is not None:
            renamed = rename_srdf(
                part.srdf,
                n,
                keep_virtual=part.spec.attach is None,
                keep_collisions=part.use_srdf,
            )
            kinds["SRDF group"] = [g.name for g in renamed.groups]
            self.srdfs.append(renamed)
        clashes = [_claim(k, v, self.owners.setdefault(k, {}), name) for k, v in kinds.items()]
        loc: Loc = ("parts", name)
        where = (*loc, "prefix") if "prefix" in part.spec.model_fields_set else loc
        _report_clashes(clashes, name, self.diag, where)

    def add(self, name: str) -> ComposedPart | None:
        """Rename one part and weld it into the robot (the base part: just add it)."""
        part = self.parts[name]
        attach = part.spec.attach
        root = part.facts.roots[0]
        merged: dict[str, str] = {}
        parent_link = None
        weld_joint = None
        if attach is not None:
            parent_link = self._parent_link(name, attach)
            if parent_link is None:
                return None
            if attach.replace_root:
                merged[root] = parent_link
            else:
                weld_joint = attach.joint or f"{name}_weld"
        n = PartNames(name, part.spec.prefix, merged)
        self.names_of[name] = n
        self._claim_names(name, n, part, weld_joint)
        tree = part.tree
        self.meshes.append((part, list(tree.iter("mesh"))))
        materials, duplicate = _materials(part, n, self.materials)
        dropped = [el for el in tree.iterfind("material") if el.get("name") in duplicate]
        rename_tree(tree, n, materials)
        for el in dropped:
            tree.remove(el)
        if attach is None or parent_link is None:
            self.robot.extend(el for el in list(tree) if isinstance(el.tag, str))
        else:
            weld(
                self.robot,
                tree,
                parent_link=parent_link,
                part_root=n.link(root),
                pose=attach.pose(),
                joint_name=weld_joint or "",
                replace_root=attach.replace_root,
            )
        return ComposedPart(
            name=name,
            names=n,
            file=part.file,
            root_link=n.link(root),
            weld_joint=weld_joint,
            links=tuple(n.link(x) for x in part.facts.links if x not in merged),
            joints=tuple(n.joint(x) for x in part.facts.joints),
        )
