"""A composed spec (``parts:``) to one URDF tree, one SRDF and one flat spec.

Pipeline: load every part (a URDF/xacro, or a spec, itself possibly composed), order the parts by
their welds (the base first), rename each part's names (:class:`PartNames`), weld the trees, merge
the SRDFs and the part specs' semantics, then let the composed spec's own entries override. The
compiler then treats the result like any flat spec; ``robotspec export urdf`` writes the tree.

Every problem of every part is collected and raised together, each at its spec line.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from robotspec.compose.flat_spec import flat_spec
from robotspec.compose.parts import Part, load_part, order_parts
from robotspec.compose.srdf_merge import merge_srdfs
from robotspec.compose.weld import ComposedPart, Joiner, pin_packages
from robotspec.description.srdf import Srdf
from robotspec.diagnostics import Diagnostics
from robotspec.files.packages import PackageResolver
from robotspec.spec.load import LoadedSpec, check_package_paths

__all__ = ["Composition", "compose"]


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


def compose(
    loaded: LoadedSpec,
    *,
    package_paths: Sequence[str | Path] = (),
    _seen: tuple[Path, ...] = (),
) -> Composition:
    """Join the parts of a composed spec; every problem is raised together."""
    check_package_paths(loaded, package_paths)
    spec = loaded.spec
    diag = Diagnostics(loaded)
    seen = (*_seen, loaded.file.resolve())
    order = order_parts(spec.parts, diag)
    loaded_parts: dict[str, Part] = {}
    share: PackageResolver | None = None
    for name in order:
        part = load_part(name, spec.parts[name], loaded, diag, package_paths, seen, share)
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
    joiner = Joiner(spec.name, diag, loaded_parts)
    composed = [c for c in map(joiner.add, order) if c is not None]
    diag.raise_if_failed()
    resolver = PackageResolver.joined([p.resolver for p in loaded_parts.values()])
    for part, meshes in joiner.meshes:
        pin_packages(part, meshes, resolver)
    srdf = merge_srdfs(spec.name, joiner.srdfs) if joiner.srdfs else None
    flat = flat_spec(loaded, loaded_parts, order, joiner.names_of, srdf, joiner.robot, diag)
    diag.raise_if_failed()
    assert flat is not None
    return Composition(
        loaded=flat,
        urdf=joiner.robot,
        srdf=srdf,
        resolver=resolver,
        parts=tuple(composed),
    )
