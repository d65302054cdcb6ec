"""A compiled robot as the semantic digital twin's own ``AbstractRobot``, in an SDT ``World``.

``to_sdt(robot)`` is the bridge PyCRAM code needs: SDT's classes (its ``Arm``, ``EndEffector``,
``Camera``, ...), its world, its ``from_world``, built from the robot robotspec compiled and
checked. Needs the ``sdt`` extra (``pip install 'robotspec[sdt]'``); importing this package
does not import SDT, calling :func:`to_sdt` does. See ``docs/sdt.md``.

Modules, one job each: :mod:`.mapping` decides the mapping as plain data (no SDT): the
:mod:`.recipe` each class is made from, with :mod:`.base` the mobile base's body;
:mod:`.world` copies the world model into an SDT world; :mod:`.classes` generates and holds
the part classes (:mod:`.backref`: a part's robot without a query; :mod:`.store`: recipes
kept for fresh processes); :mod:`.identity` makes a robot an instance of a named SDT class;
:mod:`.serial` runs builds one at a time; :mod:`._api` is the one place SDT is imported.
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


def to_sdt(
    robot: AbstractRobot,
    *,
    class_store: str | os.PathLike[str] | None = None,
    sdt_class: type | None = None,
) -> Any:
    """``robot`` as SDT's ``AbstractRobot`` in a new World.

    Its class is the one ``sdt_class`` or the spec's ``sdt: {class: ...}`` names (``PR2``,
    ``Stretch``: coraplex's robot-specific motions then apply), else one generated for it,
    built by SDT's own ``from_world``.

    The world holds robotspec's bodies, joints, limits (velocity limits as tightened by the
    spec) and the base drive; the robot's parts are SDT's kinds, with robotspec's sides,
    axes, cameras, states and collision rules (see :func:`.mapping.robot_recipe`). What has no
    place in SDT is left out with an :class:`SdtBridgeWarning` each. The robot is returned;
    its world is ``result._world``.

    ``class_store``: a folder to keep the generated classes' recipe in, for a fresh process
    that meets the classes by their path alone (a world history replayed, SDT's ORM);
    default ``$ROBOTSPEC_SDT_CLASSES``, and without it nothing is written: the classes live
    in memory and pickle with their recipe (docs/sdt.md, "Where class recipes are kept").

    ``sdt_class``: the SDT robot class the robot is an instance of (a concrete dataclass
    subclass of SDT's ``AbstractRobot``, your own or SDT's); default the spec's ``sdt:
    {class: ...}``, and without either a class generated for the robot. With a class, PyCRAM
    and coraplex treat the robot as that robot (its alternative motions apply); its parts are
    still robotspec's (docs/sdt.md, "Which SDT robot it is").
    """
    from robotspec.interop.sdt.classes import remember, robot_class
    from robotspec.interop.sdt.identity import build, checked_class, fit, named_class
    from robotspec.interop.sdt.mapping import robot_recipe
    from robotspec.interop.sdt.serial import run
    from robotspec.interop.sdt.world import building_world

    api = sdt_api()  # before anything is stored: without SDT, only the error
    recipe = robot_recipe(robot)
    own: type | None = None
    if sdt_class is not None or robot.sdt_class is not None:
        own = checked_class(api, sdt_class or named_class(robot.sdt_class or ""))
        recipe = fit(recipe, own)
    for note in recipe.left_out:
        warnings.warn(f"{robot.name}: {note}", SdtBridgeWarning, stacklevel=2)
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

    def build_in_sdt() -> Any:
        cls = robot_class(recipe) if own is None else None
        # World and robot in one modification block: SDT syncs its collision shapes and
        # compiles its kinematics once, not once per block (.world.building_world).
        with building_world(robot.world, drive=robot.drive_type) as world:
            if own is not None:
                sdt_robot = build(api, own, recipe, world)
            else:
                sdt_robot = cls.from_world(world)  # type: ignore[union-attr]
            for name in recipe.extra_hardware_joints:
                world.get_connection_by_name(name).has_hardware_interface = True
        return sdt_robot

    # One build at a time, and never on a thread that will exit (.serial says why).
    return run(build_in_sdt)
