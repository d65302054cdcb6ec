"""Read and check MoveIt SRDF files (Semantic Robot Description Format).

Why our own reader: srdfdom is C++ and ROS-only, and its Python port drops line numbers and logs
problems instead of reporting them. This module parses the element tree safely (``xmlsafe``),
keeps each element's line, and reports every problem of a file at once, in the package's error
types, so a user can fix an SRDF in one pass.

Two dialects are read. MoveIt's (``disable_collisions``, ``disable_default_collisions``,
``enable_collisions``) and the Giskard one used by the semantic-digital-twin reference, whose
``disable_all_collisions link=`` and ``disable_self_collision link1= link2=`` are read as aliases
of MoveIt's tags. Elements MoveIt does not know (pinocchio's ``rotor_params``, ``specificities``,
``gripper``) are ignored, as MoveIt ignores them. The writer (:mod:`robotspec.export.srdf`)
always writes MoveIt's dialect.

Problems come in two grades. A malformed file (a missing required attribute, a number that is not
a number, an unknown virtual joint type, two groups of one name, groups that contain each other)
is always an error. A dangling group reference (a group state or end effector naming a group the
file does not define, a subgroup that is not defined, a group state without a group) is an error
in strict mode, the default. MoveIt logs and skips such elements and pinocchio ignores groups
altogether, so several pinocchio-made SRDFs of example-robot-data have them; ``strict=False``
keeps them as they are and :func:`check_srdf_references` lists them.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Collection, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol, TypeVar

from lxml import etree

from robotspec.errors import (
    NotFoundError,
    RobotSpecError,
    SrdfError,
    raise_collected,
)
from robotspec.files.xmlsafe import parse_xml_bytes

__all__ = [
    "VIRTUAL_JOINT_TYPES",
    "DisableDefaultCollisions",
    "DisabledCollision",
    "EnabledCollision",
    "EndEffector",
    "Group",
    "GroupChain",
    "GroupState",
    "PassiveJoint",
    "Srdf",
    "SrdfNotFoundError",
    "VirtualJoint",
    "check_srdf_against",
    "check_srdf_references",
    "load_srdf",
    "parse_srdf_bytes",
]

#: The virtual joint types MoveIt knows (srdfdom compares them lower-cased).
VIRTUAL_JOINT_TYPES = ("fixed", "floating", "planar")

# A C-style decimal number, as srdfdom's stream parsing reads it. Python's float() also takes
# "1_000", "nan" and "infinity", none of which MoveIt would accept.
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


class SrdfNotFoundError(NotFoundError, SrdfError):
    """A name an SRDF uses that is defined neither in the SRDF nor in its URDF.

    Why both bases: callers that catch SRDF problems catch this too, and it renders like every
    other "not found" error of the package (with the closest names).
    """


# --------------------------------------------------------------------------------------------
# Records


@dataclass(frozen=True, slots=True)
class GroupChain:
    """A ``<chain>`` of a group: every link from ``base_link`` to ``tip_link`` (needs the URDF)."""

    base_link: str
    tip_link: str
    line: int | None = None


@dataclass(frozen=True, slots=True)
class Group:
    """A ``<group>``: joints, links, chains and other groups, in the SRDF's own terms.

    The ``*_lines`` fields hold the line of each member, so that a missing member is reported
    where it is written; they are not part of a group's value (excluded from equality).
    """

    name: str
    joints: tuple[str, ...] = ()
    links: tuple[str, ...] = ()
    chains: tuple[GroupChain, ...] = ()
    subgroups: tuple[str, ...] = ()
    line: int | None = None
    joint_lines: tuple[int | None, ...] = field(default=(), compare=False, repr=False)
    link_lines: tuple[int | None, ...] = field(default=(), compare=False, repr=False)
    subgroup_lines: tuple[int | None, ...] = field(default=(), compare=False, repr=False)


@dataclass(frozen=True, slots=True)
class GroupState:
    """A named configuration of a group; a multi-DOF joint holds several values.

    ``group`` is ``None`` only for a pinocchio-style state without a group, read with
    ``strict=False``.
    """

    name: str
    group: str | None
    joint_values: tuple[tuple[str, tuple[float, ...]], ...] = ()
    line: int | None = None
    joint_lines: tuple[int | None, ...] = field(default=(), compare=False, repr=False)


@dataclass(frozen=True, slots=True)
class EndEffector:
    """An ``<end_effector>``: the group that acts, attached to ``parent_link``."""

    name: str
    parent_link: str
    group: str
    parent_group: str | None = None
    line: int | None = None


@dataclass(frozen=True, slots=True)
class VirtualJoint:
    """A joint between an outside frame (``parent_frame``) and the URDF's ``child_link``."""

    name: str
    type: str
    parent_frame: str
    child_link: str
    line: int | None = None


@dataclass(frozen=True, slots=True)
class PassiveJoint:
    """A joint that is not actuated (planners leave it alone)."""

    name: str
    line: int | None = None


@dataclass(frozen=True, slots=True)
class DisabledCollision:
    """A link pair never checked for collision (``reason``: Adjacent, Never, Default, ...)."""

    link1: str
    link2: str
    reason: str | None = None
    line: int | None = None


@dataclass(frozen=True, slots=True)
class DisableDefaultCollisions:
    """A link whose collisions are off unless an ``enable_collisions`` pair turns one on."""

    link: str
    line: int | None = None


@dataclass(frozen=True, slots=True)
class EnabledCollision:
    """A link pair re-enabled after ``disable_default_collisions`` (disabled pairs still win)."""

    link1: str
    link2: str
    reason: str | None = None
    line: int | None = None


@dataclass(frozen=True, slots=True)
class Srdf:
    """The contents of one SRDF file, in file order within each kind of element."""

    robot_name: str
    file: str | None = None
    groups: tuple[Group, ...] = ()
    group_states: tuple[GroupState, ...] = ()
    end_effectors: tuple[EndEffector, ...] = ()
    virtual_joints: tuple[VirtualJoint, ...] = ()
    passive_joints: tuple[PassiveJoint, ...] = ()
    disabled_collisions: tuple[DisabledCollision, ...] = ()
    disable_default_collisions: tuple[DisableDefaultCollisions, ...] = ()
    enabled_collisions: tuple[EnabledCollision, ...] = ()

    @property
    def group_names(self) -> tuple[str, ...]:
        """The group names in file order."""
        return tuple(g.name for g in self.groups)

    def group(self, name: str) -> Group:
        """The group called ``name``; a NotFoundError with the closest names otherwise."""
        for g in self.groups:
            if g.name == name:
                return g
        raise SrdfNotFoundError(
            "group", name, self.group_names, where=self._where(), file=self.file
        )

    def group_joints(self, name: str) -> list[str]:
        """The joints a group names, itself and through its subgroups, first mention first.

        Why not chains: a chain's joints are known only with the URDF. Subgroups the SRDF does not
        define (possible only with ``strict=False``) are skipped; a cycle is walked once.
        """
        by_name = {g.name: g for g in self.groups}
        out: dict[str, None] = {}
        seen: set[str] = set()

        def visit(group: Group) -> None:
            if group.name in seen:
                return
            seen.add(group.name)
            out.update(dict.fromkeys(group.joints))
            for sub in group.subgroups:
                if sub in by_name:
                    visit(by_name[sub])

        visit(self.group(name))
        return list(out)

    def disabled_pairs(self) -> frozenset[frozenset[str]]:
        """Every ``disable_collisions`` pair, unordered.

        Why enabled pairs are not subtracted: MoveIt applies ``enable_collisions`` before
        ``disable_collisions``, so a pair listed in both stays disabled.
        """
        return frozenset(frozenset((d.link1, d.link2)) for d in self.disabled_collisions)

    def _where(self) -> str:
        return _short(self.file) if self.file else "the SRDF"


# --------------------------------------------------------------------------------------------
# Reading


def load_srdf(path: str | Path, *, strict: bool = True) -> Srdf:
    """Read an SRDF file; every problem of the file is raised together.

    A missing or unreadable file is an SrdfError naming it.
    """
    p = Path(path)
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise SrdfError("file not found", file=str(p)) from None
    except IsADirectoryError:
        raise SrdfError("is a directory, not an SRDF file", file=str(p)) from None
    except OSError as exc:
        raise SrdfError(f"cannot read file: {exc.strerror}", file=str(p)) from None
    return parse_srdf_bytes(data, str(p), strict=strict)


def parse_srdf_bytes(data: bytes, file: str | None = None, *, strict: bool = True) -> Srdf:
    """Parse the bytes of an SRDF (``file`` names it in errors and in the result).

    Raises one SrdfError, or a RobotSpecErrors holding every problem found, in file order.
    """
    try:
        root = parse_xml_bytes(data, file or "<string>", SrdfError)
    except RobotSpecError as exc:
        if file is None:
            raise exc.located(file=None, line=exc.line, column=exc.column) from None
        raise
    if root.tag != "robot":
        raise SrdfError(
            f"root element must be <robot>, got <{root.tag}>",
            file=file,
            line=_line(root),
            kind="robot",
        )
    reader = _Reader(file)
    srdf = reader.read(root)
    problems = list(reader.errors)
    problems += _cycle_errors(srdf)
    if strict:
        problems += check_srdf_references(srdf)
    problems.sort(key=_line_key)
    raise_collected(problems, summary=f"{srdf._where()}: {len(problems)} problems")
    return srdf


def _line_key(err: RobotSpecError) -> int:
    return err.line if err.line is not None else 1 << 62


def _short(file: str) -> str:
    return file.replace("\\", "/").rsplit("/", 1)[-1]


_T = TypeVar("_T")


class _Named(Protocol):
    @property
    def name(self) -> str: ...

    @property
    def line(self) -> int | None: ...


_N = TypeVar("_N", bound=_Named)


def _line(el: etree._Element) -> int | None:
    # lxml-stubs types ``sourceline`` wrongly; lxml gives an int, or None for built trees.
    line: object = el.sourceline
    return line if isinstance(line, int) else None


def _children(el: etree._Element, *tags: str) -> Iterator[etree._Element]:
    # Direct children with one of ``tags``; comments and PIs have non-string tags and never match.
    for child in el:
        if isinstance(child.tag, str) and child.tag in tags:
            yield child


class _Reader:
    """Turns the element tree into records, collecting problems instead of stopping at one."""

    def __init__(self, file: str | None) -> None:
        self.file = file
        self.errors: list[RobotSpecError] = []
        # The root's children by tag, with their document position: one pass over a file
        # whose thousand ``disable_collisions`` would otherwise be walked once per element kind.
        self._by_tag: dict[str, list[tuple[int, etree._Element]]] = {}

    def error(self, message: str, el: etree._Element, *, kind: str, name: str | None) -> None:
        self.errors.append(SrdfError(message, file=self.file, line=_line(el), kind=kind, name=name))

    def attr(
        self, el: etree._Element, attr: str, what: str, *, kind: str, name: str | None = None
    ) -> str | None:
        """A required attribute (whitespace trimmed, as srdfdom does), or a collected error."""
        value = (el.get(attr) or "").strip()
        if not value:
            self.error(f"{what} has no {attr} attribute", el, kind=kind, name=name)
            return None
        return value

    def read(self, root: etree._Element) -> Srdf:
        for i, child in enumerate(root):
            if isinstance(child.tag, str):
                self._by_tag.setdefault(child.tag, []).append((i, child))
        robot_name = self.attr(root, "name", "<robot>", kind="robot") or ""
        return Srdf(
            robot_name=robot_name,
            file=self.file,
            groups=self._unique(self._all(root, ("group",), self.group), "group"),
            group_states=self._states(root),
            end_effectors=self._unique(
                self._all(root, ("end_effector",), self.end_effector), "end_effector"
            ),
            virtual_joints=self._unique(
                self._all(root, ("virtual_joint",), self.virtual_joint), "virtual_joint"
            ),
            passive_joints=self._all(root, ("passive_joint",), self.passive_joint),
            disabled_collisions=self._all(
                root, ("disable_collisions", "disable_self_collision"), self.disabled
            ),
            disable_default_collisions=self._all(
                root, ("disable_default_collisions", "disable_all_collisions"), self.no_default
            ),
            enabled_collisions=self._all(root, ("enable_collisions",), self.enabled),
        )

    def _all(
        self,
        root: etree._Element,
        tags: tuple[str, ...],
        read: Callable[[etree._Element], _T | None],
    ) -> tuple[_T, ...]:
        """Every root child with one of ``tags`` (aliases included), read in document order."""
        found = [item for tag in tags for item in self._by_tag.get(tag, ())]
        if len(tags) > 1:
            found.sort(key=lambda item: item[0])
        out = [read(el) for _, el in found]
        return tuple(r for r in out if r is not None)

    def _unique(self, records: tuple[_N, ...], kind: str) -> tuple[_N, ...]:
        first: dict[str, int | None] = {}
        for r in records:
            name, line = r.name, r.line
            if name in first:
                self.errors.append(
                    SrdfError(
                        f"{kind} '{name}' is defined twice (first on line {first[name]})",
                        file=self.file,
                        line=line,
                        kind=kind,
                        name=name,
                    )
                )
            else:
                first[name] = line
        return records

    def group(self, el: etree._Element) -> Group | None:
        name = self.attr(el, "name", "<group>", kind="group")
        what = f"group '{name}'" if name else "<group>"
        joints: list[tuple[str, int | None]] = []
        links: list[tuple[str, int | None]] = []
        subgroups: list[tuple[str, int | None]] = []
        chains: list[GroupChain] = []
        for child in _children(el, "joint", "link", "chain", "group"):
            tag = str(child.tag)
            if tag == "chain":
                base = self.attr(child, "base_link", f"<chain> of {what}", kind="group", name=name)
                tip = self.attr(child, "tip_link", f"<chain> of {what}", kind="group", name=name)
                if base is not None and tip is not None:
                    chains.append(GroupChain(base, tip, _line(child)))
                continue
            member = self.attr(child, "name", f"<{tag}> of {what}", kind="group", name=name)
            if member is None:
                continue
            target = {"joint": joints, "link": links, "group": subgroups}[tag]
            target.append((member, _line(child)))
        if name is None:
            return None
        return Group(
            name=name,
            joints=tuple(n for n, _ in joints),
            links=tuple(n for n, _ in links),
            chains=tuple(chains),
            subgroups=tuple(n for n, _ in subgroups),
            line=_line(el),
            joint_lines=tuple(line for _, line in joints),
            link_lines=tuple(line for _, line in links),
            subgroup_lines=tuple(line for _, line in subgroups),
        )

    def _states(self, root: etree._Element) -> tuple[GroupState, ...]:
        states = self._all(root, ("group_state",), self.group_state)
        first: dict[tuple[str, str | None], int | None] = {}
        for s in states:
            key = (s.name, s.group)
            if key in first:
                self.errors.append(
                    SrdfError(
                        f"group_state '{s.name}' of group '{s.group}' is defined twice "
                        f"(first on line {first[key]})",
                        file=self.file,
                        line=s.line,
                        kind="group_state",
                        name=s.name,
                    )
                )
            else:
                first[key] = s.line
        return states

    def group_state(self, el: etree._Element) -> GroupState | None:
        name = self.attr(el, "name", "<group_state>", kind="group_state")
        group = (el.get("group") or "").strip() or None
        what = f"group_state '{name}'" if name else "<group_state>"
        values: list[tuple[str, tuple[float, ...]]] = []
        lines: list[int | None] = []
        for child in _children(el, "joint"):
            joint = self.attr(child, "name", f"<joint> of {what}", kind="group_state", name=name)
            label = f"<joint '{joint}'> of {what}" if joint else f"<joint> of {what}"
            text = self.attr(child, "value", label, kind="group_state", name=name)
            if joint is None or text is None:
                continue
            numbers = self.numbers(text, f"{what}: value of joint '{joint}'", child, name)
            if numbers is not None:
                values.append((joint, numbers))
                lines.append(_line(child))
        if name is None:
            return None
        return GroupState(name, group, tuple(values), _line(el), tuple(lines))

    def numbers(
        self, text: str, what: str, el: etree._Element, name: str | None
    ) -> tuple[float, ...] | None:
        out: list[float] = []
        for part in text.replace(",", " ").split():
            if not _NUMBER.fullmatch(part):
                self.error(f"{what}: '{part}' is not a number", el, kind="group_state", name=name)
                return None
            v = float(part)
            if not math.isfinite(v):
                self.error(
                    f"{what} must be finite, got '{part}'", el, kind="group_state", name=name
                )
                return None
            out.append(v)
        return tuple(out)

    def end_effector(self, el: etree._Element) -> EndEffector | None:
        name = self.attr(el, "name", "<end_effector>", kind="end_effector")
        what = f"end_effector '{name}'" if name else "<end_effector>"
        parent_link = self.attr(el, "parent_link", what, kind="end_effector", name=name)
        group = self.attr(el, "group", what, kind="end_effector", name=name)
        parent_group = (el.get("parent_group") or "").strip() or None
        if name is None or parent_link is None or group is None:
            return None
        return EndEffector(name, parent_link, group, parent_group, _line(el))

    def virtual_joint(self, el: etree._Element) -> VirtualJoint | None:
        name = self.attr(el, "name", "<virtual_joint>", kind="virtual_joint")
        what = f"virtual_joint '{name}'" if name else "<virtual_joint>"
        got = [
            self.attr(el, a, what, kind="virtual_joint", name=name)
            for a in ("type", "parent_frame", "child_link")
        ]
        jtype, parent, child = got
        if jtype is not None and jtype.lower() not in VIRTUAL_JOINT_TYPES:
            self.error(
                f"{what} has type '{jtype}'; expected one of {', '.join(VIRTUAL_JOINT_TYPES)}",
                el,
                kind="virtual_joint",
                name=name,
            )
            return None
        if name is None or jtype is None or parent is None or child is None:
            return None
        return VirtualJoint(name, jtype.lower(), parent, child, _line(el))

    def passive_joint(self, el: etree._Element) -> PassiveJoint | None:
        name = self.attr(el, "name", "<passive_joint>", kind="passive_joint")
        return None if name is None else PassiveJoint(name, _line(el))

    def _pair(self, el: etree._Element) -> tuple[str, str, str | None] | None:
        what = f"<{el.tag}>"
        link1 = self.attr(el, "link1", what, kind="collision")
        link2 = self.attr(el, "link2", what, kind="collision")
        if link1 is None or link2 is None:
            return None
        return link1, link2, el.get("reason")

    def disabled(self, el: etree._Element) -> DisabledCollision | None:
        pair = self._pair(el)
        return None if pair is None else DisabledCollision(*pair, line=_line(el))

    def enabled(self, el: etree._Element) -> EnabledCollision | None:
        pair = self._pair(el)
        return None if pair is None else EnabledCollision(*pair, line=_line(el))

    def no_default(self, el: etree._Element) -> DisableDefaultCollisions | None:
        link = self.attr(el, "link", f"<{el.tag}>", kind="collision")
        return None if link is None else DisableDefaultCollisions(link, _line(el))


def _cycle_errors(srdf: Srdf) -> list[RobotSpecError]:
    """One error per cycle of groups containing each other, at the cycle's first group."""
    by_name = {g.name: g for g in srdf.groups}
    order = {name: i for i, name in enumerate(by_name)}
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    found: dict[tuple[str, ...], Group] = {}

    def visit(name: str, path: list[str]) -> None:
        state[name] = 1
        path.append(name)
        for sub in by_name[name].subgroups:
            if sub not in by_name:
                continue
            if state.get(sub) == 1:
                cycle = path[path.index(sub) :]
                start = min(range(len(cycle)), key=lambda i: order[cycle[i]])
                key = tuple(cycle[start:] + cycle[:start])
                found.setdefault(key, by_name[key[0]])
            elif sub not in state:
                visit(sub, path)
        path.pop()
        state[name] = 2

    for name in by_name:
        if name not in state:
            visit(name, [])
    return [
        SrdfError(
            f"groups contain each other: {' -> '.join((*cycle, cycle[0]))}",
            file=srdf.file,
            line=group.line,
            kind="group",
            name=group.name,
        )
        for cycle, group in found.items()
    ]


def check_srdf_references(srdf: Srdf) -> list[RobotSpecError]:
    """The SRDF's references to groups it does not define, in file order.

    A group state without a group counts too: MoveIt needs the group to know what the state sets.
    ``parse_srdf_bytes`` raises these in strict mode; this lists them for files read leniently.
    """
    names = srdf.group_names
    where = srdf._where()
    out: list[RobotSpecError] = []

    def missing(name: str, role: str, line: int | None) -> None:
        out.append(
            SrdfNotFoundError(
                "group", name, names, where=f"{where} ({role})", file=srdf.file, line=line
            )
        )

    for g in srdf.groups:
        lines = g.subgroup_lines or (g.line,) * len(g.subgroups)
        for sub, line in zip(g.subgroups, lines, strict=False):
            if sub not in names:
                missing(sub, f"subgroup of group '{g.name}'", line)
    for s in srdf.group_states:
        if s.group is None:
            out.append(
                SrdfError(
                    f"group_state '{s.name}' has no group attribute",
                    file=srdf.file,
                    line=s.line,
                    kind="group_state",
                    name=s.name,
                )
            )
        elif s.group not in names:
            missing(s.group, f"group of group_state '{s.name}'", s.line)
    for e in srdf.end_effectors:
        if e.group not in names:
            missing(e.group, f"group of end_effector '{e.name}'", e.line)
        if e.parent_group is not None and e.parent_group not in names:
            missing(e.parent_group, f"parent_group of end_effector '{e.name}'", e.line)
    out.sort(key=_line_key)
    return out


# --------------------------------------------------------------------------------------------
# Checking against the URDF


def check_srdf_against(
    srdf: Srdf, links: Collection[str], joints: Collection[str], *, urdf_name: str
) -> list[RobotSpecError]:
    """Every link and joint name the SRDF uses that the URDF lacks, in file order.

    Why virtual joints count as joints: MoveIt adds them to the robot model, so groups and group
    states may name them (HSRB's ``world_joint``). A virtual joint's ``parent_frame`` is outside
    the robot and is not checked. Identical messages on one line are reported once.
    """
    # Lists keep the URDF's order, so that equally close suggestions always come in one order.
    link_pool = list(dict.fromkeys(links))
    joint_pool = list(dict.fromkeys([*joints, *(v.name for v in srdf.virtual_joints)]))
    link_set, joint_set = set(link_pool), set(joint_pool)
    found: list[RobotSpecError] = []

    def need(kind: str, name: str, line: int | None) -> None:
        pool = link_pool if kind == "link" else joint_pool
        known = link_set if kind == "link" else joint_set
        if name not in known:
            found.append(
                SrdfNotFoundError(kind, name, pool, where=urdf_name, file=srdf.file, line=line)
            )

    def lines(own: tuple[int | None, ...], count: int, default: int | None) -> list[int | None]:
        return list(own) if len(own) == count else [default] * count

    for g in srdf.groups:
        for name, line in zip(g.joints, lines(g.joint_lines, len(g.joints), g.line), strict=True):
            need("joint", name, line)
        for name, line in zip(g.links, lines(g.link_lines, len(g.links), g.line), strict=True):
            need("link", name, line)
        for c in g.chains:
            need("link", c.base_link, c.line if c.line is not None else g.line)
            need("link", c.tip_link, c.line if c.line is not None else g.line)
    for s in srdf.group_states:
        state_lines = lines(s.joint_lines, len(s.joint_values), s.line)
        for (name, _), line in zip(s.joint_values, state_lines, strict=True):
            need("joint", name, line)
    for e in srdf.end_effectors:
        need("link", e.parent_link, e.line)
    for v in srdf.virtual_joints:
        need("link", v.child_link, v.line)
    for p in srdf.passive_joints:
        need("joint", p.name, p.line)
    for d in srdf.disable_default_collisions:
        need("link", d.link, d.line)
    pairs: list[DisabledCollision | EnabledCollision] = [
        *srdf.disabled_collisions,
        *srdf.enabled_collisions,
    ]
    for pair in pairs:
        need("link", pair.link1, pair.line)
        need("link", pair.link2, pair.line)
    seen: set[tuple[int | None, str]] = set()
    unique: list[RobotSpecError] = []
    for err in found:
        key = (err.line, err.message)
        if key not in seen:
            seen.add(key)
            unique.append(err)
    unique.sort(key=_line_key)
    return unique
