"""SRDF names as robots ship them: a robot prefix the URDF lacks, a link disabled against itself.

Why: SRDFs are often written for a namespaced robot (Baxter's in example-robot-data says
``baxter/head_pan`` for the URDF's ``head_pan``, as a ``tf_prefix`` or a multi-robot launch
writes it), and collision SRDFs from several public packages disable a link against itself.
MoveIt would reject or silently drop both; a user bringing such a robot needs to be told once, in
the SRDF's own terms, what robotspec did. A prefix that maps each name to exactly one URDF name is
read through (one warning per group); a name that could map to two URDF names, or two SRDF names
that would map to one, is a located error saying what to change in the SRDF.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass, field, replace
from typing import Protocol

from robotspec.description.srdf import (
    DisabledCollision,
    DisableDefaultCollisions,
    EnabledCollision,
    EndEffector,
    Group,
    GroupChain,
    GroupState,
    PassiveJoint,
    Srdf,
    VirtualJoint,
)
from robotspec.description.srdf_checks import by_line
from robotspec.errors import RobotSpecError, SrdfError

__all__ = ["PrefixMapping", "map_prefixed_names", "self_pair_warnings"]

#: How many renamings a warning shows before it says "and N more".
SHOWN = 3


#: Renames one name of a scope: (kind "link" or "joint", name, line) -> the name to use.
_Rename = Callable[[str, str, int | None], str]


class _Lined(Protocol):
    @property
    def line(self) -> int | None: ...


@dataclass
class _Scope:
    """The renamings of one group (its states included) or of one kind of element."""

    what: str
    line: int | None
    renamed: dict[str, str] = field(default_factory=dict)
    kinds: set[str] = field(default_factory=set)


@dataclass(frozen=True)
class PrefixMapping:
    """The SRDF with prefixed names read as the URDF's, and what to tell the user about it."""

    srdf: Srdf
    warnings: tuple[RobotSpecError, ...]
    errors: tuple[RobotSpecError, ...]
    #: (line, name) of every SRDF name that was left as written because it was ambiguous.
    ambiguous: frozenset[tuple[int | None, str]]


def _candidates(name: str, known: Collection[str]) -> list[str]:
    """URDF names ``name`` becomes once a ``prefix/`` is cut, longest remaining name first."""
    out: list[str] = []
    start = 0
    while True:
        cut = name.find("/", start)
        if cut < 0:
            return out
        rest = name[cut + 1 :]
        if rest and rest in known:
            out.append(rest)
        start = cut + 1


def _has_prefixed_name(srdf: Srdf) -> bool:
    """Whether any link or joint name the SRDF refers to has a ``/`` (only those are mapped)."""
    names = [
        *(n for g in srdf.groups for n in (*g.joints, *g.links)),
        *(n for g in srdf.groups for c in g.chains for n in (c.base_link, c.tip_link)),
        *(j for s in srdf.group_states for j, _ in s.joint_values),
        *(e.parent_link for e in srdf.end_effectors),
        *(v.child_link for v in srdf.virtual_joints),
        *(p.name for p in srdf.passive_joints),
        *(n for d in srdf.disabled_collisions for n in (d.link1, d.link2)),
        *(n for d in srdf.enabled_collisions for n in (d.link1, d.link2)),
        *(d.link for d in srdf.disable_default_collisions),
    ]
    return any("/" in n for n in names)


def map_prefixed_names(
    srdf: Srdf, links: Collection[str], joints: Collection[str]
) -> PrefixMapping:
    """Read SRDF names that carry a prefix the URDF's names lack as the URDF's names.

    A name the URDF has is never touched. Only a prefix ending in ``/`` is cut (a ROS namespace
    or ``tf_prefix``): cutting other text would guess.
    """
    if not _has_prefixed_name(srdf):  # the common case: nothing to map, nothing to rebuild
        return PrefixMapping(srdf, (), (), frozenset())
    ren = _Renamer(set(links), set(joints) | {v.name for v in srdf.virtual_joints}, srdf.file)
    groups, states = _groups(srdf, ren), _group_states(srdf, ren)  # their scopes first
    mapped = replace(_with_elements(srdf, ren), groups=groups, group_states=states)
    warnings = [_warning(scope, srdf.file) for scope in ren.scopes.values() if scope.renamed]
    warnings.sort(key=by_line)
    errors = sorted(ren.errors, key=by_line)
    if not warnings and not errors:
        return PrefixMapping(srdf, (), (), frozenset())
    return PrefixMapping(mapped, tuple(warnings), tuple(errors), frozenset(ren.ambiguous))


@dataclass
class _Renamer:
    """Cuts prefixes scope by scope, collecting the renamings, the errors and what stays."""

    links: set[str]
    joints: set[str]
    file: str | None
    scopes: dict[str, _Scope] = field(default_factory=dict)
    errors: list[RobotSpecError] = field(default_factory=list)
    ambiguous: set[tuple[int | None, str]] = field(default_factory=set)

    def scoped(self, key: str, what: str, line: int | None) -> _Rename:
        """A renamer for one scope (a group with its states, or one kind of element)."""
        scope = self.scopes.setdefault(key, _Scope(what, line))
        return lambda kind, name, at: self.rename(scope, kind, name, at)

    def rename(self, scope: _Scope, kind: str, name: str, line: int | None) -> str:
        """``name`` as the URDF's, when exactly one URDF name is it with a prefix cut."""
        known = self.links if kind == "link" else self.joints
        if name in known:
            return name
        found = _candidates(name, known)
        if not found:
            return name
        where = _short(self.file)
        if len(found) > 1:
            choices = " or ".join(f"'{f}'" for f in found)
            return self._keep(
                f"{kind} '{name}' of {scope.what} could be the URDF's {kind} {choices} "
                f"once a prefix is cut; write the URDF's name in {where}",
                kind,
                name,
                line,
                found,
            )
        target = found[0]
        clash = next((s for s, t in scope.renamed.items() if t == target and s != name), None)
        if clash is not None:
            return self._keep(
                f"{kind}s '{clash}' and '{name}' of {scope.what} would both be the URDF's "
                f"{kind} '{target}' once their prefixes are cut; keep one of them, "
                f"written '{target}', in {where}",
                kind,
                name,
                line,
                [target],
            )
        scope.renamed[name] = target
        scope.kinds.add(kind)
        return target

    def _keep(self, message: str, kind: str, name: str, line: int | None, found: list[str]) -> str:
        self.ambiguous.add((line, name))
        self.errors.append(
            SrdfError(message, file=self.file, line=line, kind=kind, name=name, suggestions=found)
        )
        return name


def _groups(srdf: Srdf, ren: _Renamer) -> tuple[Group, ...]:
    groups = []
    for g in srdf.groups:
        r = ren.scoped(f"group:{g.name}", f"group '{g.name}'", g.line)
        jl = _lines(g.joint_lines, len(g.joints), g.line)
        ll = _lines(g.link_lines, len(g.links), g.line)
        groups.append(
            replace(
                g,
                joints=tuple(r("joint", n, ln) for n, ln in zip(g.joints, jl, strict=True)),
                links=tuple(r("link", n, ln) for n, ln in zip(g.links, ll, strict=True)),
                chains=tuple(
                    GroupChain(
                        r("link", c.base_link, c.line or g.line),
                        r("link", c.tip_link, c.line or g.line),
                        c.line,
                    )
                    for c in g.chains
                ),
            )
        )
    return tuple(groups)


def _group_states(srdf: Srdf, ren: _Renamer) -> tuple[GroupState, ...]:
    """Each state renamed in its group's scope (one warning per group, states included)."""
    group_names = {g.name for g in srdf.groups}
    states = []
    for s in srdf.group_states:
        key = f"group:{s.group}" if s.group in group_names else f"state:{s.name}"
        r = ren.scoped(key, f"group '{s.group}'" if s.group else f"group_state '{s.name}'", s.line)
        sl = _lines(s.joint_lines, len(s.joint_values), s.line)
        states.append(
            replace(
                s,
                joint_values=tuple(
                    (r("joint", j, ln), v) for (j, v), ln in zip(s.joint_values, sl, strict=True)
                ),
            )
        )
    return tuple(states)


def _with_elements(srdf: Srdf, ren: _Renamer) -> Srdf:
    """The other elements renamed, each kind one scope placed at its first element's line."""

    def scope(tag: str, items: tuple[_Lined, ...]) -> _Rename:
        return ren.scoped(tag, f"the <{tag}> elements", next((x.line for x in items), None))

    r_ee = scope("end_effector", srdf.end_effectors)
    r_vj = scope("virtual_joint", srdf.virtual_joints)
    r_pj = scope("passive_joint", srdf.passive_joints)
    r_dc = scope("disable_collisions", srdf.disabled_collisions)
    r_ec = scope("enable_collisions", srdf.enabled_collisions)
    r_dd = scope("disable_default_collisions", srdf.disable_default_collisions)
    return replace(
        srdf,
        end_effectors=tuple(
            EndEffector(
                e.name, r_ee("link", e.parent_link, e.line), e.group, e.parent_group, e.line
            )
            for e in srdf.end_effectors
        ),
        virtual_joints=tuple(
            VirtualJoint(v.name, v.type, v.parent_frame, r_vj("link", v.child_link, v.line), v.line)
            for v in srdf.virtual_joints
        ),
        passive_joints=tuple(
            PassiveJoint(r_pj("joint", p.name, p.line), p.line) for p in srdf.passive_joints
        ),
        disabled_collisions=tuple(
            DisabledCollision(
                r_dc("link", d.link1, d.line), r_dc("link", d.link2, d.line), d.reason, d.line
            )
            for d in srdf.disabled_collisions
        ),
        enabled_collisions=tuple(
            EnabledCollision(
                r_ec("link", d.link1, d.line), r_ec("link", d.link2, d.line), d.reason, d.line
            )
            for d in srdf.enabled_collisions
        ),
        disable_default_collisions=tuple(
            DisableDefaultCollisions(r_dd("link", d.link, d.line), d.line)
            for d in srdf.disable_default_collisions
        ),
    )


def _warning(scope: _Scope, file: str | None) -> RobotSpecError:
    items = list(scope.renamed.items())
    prefixes = list(dict.fromkeys(src[: len(src) - len(dst)] for src, dst in items))
    shown = ", ".join(f"'{s}' as '{d}'" for s, d in items[:SHOWN])
    more = len(items) - SHOWN
    kinds = " and ".join(f"{k} names" for k in sorted(scope.kinds))
    prefix_text = " or ".join(f"'{p}'" for p in prefixes)
    return SrdfError(
        f"{scope.what}: {len(items)} {kinds} carry the prefix {prefix_text} that the URDF's "
        f"names lack; read as the URDF's names ({shown}{f' and {more} more' if more > 0 else ''})",
        file=file,
        line=scope.line,
        kind="prefix",
        name=prefixes[0],
        severity="warning",
    )


def self_pair_warnings(srdf: Srdf) -> list[RobotSpecError]:
    """One warning per ``disable_collisions`` of a link against itself (it is ignored)."""
    return [
        SrdfError(
            f"<disable_collisions> disables link '{d.link1}' against itself; a link is never "
            "checked against itself, so the entry is ignored (delete it)",
            file=srdf.file,
            line=d.line,
            kind="link",
            name=d.link1,
            severity="warning",
        )
        for d in srdf.disabled_collisions
        if d.link1 == d.link2
    ]


def _lines(own: tuple[int | None, ...], count: int, default: int | None) -> list[int | None]:
    return list(own) if len(own) == count else [default] * count


def _short(file: str | None) -> str:
    if not file:
        return "the SRDF"
    return file.rsplit("/", 1)[-1]
