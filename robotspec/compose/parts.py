"""Loading the parts of a composed spec and ordering them by their welds (the base first).

A part is a URDF/xacro file or a spec (itself possibly composed); each is read with its own
package resolver and SRDF, and its semantics renamed into the composed names.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from robotspec.compose.urdf_merge import (
    TreeFacts,
    absolute_mesh_paths,
    add_fixed_frames,
    tree_facts,
)
from robotspec.description.srdf import Srdf
from robotspec.diagnostics import Diagnostics, Loc
from robotspec.errors import RobotSpecError
from robotspec.files.packages import PackageResolver
from robotspec.files.yamlio import LocatedYaml
from robotspec.shipped import shipped_part_files, shipped_spec_files
from robotspec.spec.load import LoadedSpec, check_package_paths, load_spec
from robotspec.spec.models import DescriptionSpec, PartSpec

__all__ = ["Part", "description_tree", "load_part", "order_parts"]


@dataclass
class Part:
    """One part as loaded: its tree, SRDF, resolver and (renamed) semantics."""

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
    from robotspec.description.urdf_walk import check_urdf_tree

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
        from robotspec.description.srdf_reader import load_srdf

        srdf = load_srdf(resolve_file(desc.srdf, folder, resolver), strict=False)
    return tree, urdf, resolver, srdf


def spec_path(ref: str, folder: Path) -> Path | None:
    """A part's spec: a path, a shipped robot's name, or a shipped part's name."""
    p = Path(ref) if Path(ref).is_absolute() else folder / ref
    if p.is_file():
        return p
    key = ref.lower()
    return shipped_spec_files().get(key) or shipped_part_files().get(key)


def load_part(
    name: str,
    ps: PartSpec,
    loaded: LoadedSpec,
    diag: Diagnostics,
    package_paths: Sequence[str | Path],
    seen: tuple[Path, ...],
    share: PackageResolver | None,
) -> Part | None:
    """Load one part (URDF/xacro or spec) with its SRDF and renamed semantics, or ``None``.

    Problems go to ``diag`` at the part's spec line; ``share`` lends a resolver's package
    crawls to the next part.
    """
    loc: Loc = ("parts", name)
    try:
        if ps.spec is not None:
            return _spec_part(name, ps, ps.spec, loaded, diag, package_paths, seen, share)
        assert ps.urdf is not None  # PartSpec checks one of spec/urdf is given
        part_desc = DescriptionSpec(
            urdf=ps.urdf, srdf=ps.srdf, xacro_args=ps.xacro_args, package_paths=ps.package_paths
        )
        tree, file, resolver, srdf = description_tree(
            part_desc, loaded.folder, package_paths, share_crawls_with=share
        )
        return Part(name, ps, file, tree, srdf, resolver, tree_facts(tree))
    except RobotSpecError as exc:
        key = "spec" if ps.spec is not None else "urdf"
        diag.add_all(exc, (*loc, key))
        return None


def _spec_part(
    name: str,
    ps: PartSpec,
    ref: str,
    loaded: LoadedSpec,
    diag: Diagnostics,
    package_paths: Sequence[str | Path],
    seen: tuple[Path, ...],
    share: PackageResolver | None,
) -> Part | None:
    """A part given by a spec (``spec: ur5``): its own description, semantics and rules.

    A spec that is itself composed is composed first; a part that includes its includer is
    refused, naming the loop.
    """
    loc: Loc = ("parts", name)
    path = spec_path(ref, loaded.folder)
    if path is None:
        candidates = [
            *shipped_spec_files(),
            *(f.name for f in loaded.folder.glob("*.yaml")),
        ]
        diag.not_found(
            (*loc, "spec"),
            "spec",
            ref,
            candidates,
            "this folder or the shipped robots and parts",
        )
        return None
    if path.resolve() in seen:
        chain = " -> ".join(p.name for p in (*seen, path.resolve()))
        diag.error((*loc, "spec"), f"parts include each other: {chain}")
        return None
    part_loaded = load_spec(path, allowed=package_paths)
    check_package_paths(part_loaded, package_paths)
    if part_loaded.spec.parts:
        # A part may itself be composed: the one loop inside compose/, by design.
        from robotspec.compose.assembly import compose

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
    return Part(
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


# ------------------------------------------------------------------------------------ ordering
def order_parts(parts: Mapping[str, PartSpec], diag: Diagnostics) -> list[str]:
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
