"""Importable robots, one class per shipped spec: ``from robotspec.robots import PR2, HSRB``.

Each class is an :class:`~robotspec.semantic.AbstractRobot` whose ``from_world(world)`` is the
compiler run on its shipped spec, and whose ``load()`` also loads the robot's own files. They
replace the reference's hand-written ``from_world`` methods with data (``specs/*.yaml``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar, TypeVar

from robotspec.semantic import AbstractRobot

if TYPE_CHECKING:
    from robotspec.model.world import World

__all__ = [
    "HSRB",
    "PR2",
    "B1UR5Allegro",
    "DualPanda",
    "Panda",
    "ShippedRobot",
    "Tiago",
    "UR5",
    "load",
    "robot_class_for",
]

R = TypeVar("R", bound="ShippedRobot")


class ShippedRobot(AbstractRobot):
    """A robot backed by a spec shipped with robotspec."""

    #: The shipped spec (``specs/<spec_name>.yaml``) this class compiles.
    spec_name: ClassVar[str | None] = None

    @classmethod
    def _spec(cls) -> str:
        if cls.spec_name is None:
            raise TypeError(f"{cls.__name__} names no shipped spec (set spec_name)")
        return cls.spec_name

    @classmethod
    def load(cls: type[R], *, package_paths: Sequence[str | Path] = ()) -> R:
        """Load the robot's description files and compile its spec."""
        from robotspec.compiler import compile_robot

        robot = compile_robot(cls._spec(), package_paths=package_paths, robot_class=cls)
        if not isinstance(robot, cls):  # the compiler builds robot_class; never false
            raise TypeError(f"compiled {type(robot).__name__}, expected {cls.__name__}")
        return robot

    @classmethod
    def from_world(cls, world: World) -> AbstractRobot:
        """The seed's factory: the shipped spec's semantics over an existing ``world``."""
        from robotspec.compiler import compile_spec_for_world

        return compile_spec_for_world(cls._spec(), world, robot_class=cls)


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


def load(ref: str | Path, *, package_paths: Sequence[str | Path] = ()) -> AbstractRobot:
    """Compile a shipped robot (as its own class: ``load("pr2")`` is a :class:`PR2`) or a spec."""
    from robotspec.compiler import compile_robot

    return compile_robot(ref, package_paths=package_paths, robot_class=robot_class_for(ref))
