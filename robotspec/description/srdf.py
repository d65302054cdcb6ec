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
is always an error, except a virtual joint declared twice: MoveIt keeps the first, so robotspec
warns at the second and reads the first (``Srdf.warnings``). A dangling group reference (a group
state or end effector naming a group the file does not define, a subgroup that is not defined, a
group state without a group) is an error in strict mode, the default. MoveIt logs and skips such
elements and pinocchio ignores groups altogether, so several pinocchio-made SRDFs of
example-robot-data have them; ``strict=False`` keeps them as they are and
:func:`check_srdf_references` lists them.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from robotspec.errors import (
    NotFoundError,
    SrdfError,
)

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
]

#: The virtual joint types MoveIt knows (srdfdom compares them lower-cased).
VIRTUAL_JOINT_TYPES = ("fixed", "floating", "planar")

# A C-style decimal number, as srdfdom's stream parsing reads it. Python's float() also takes
# "1_000", "nan" and "infinity", none of which MoveIt would accept.


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
    #: What the reader passed over as MoveIt does (a second virtual joint of one name), each a
    #: located warning the compiler reports; not part of the file's contents, so never compared.
    warnings: tuple[SrdfError, ...] = field(default=(), compare=False)

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

        # An explicit stack, not recursion: a 1,500-deep chain of subgroups is valid input.
        first = self.group(name)
        seen.add(first.name)
        out.update(dict.fromkeys(first.joints))
        stack: list[Iterator[str]] = [iter(first.subgroups)]
        while stack:
            sub = next(stack[-1], None)
            if sub is None:
                stack.pop()
                continue
            group = by_name.get(sub)
            if group is None or group.name in seen:
                continue
            seen.add(group.name)
            out.update(dict.fromkeys(group.joints))
            stack.append(iter(group.subgroups))
        return list(out)

    def disabled_pairs(self) -> frozenset[frozenset[str]]:
        """Every ``disable_collisions`` pair, unordered.

        Why enabled pairs are not subtracted: MoveIt applies ``enable_collisions`` before
        ``disable_collisions``, so a pair listed in both stays disabled.
        """
        return frozenset(frozenset((d.link1, d.link2)) for d in self.disabled_collisions)

    def _where(self) -> str:
        return _short(self.file) if self.file else "the SRDF"


def _short(file: str) -> str:
    return file.replace("\\", "/").rsplit("/", 1)[-1]
