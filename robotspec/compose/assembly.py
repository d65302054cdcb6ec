"""A composed spec (``parts:``) to one URDF tree, one SRDF and one flat spec.

Pipeline: load every part (a URDF/xacro, or a spec, itself possibly composed), order the parts by
their welds (the base first), rename each part's names (:class:`PartNames`), weld the trees, merge
the SRDFs and the part specs' semantics, then let the composed spec's own entries override. The
compiler then treats the result like any flat spec; ``robotspec export urdf`` writes the tree.

Every problem of every part is collected and raised together, each at its spec line.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree
from pydantic import ValidationError

from robotspec.compose.naming import PartNames
from robotspec.compose.semantics import NAMED_SECTIONS, remap_marks, rename_semantics
from robotspec.compose.srdf_merge import merge_srdfs, rename_srdf
from robotspec.compose.urdf_merge import (
    TreeFacts,
    absolute_mesh_paths,
    add_fixed_frames,
    rename_tree,
    tree_facts,
    weld,
)
from robotspec.description.srdf import Srdf
from robotspec.diagnostics import Diagnostics, Loc
from robotspec.errors import RobotSpecError, SpecError
from robotspec.files.packages import PackageResolver
from robotspec.files.yamlio import LocatedYaml, validation_errors
from robotspec.model.geometry import UNIT_TOL, unit_norm
from robotspec.shipped import shipped_part_files, shipped_spec_files
from robotspec.spec.load import LoadedSpec, load_spec, merge_data
from robotspec.spec.models import AttachSpec, DescriptionSpec, PartSpec, RobotSpec

__all__ = ["ComposedPart", "Composition", "compose", "description_tree"]


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


@dataclass(frozen=True)
class Composition:
    """The joined description of a robot and its flat spec.

    ``urdf`` is shared: callers that change a tree (the world builder strips comments) work on
    ``copy.deepcopy(composition.urdf)``.
    """

    loaded: LoadedSpec
    urdf: etree._Element = field(repr=False)
    srdf: Srdf | None
    resolver: PackageResolver = field(repr=False)
    parts: tuple[ComposedPart, ...] = ()

    @property
    def source(self) -> str:
        """How messages name the joined description."""
        return f"{self.loaded.file.name} (composed)"


@dataclass
class _Part:
    name: str
    spec: PartSpec
    file: Path
    tree: etree._Element
    srdf: Srdf | None
    resolver: PackageResolver
    facts: TreeFacts
    data: dict[str, Any] = field(default_factory=dict)
    documents: tuple[LocatedYaml, ...] = ()
    use_srdf: bool = True
    spec_root: str | None = None
    drive: dict[str, Any] | None = None
    collision: dict[str, Any] = field(default_factory=dict)


# ------------------------------------------------------------------------------------- loading
def description_tree(
    desc: DescriptionSpec,
    folder: Path,
    package_paths: Sequence[str | Path] = (),
    *,
    share_crawls_with: PackageResolver | None = None,
) -> tuple[etree._Element, Path, PackageResolver, Srdf | None]:
    """A description's URDF tree (xacro run, frames added, mesh paths absolute) and its SRDF.

    Paths start at ``folder`` (the spec's). ``share_crawls_with``: a resolver of the same
    compilation whose package-folder crawls are reused (parts search the same folders).
    """
    from robotspec.description.load import read_urdf_tree, resolve_file
    from robotspec.description.urdf_check import check_urdf_tree

    tree, urdf, resolver = read_urdf_tree(
        desc.urdf,
        package_paths=[*desc.package_paths, *map(str, package_paths)],
        xacro_args=desc.xacro_args,
        base_folder=folder,
        share_crawls_with=share_crawls_with,
    )
    check_urdf_tree(tree, str(urdf))
    absolute_mesh_paths(tree, urdf.parent)
    links = {el.get("name") for el in tree.iterfind("link")}
    add_fixed_frames(
        tree,
        [(n, f.parent, f.pose()) for n, f in desc.frames.items() if n not in links],
    )
    srdf = None
    if desc.srdf is not None:
        from robotspec.description.srdf import load_srdf

        srdf = load_srdf(resolve_file(desc.srdf, folder, resolver), strict=False)
    return tree, urdf, resolver, srdf


def _spec_path(ref: str, folder: Path) -> Path | None:
    """A part's spec: a path, a shipped robot's name, or a shipped part's name."""
    p = Path(ref) if Path(ref).is_absolute() else folder / ref
    if p.is_file():
        return p
    key = ref.lower()
    return shipped_spec_files().get(key) or shipped_part_files().get(key)


def _load_part(
    name: str,
    ps: PartSpec,
    loaded: LoadedSpec,
    diag: Diagnostics,
    package_paths: Sequence[str | Path],
    seen: tuple[Path, ...],
    share: PackageResolver | None,
) -> _Part | None:
    loc: Loc = ("parts", name)
    try:
        if ps.spec is not None:
            path = _spec_path(ps.spec, loaded.folder)
            if path is None:
                candidates = [
                    *shipped_spec_files(),
                    *(f.name for f in loaded.folder.glob("*.yaml")),
                ]
                diag.not_found(
                    (*loc, "spec"),
                    "spec",
                    ps.spec,
                    candidates,
                    "this folder or the shipped robots and parts",
                )
                return None
            if path.resolve() in seen:
                chain = " -> ".join(p.name for p in (*seen, path.resolve()))
                diag.error((*loc, "spec"), f"parts include each other: {chain}")
                return None
            part_loaded = load_spec(path)
            if part_loaded.spec.parts:
                inner = compose(part_loaded, package_paths=package_paths, _seen=seen)
                flat = inner.loaded
                tree, file, resolver, srdf = inner.urdf, path, inner.resolver, inner.srdf
            else:
                flat = part_loaded
                tree, file, resolver, srdf = description_tree(
                    part_loaded.spec.files,
                    part_loaded.folder,
                    package_paths,
                    share_crawls_with=share,
                )
            spec = flat.spec
            data = spec.model_dump(mode="json", exclude_unset=True)
            return _Part(
                name=name,
                spec=ps,
                file=file,
                tree=tree,
                srdf=srdf,
                resolver=resolver,
                facts=tree_facts(tree),
                data=data,
                documents=flat.documents,
                use_srdf=spec.collision.use_srdf,
                spec_root=spec.root,
                drive=data.get("drive"),
                collision={
                    k: v
                    for k, v in data.get("collision", {}).items()
                    if k in ("buffer_distance", "violated_distance")
                },
            )
        assert ps.urdf is not None  # PartSpec checks one of spec/urdf is given
        part_desc = DescriptionSpec(
            urdf=ps.urdf, srdf=ps.srdf, xacro_args=ps.xacro_args, package_paths=ps.package_paths
        )
        tree, file, resolver, srdf = description_tree(
            part_desc, loaded.folder, package_paths, share_crawls_with=share
        )
        return _Part(name, ps, file, tree, srdf, resolver, tree_facts(tree))
    except RobotSpecError as exc:
        key = "spec" if ps.spec is not None else "urdf"
        diag.add_all(exc, (*loc, key))
        return None


# ------------------------------------------------------------------------------------ ordering
def _order(parts: Mapping[str, PartSpec], diag: Diagnostics) -> list[str]:
    """Parts in weld order, base first; missing parents, several bases and cycles reported."""
    bases = [n for n, p in parts.items() if p.attach is None]
    for extra in bases[1:]:
        diag.error(
            ("parts", extra),
            f"part '{extra}' has no 'attach', and neither has part '{bases[0]}'; "
            "only the base part is not attached to another",
        )
    for n, p in parts.items():
        if p.attach is not None and p.attach.part not in parts:
            diag.not_found(
                ("parts", n, "attach", "part"),
                "part",
                p.attach.part,
                [m for m in parts if m != n],
                "the spec's parts",
            )
    order: list[str] = []
    done: set[str] = set()
    frontier = bases[:1]
    while frontier:
        current = frontier.pop(0)
        order.append(current)
        done.add(current)
        frontier += [
            n
            for n, p in parts.items()
            if p.attach is not None and p.attach.part == current and n not in done
        ]
    in_cycle: set[str] = set()
    for n, p in parts.items():
        if n in done or n in in_cycle or p.attach is None or p.attach.part not in parts:
            continue
        # Not reachable from the base and its parent exists: it hangs in a cycle.
        path, cur = [n], p.attach.part
        while cur not in path and cur in parts and parts[cur].attach is not None:
            path.append(cur)
            att = parts[cur].attach
            assert att is not None
            cur = att.part
        if cur in path:
            cycle = [*path[path.index(cur) :], cur]
            in_cycle.update(cycle)
            diag.error(
                ("parts", n, "attach", "part"),
                f"the parts' attachments form a cycle: {' -> '.join(cycle)}",
            )
    if not bases and parts:
        diag.error(("parts",), "every part is attached to another: one part must be the base")
    return order


# ------------------------------------------------------------------------------------ joining
def _pin_packages(part: _Part, meshes: Sequence[etree._Element], joined: PackageResolver) -> None:
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


def _materials(
    part: _Part, n: PartNames, used: dict[str, bytes]
) -> tuple[dict[str, str], set[str]]:
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
class _Joiner:
    """The robot tree being joined, and who owns each name so far."""

    name: str
    diag: Diagnostics
    parts: Mapping[str, _Part]
    robot: etree._Element = field(init=False)
    names_of: dict[str, PartNames] = field(default_factory=dict)
    owners: dict[str, dict[str, str]] = field(default_factory=dict)  # kind -> name -> part
    materials: dict[str, bytes] = field(default_factory=dict)
    srdfs: list[Srdf] = field(default_factory=list)
    meshes: list[tuple[_Part, list[etree._Element]]] = field(default_factory=list)

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

    def _claim_names(self, name: str, n: PartNames, part: _Part, weld_joint: str | None) -> None:
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


def compose(
    loaded: LoadedSpec,
    *,
    package_paths: Sequence[str | Path] = (),
    _seen: tuple[Path, ...] = (),
) -> Composition:
    """Join the parts of a composed spec; every problem is raised together."""
    spec = loaded.spec
    diag = Diagnostics(loaded)
    seen = (*_seen, loaded.file.resolve())
    order = _order(spec.parts, diag)
    loaded_parts: dict[str, _Part] = {}
    share: PackageResolver | None = None
    for name in order:
        part = _load_part(name, spec.parts[name], loaded, diag, package_paths, seen, share)
        if part is not None:
            loaded_parts[name] = part
            share = share or part.resolver
            if len(part.facts.roots) != 1:
                diag.error(
                    ("parts", name),
                    f"part '{name}' ({part.file.name}) must have one root link, "
                    f"it has {len(part.facts.roots)}: {', '.join(part.facts.roots)}",
                )
    diag.raise_if_failed()
    joiner = _Joiner(spec.name, diag, loaded_parts)
    composed = [c for c in map(joiner.add, order) if c is not None]
    diag.raise_if_failed()
    resolver = PackageResolver.joined([p.resolver for p in loaded_parts.values()])
    for part, meshes in joiner.meshes:
        _pin_packages(part, meshes, resolver)
    srdf = merge_srdfs(spec.name, joiner.srdfs) if joiner.srdfs else None
    flat = _flat_spec(loaded, loaded_parts, order, joiner.names_of, srdf, joiner.robot, diag)
    diag.raise_if_failed()
    assert flat is not None
    return Composition(
        loaded=flat,
        urdf=joiner.robot,
        srdf=srdf,
        resolver=resolver,
        parts=tuple(composed),
    )


# ---------------------------------------------------------------------------------- semantics
def _ancestors(parent_of: Mapping[str, str], link: str) -> list[str]:
    out = [link]
    while out[-1] in parent_of:
        out.append(parent_of[out[-1]])
    return out


def _flat_spec(
    loaded: LoadedSpec,
    parts: Mapping[str, _Part],
    order: Sequence[str],
    names_of: Mapping[str, PartNames],
    srdf: Srdf | None,
    robot: etree._Element,
    diag: Diagnostics,
) -> LoadedSpec | None:
    """The composed robot's spec: every part's semantics renamed, then the spec's own entries."""
    spec = loaded.spec
    merged: dict[str, Any] = {s: {} for s in NAMED_SECTIONS}
    owner: dict[tuple[str, str], str] = {}
    velocity: dict[str, float] = {}
    controlled: list[str] = []
    any_controlled = False
    disabled: list[str] = []
    documents: list[LocatedYaml] = []
    import_states = False
    carried_before: set[str] = set()
    for name in order:
        part, n = parts[name], names_of[name]
        sem = rename_semantics(part.data, n, part.facts)
        loc: Loc = ("parts", name)
        carried_before.update(
            c["manipulator"] for c in sem.get("chains", {}).values() if c.get("manipulator")
        )
        for section in NAMED_SECTIONS:
            for key, value in sem.get(section, {}).items():
                other = owner.get((section, key))
                if other is not None:
                    diag.error(
                        loc,
                        f"{section[:-1]} '{key}' comes from both part '{other}' and part "
                        f"'{name}'; give part '{name}' a (different) prefix",
                        name=key,
                        kind="clash",
                    )
                    continue
                owner[(section, key)] = name
                merged[section][key] = value
        for key in ("torso", "neck"):
            if key in sem:
                if key in merged:
                    diag.error(
                        loc, f"both part '{owner[(key, '')]}' and part '{name}' have a {key}"
                    )
                    continue
                owner[(key, "")] = name
                merged[key] = sem[key]
        velocity.update(sem.get("velocity_limits", {}).get("joints", {}))
        if "controlled_joints" in sem:
            any_controlled = True
            controlled += sem["controlled_joints"]
        else:
            controlled += [n.joint(j) for j in part.facts.driven_joints]
        disabled += sem.get("collision", {}).get("disabled_bodies", [])
        import_states |= bool(sem.get("import_srdf_group_states"))
        documents += [remap_marks(d, n) for d in part.documents]
    base = parts[order[0]]
    base_names = names_of[order[0]]
    root = spec.root or base_names.link(base.spec_root or base.facts.roots[0])
    data: dict[str, Any] = {
        "name": spec.name,
        "description": {"urdf": str(loaded.file)},
        "root": root,
        **{k: v for k, v in merged.items() if v},
    }
    if base.drive is not None:
        drive = dict(base.drive)
        if drive.get("joint"):
            drive["joint"] = base_names.joint(drive["joint"])
        data["drive"] = drive
    if velocity:
        data["velocity_limits"] = {"joints": velocity}
    if any_controlled:
        data["controlled_joints"] = controlled
    collision: dict[str, Any] = dict(base.collision)
    if disabled:
        collision["disabled_bodies"] = disabled
    if collision:
        data["collision"] = collision
    if import_states:
        data["import_srdf_group_states"] = True
    own = spec.model_dump(mode="json", exclude_unset=True)
    for key, value in own.items():
        if key in ("parts", "description", "robotspec", "extends"):
            continue
        if isinstance(value, dict) and isinstance(data.get(key), dict):
            # Like ``extends``: an entry the spec names changes the part's entry key by key
            # (``chains: {ur5_arm: {tip: ...}}`` keeps the part's root and states).
            data[key] = merge_data(data[key], value)
        else:
            data[key] = value
    explicit = {c for c, chain in own.get("chains", {}).items() if "manipulator" in chain}
    tips = {
        g.name: g.chains[0].tip_link for g in (srdf.groups if srdf else ()) if len(g.chains) == 1
    }
    _hand_over_manipulators(data, explicit, tips, parts, order, owner, robot, names_of)
    # A part's manipulator that its own chain carried and no chain carries any more was
    # replaced (by a hand, or by the composed spec's own choice): it is not the robot's.
    carried = {c.get("manipulator") for c in data.get("chains", {}).values()}
    for m in [m for m in data.get("manipulators", {}) if m in carried_before - carried]:
        if m not in own.get("manipulators", {}):
            del data["manipulators"][m]
    try:
        flat = RobotSpec.model_validate(data)
    except ValidationError as exc:
        diag.add_all(validation_errors(exc, loaded.documents[0], RobotSpec, SpecError))
        return None
    return LoadedSpec(flat, loaded.file, (*loaded.documents, *documents))


def _hand_over_manipulators(
    data: dict[str, Any],
    explicit: set[str],
    group_tips: Mapping[str, str],
    parts: Mapping[str, _Part],
    order: Sequence[str],
    owner: Mapping[tuple[str, str], str],
    robot: etree._Element,
    names_of: Mapping[str, PartNames],
) -> None:
    """A welded hand's manipulator becomes the manipulator of the arm chain it is welded to.

    The chain chosen is the one whose tip is nearest above the weld link, among the parent
    part's chains and the composed spec's own (a chain given by SRDF group counts with the
    group's tip); a chain whose manipulator the composed spec names is left alone. Its previous
    manipulator (an arm's bare flange) is dropped unless another chain carries it or the composed
    spec names it: the hand's tool frame is now the chain's end.
    """
    chains: dict[str, Any] = data.get("chains", {})
    manips: dict[str, Any] = data.get("manipulators", {})
    parent_of = tree_facts(robot).parent_of
    for name in order:
        attach = parts[name].spec.attach
        if attach is None:
            continue
        carried = {c.get("manipulator") for c in chains.values()}
        free = [m for m in manips if owner.get(("manipulators", m)) == name and m not in carried]
        if len(free) != 1:
            continue
        above = _ancestors(parent_of, names_of[attach.part].link(attach.link))
        best: tuple[int, str] | None = None
        for cname, chain in chains.items():
            chain_owner = owner.get(("chains", cname))
            if cname in explicit or chain_owner not in (attach.part, None):
                continue
            tip = chain.get("tip") or group_tips.get(chain.get("group") or "")
            if tip not in above:
                continue
            depth = above.index(tip)
            if best is None or depth < best[0]:
                best = (depth, cname)
        if best is None:
            continue
        chains[best[1]]["manipulator"] = free[0]  # the one it replaces is dropped later
