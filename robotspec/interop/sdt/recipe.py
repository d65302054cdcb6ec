"""A compiled robot as SDT part recipes: plain data, no SDT import.

Why a recipe between the two models: SDT wires a robot by *classes* (one class per part, the
tree given by generic type parameters: ``Arm[Gripper]``, ``HasLeftRightArm[L, R]``), and its
world copy, pickles and ORM find those classes again by import path. A recipe is the
hashable, JSON-able description a class is generated from: the same robot gives equal
recipes, equal recipes give the same class (:mod:`robotspec.interop.sdt.classes`), and a
fresh process can rebuild a class from its stored recipe. The mapping itself (which part
becomes which SDT kind, which joints get hardware interfaces, which states have an SDT kind)
is decided in :mod:`robotspec.interop.sdt.mapping`, as these recipes, testably, without SDT.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field
from typing import Any, Literal

__all__ = ["PartKind", "PartRecipe", "RobotRecipe", "StateRecipe"]

PartKind = Literal[
    "mobile_base", "torso", "neck", "arm", "end_effector", "finger", "camera", "sensor"
]


@dataclass(frozen=True)
class StateRecipe:
    """A named joint state of a part with its SDT kind; joints in the spec's order."""

    name: str
    kind: tuple[str, str]
    joints: tuple[tuple[str, float], ...]


@dataclass(frozen=True)
class PartRecipe:
    """One SDT part: its kind, bodies, values, and the parts SDT hangs below it.

    ``children`` are SDT's slots, in the order the generic parameters take them: ``torso``,
    ``neck``, ``arms`` (left then right for two arms), ``end_effector``, ``fingers`` (thumb
    first), ``sensors``.
    """

    kind: PartKind
    name: str
    root: str
    tip: str | None = None
    tool_frame: str | None = None
    front_facing_orientation: tuple[float, float, float, float] | None = None
    front_facing_axis: tuple[float, float, float] | None = None
    forward_facing_axis: tuple[float, float, float] | None = None
    field_of_view: tuple[float, float] | None = None  # (vertical, horizontal), rad
    minimal_height: float | None = None
    maximal_height: float | None = None
    default_camera: bool = False
    hardware_joints: tuple[str, ...] = ()
    states: tuple[StateRecipe, ...] = ()
    children: tuple[tuple[str, tuple[PartRecipe, ...]], ...] = ()

    def slot(self, name: str) -> tuple[PartRecipe, ...]:
        """The parts in one of SDT's slots (empty when absent)."""
        return dict(self.children).get(name, ())

    def walk(self) -> list[PartRecipe]:
        """This part and every part below it, depth first."""
        out = [self]
        for _, parts in self.children:
            for p in parts:
                out.extend(p.walk())
        return out


@dataclass(frozen=True)
class RobotRecipe:
    """The robot: its root, its parts, and what the robot itself holds in SDT.

    ``extra_hardware_joints`` are controlled joints that move no part SDT has a kind for
    (set on the world after SDT's ``from_world``). ``left_out`` says, one line each, what of
    the robotspec robot has no place in SDT.
    """

    name: str
    root: str
    source: str
    children: tuple[tuple[str, tuple[PartRecipe, ...]], ...]
    disabled_pairs: tuple[tuple[str, str], ...]
    disabled_bodies: tuple[str, ...]
    buffer_zone_distance: float
    violated_distance: float
    collisions_disabled: bool
    extra_hardware_joints: tuple[str, ...] = ()
    left_out: tuple[str, ...] = field(default=(), compare=False)

    def slot(self, name: str) -> tuple[PartRecipe, ...]:
        """The parts in one of SDT's slots of the robot (empty when absent)."""
        return dict(self.children).get(name, ())

    def parts(self) -> list[PartRecipe]:
        """Every part, depth first."""
        return [q for _, ps in self.children for p in ps for q in p.walk()]

    def digest(self) -> str:
        """A short hash of the recipe's content: the suffix of its generated class names.

        A function of the robot, not of the machine: the recipe holds body, joint and part
        names, values and a portable ``source`` (:func:`portable_source`), no machine path, so
        the same spec gives the same digest wherever its files are installed.
        """
        data = asdict(self)
        data.pop("left_out")
        text = json.dumps(data, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:10]

    def to_json(self) -> dict[str, Any]:
        """The recipe as JSON data (what a fresh process rebuilds its classes from)."""
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RobotRecipe:
        """The inverse of :meth:`to_json`."""
        return cls(
            name=data["name"],
            root=data["root"],
            source=data["source"],
            children=_children_from_json(data["children"]),
            disabled_pairs=tuple((a, b) for a, b in data["disabled_pairs"]),
            disabled_bodies=tuple(data["disabled_bodies"]),
            buffer_zone_distance=float(data["buffer_zone_distance"]),
            violated_distance=float(data["violated_distance"]),
            collisions_disabled=bool(data["collisions_disabled"]),
            extra_hardware_joints=tuple(data["extra_hardware_joints"]),
            left_out=tuple(data["left_out"]),
        )


def _tuple_or_none(v: Any) -> Any:
    return None if v is None else tuple(v)


def _part_from_json(d: dict[str, Any]) -> PartRecipe:
    return PartRecipe(
        kind=d["kind"],
        name=d["name"],
        root=d["root"],
        tip=d["tip"],
        tool_frame=d["tool_frame"],
        front_facing_orientation=_tuple_or_none(d["front_facing_orientation"]),
        front_facing_axis=_tuple_or_none(d["front_facing_axis"]),
        forward_facing_axis=_tuple_or_none(d["forward_facing_axis"]),
        field_of_view=_tuple_or_none(d["field_of_view"]),
        minimal_height=d["minimal_height"],
        maximal_height=d["maximal_height"],
        default_camera=bool(d["default_camera"]),
        hardware_joints=tuple(d["hardware_joints"]),
        states=tuple(
            StateRecipe(
                name=s["name"],
                kind=(s["kind"][0], s["kind"][1]),
                joints=tuple((j, float(v)) for j, v in s["joints"]),
            )
            for s in d["states"]
        ),
        children=_children_from_json(d["children"]),
    )


def _children_from_json(data: Any) -> tuple[tuple[str, tuple[PartRecipe, ...]], ...]:
    return tuple((slot, tuple(_part_from_json(p) for p in parts)) for slot, parts in data)
