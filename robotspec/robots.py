"""Importable robots, one class per shipped spec: ``from robotspec.robots import PR2, HSRB``.

Each class is an :class:`~robotspec.semantic.AbstractRobot` whose ``from_world(world)`` is the
compiler run on its shipped spec, and whose ``load()`` also loads the robot's own files. They
replace the reference's hand-written ``from_world`` methods with data (``specs/*.yaml``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import ClassVar, TypeVar

from robotspec.semantic import AbstractRobot

__all__ = [
    "HSRB",
    "PR2",
    "B1UR5Allegro",
    "DualPanda",
    "Panda",
    "ShippedRobot",
    "Tiago",
    "UR5",
    "robot_class_for",
]

R = TypeVar("R", bound="ShippedRobot")


class ShippedRobot(AbstractRobot):
    """A robot backed by a spec shipped with robotspec."""

    spec_name: ClassVar[str | None] = None

    @classmethod
    def load(cls: type[R], *, package_paths: Sequence[str | Path] = ()) -> R:
        """Load the robot's description files and compile its spec."""
        from robotspec.compiler import compile_robot

        robot = compile_robot(cls.spec_name or "", package_paths=package_paths, robot_class=cls)
        assert isinstance(robot, cls)
        return robot


class PR2(ShippedRobot):
    """Willow Garage PR2: two arms with parallel grippers, a torso, a neck with a Kinect."""

    spec_name = "pr2"


class HSRB(ShippedRobot):
    """Toyota HSR-B: one arm with gripper and hand camera, a neck with four cameras."""

    spec_name = "hsrb"


class Tiago(ShippedRobot):
    """PAL Tiago: one arm with a parallel gripper, a lifting torso, a head camera."""

    spec_name = "tiago"


class Panda(ShippedRobot):
    """Franka Emika Panda: a fixed-base 7-DOF arm with its hand."""

    spec_name = "panda"


class UR5(ShippedRobot):
    """Universal Robots UR5: a fixed-base 6-DOF arm with a tool flange."""

    spec_name = "ur5"


class B1UR5Allegro(ShippedRobot):
    """Composed: Unitree B1 legs, a UR5 on the trunk, an Allegro hand on the flange."""

    spec_name = "b1_ur5_allegro"


class DualPanda(ShippedRobot):
    """Composed: two Panda arms with hands on a pedestal."""

    spec_name = "dual_panda"


_CLASSES: dict[str, type[ShippedRobot]] = {
    c.spec_name: c
    for c in (PR2, HSRB, Tiago, Panda, UR5, B1UR5Allegro, DualPanda)
    if c.spec_name is not None
}


def robot_class_for(ref: str | Path) -> type[AbstractRobot]:
    """The class for a shipped robot's name; plain ``AbstractRobot`` for a user's spec file."""
    if isinstance(ref, str) and ref.lower() in _CLASSES and not Path(ref).is_file():
        return _CLASSES[ref.lower()]
    return AbstractRobot
