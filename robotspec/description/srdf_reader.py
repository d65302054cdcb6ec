"""Reading an SRDF file into :class:`~robotspec.description.srdf.Srdf` records, with lines.

Every problem of a file is collected and raised at once (MoveIt's dialect and the Giskard
aliases; unknown elements ignored, as MoveIt ignores them). See :mod:`robotspec.description.srdf`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Protocol, TypeVar

from lxml import etree

from robotspec.description.srdf import (
    VIRTUAL_JOINT_TYPES,
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
from robotspec.description.srdf_checks import by_line, check_srdf_references, group_cycle_errors
from robotspec.errors import (
    RobotSpecError,
    SrdfError,
    raise_collected,
)
from robotspec.files.xmlsafe import parse_xml_bytes

__all__ = ["load_srdf", "parse_srdf_bytes"]

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


# --------------------------------------------------------------------------------------------
# Reading


def load_srdf(path: str | Path, *, strict: bool = True) -> Srdf:
    """Read an SRDF file; every problem of the file is raised together.

    A missing or unreadable file is an SrdfError naming it.
    """
    from robotspec.files.limits import limits
    from robotspec.files.reading import read_bounded

    p = Path(path)
    data = read_bounded(
        p,
        cap=limits().max_srdf_bytes,
        cap_name="max_srdf_bytes",
        what="an SRDF file",
        error_type=SrdfError,
    )
    return parse_srdf_bytes(data, str(p), strict=strict)


def parse_srdf_bytes(data: bytes, file: str | None = None, *, strict: bool = True) -> Srdf:
    """Parse the bytes of an SRDF (``file`` names it in errors and in the result).

    Raises one SrdfError, or a RobotSpecErrors holding every problem found, in file order.
    """
    try:
        root = parse_xml_bytes(data, file or "<string>", SrdfError, cap_name="max_srdf_bytes")
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
    problems += group_cycle_errors(srdf)
    if strict:
        problems += check_srdf_references(srdf)
    problems.sort(key=by_line)
    raise_collected(problems, summary=f"{srdf._where()}: {len(problems)} problems")
    return srdf


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
        self.warnings: list[SrdfError] = []
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
        srdf = Srdf(
            robot_name=robot_name,
            file=self.file,
            groups=self._unique(self._all(root, ("group",), self.group), "group"),
            group_states=self._states(root),
            end_effectors=self._unique(
                self._all(root, ("end_effector",), self.end_effector), "end_effector"
            ),
            virtual_joints=self._first_virtual_joints(
                self._all(root, ("virtual_joint",), self.virtual_joint)
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
        return replace(srdf, warnings=tuple(self.warnings)) if self.warnings else srdf

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

    def _first_virtual_joints(self, joints: tuple[VirtualJoint, ...]) -> tuple[VirtualJoint, ...]:
        """Each virtual joint once, the first of a name kept, with a warning at each repeat.

        Why not an error: MoveIt's srdfdom reads the first and ignores the rest, so a file with a
        pasted-twice ``<virtual_joint>`` works in MoveIt; refusing the whole SRDF for it made
        every group and end effector of the file unusable.
        """
        first: dict[str, VirtualJoint] = {}
        for v in joints:
            kept = first.setdefault(v.name, v)
            if kept is v:
                continue
            same = (v.type, v.parent_frame, v.child_link) == (
                kept.type,
                kept.parent_frame,
                kept.child_link,
            )
            differs = (
                ""
                if same
                else (
                    f" (this one: {v.type} from '{v.parent_frame}' to '{v.child_link}'; the first: "
                    f"{kept.type} from '{kept.parent_frame}' to '{kept.child_link}')"
                )
            )
            self.warnings.append(
                SrdfError(
                    f"virtual_joint '{v.name}' is declared again (first on line {kept.line})"
                    f"{differs}; read as MoveIt does, the first declaration only (delete this one)",
                    file=self.file,
                    line=v.line,
                    kind="virtual_joint",
                    name=v.name,
                    severity="warning",
                )
            )
        return tuple(first.values())

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
