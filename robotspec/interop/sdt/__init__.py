"""A compiled robot as the semantic digital twin's own ``AbstractRobot``, in an SDT ``World``.

``to_sdt(robot)`` is the bridge PyCRAM code needs: SDT's classes (its ``Arm``, ``EndEffector``,
``Camera``, ...), its world, its ``from_world``, built from the robot robotspec compiled and
checked. Needs the ``sdt`` extra (``pip install 'robotspec[sdt]'``); importing this package
does not import SDT, calling :func:`to_sdt` does. See ``docs/sdt.md``.

Modules, one job each: :mod:`.recipe` decides the mapping as plain data (no SDT),
:mod:`.world` copies the world model into an SDT world, :mod:`.classes` generates and holds
the part classes, :mod:`._api` is the one place SDT is imported.
"""

from __future__ import annotations

import os
import warnings
from types import ModuleType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot

__all__ = ["SdtBridgeWarning", "sdt_api", "to_sdt"]

#: The SDT minor version the bridge is written and tested against (the ``sdt`` extra pins it).
SDT_VERSION = "26.7"


class SdtBridgeWarning(UserWarning):
    """Something of the robotspec robot has no place in SDT (a state kind, a chain kind)."""


def sdt_api() -> ModuleType:
    """SDT's names the bridge uses, or a RobotSpecError naming what is missing (``.install``)."""
    try:
        from robotspec.interop.sdt import _api
    except ImportError as exc:
        from robotspec.interop.sdt.install import import_error

        raise import_error(exc, tested=SDT_VERSION) from exc
    return _api


def to_sdt(robot: AbstractRobot, *, class_store: str | os.PathLike[str] | None = None) -> Any:
    """``robot`` as SDT's ``AbstractRobot`` (built by SDT's own ``from_world``) in a new World.

    The world holds robotspec's bodies, joints, limits (velocity limits as tightened by the
    spec) and the base drive; the robot's parts are SDT's kinds, with robotspec's sides,
    axes, cameras, states and collision rules (see :func:`.recipe.robot_recipe`). What has no
    place in SDT is left out with an :class:`SdtBridgeWarning` each. The robot is returned;
    its world is ``result._world``.

    ``class_store``: a folder to keep the generated classes' recipe in, for a fresh process
    that meets the classes by their path alone (a world history replayed, SDT's ORM);
    default ``$ROBOTSPEC_SDT_CLASSES``, and without it nothing is written: the classes live
    in memory and pickle with their recipe (docs/sdt.md, "Where class recipes are kept").
    """
    from robotspec.interop.sdt.classes import remember, robot_class
    from robotspec.interop.sdt.recipe import robot_recipe
    from robotspec.interop.sdt.world import sdt_world

    recipe = robot_recipe(robot)
    for note in recipe.left_out:
        warnings.warn(f"{robot.name}: {note}", SdtBridgeWarning, stacklevel=2)
    cls = robot_class(recipe)
    try:
        remember(recipe, class_store)
    except OSError as exc:  # this process works without it; a fresh one cannot rebuild
        warnings.warn(
            f"{robot.name}: the recipe of its SDT classes could not be stored ({exc}); another "
            "process will not find them by path (give class_store or ROBOTSPEC_SDT_CLASSES "
            "a writable folder)",
            SdtBridgeWarning,
            stacklevel=2,
        )
    world = sdt_world(robot.world, drive=robot.drive_type)
    sdt_robot = cls.from_world(world)  # type: ignore[attr-defined]
    if recipe.extra_hardware_joints:
        with world.modify_world():
            for name in recipe.extra_hardware_joints:
                world.get_connection_by_name(name).has_hardware_interface = True
    return sdt_robot
