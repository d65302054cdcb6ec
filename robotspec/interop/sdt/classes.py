"""The generated SDT classes live in this module: one class per part, made from a recipe.

Why generated classes at all: SDT's robot parts are abstract and wired by generic type
parameters, so a robot *is* a set of classes (``Arm[Gripper]``, ``Torso, HasNeck[Neck]``), and
``from_world`` builds parts from those parameters. Why here: SDT copies a world by replaying its
history and serialises parts by class path, so each class must be found again as
``robotspec.interop.sdt.classes.<Name>``. Names end in the recipe's digest: the same robot gives
the same classes (built once per process), two different robots of one name never clash.

A fresh process (an unpickle, a load from SDT's ORM) asks this module for a class it has not
built: :func:`__getattr__` rebuilds it from the recipe :func:`remember` stored when the class
was first made (in ``$ROBOTSPEC_SDT_CLASSES``, default ``~/.cache/robotspec/sdt-classes``).
"""

from __future__ import annotations

import json
import os
import re
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robotspec.interop.sdt.recipe import PartRecipe, RobotRecipe

__all__ = ["class_store", "remember", "robot_class"]

_MODULE = sys.modules[__name__]
_BUILT: dict[str, type] = {}


def _camel(name: str) -> str:
    return "".join(w[:1].upper() + w[1:] for w in re.split(r"[^0-9A-Za-z]+", name) if w)


def _register(name: str, cls: type) -> type:
    cls.__module__ = __name__
    cls.__qualname__ = name
    setattr(_MODULE, name, cls)
    _BUILT[name] = cls
    return cls


def _make(name: str, bases: tuple[Any, ...], namespace: dict[str, Any]) -> type:
    """A dataclass of SDT's kind (``eq=False`` as all of SDT's parts), registered here."""
    import types

    cls = types.new_class(name, bases, {}, lambda ns: ns.update(namespace))
    return _register(name, dataclass(eq=False)(cls))


# ------------------------------------------------------------------------------- parts
def _arms_mixin(sdt: Any, arms: list[type]) -> list[Any]:
    if not arms:
        return []
    if len(arms) == 1:
        return [sdt.mixins.HasOneArm[arms[0]]]
    if len(arms) == 2:
        return [sdt.mixins.HasLeftRightArm[arms[0], arms[1]]]
    return [sdt.mixins.HasArms[tuple(arms)]]


def _sides(arms: list[type]) -> dict[str, Any]:
    """The sides robotspec decided, not SDT's guess from the arms' second bodies."""
    if len(arms) != 2:
        return {}
    left, right = arms

    def pick(kind: type) -> Callable[[Any], Any]:
        def side(self: Any) -> Any:
            [arm] = [a for a in self.arms if type(a) is kind]
            return arm

        return side

    return {"left_arm": property(pick(left)), "right_arm": property(pick(right))}


def _upper_mixins(sdt: Any, built: dict[str, list[type]]) -> tuple[list[Any], dict[str, Any]]:
    """SDT mixins for the slots a torso, mobile base or robot holds."""
    bases: list[Any] = []
    if built.get("mobile_base"):
        bases.append(sdt.mixins.HasMobileBase[built["mobile_base"][0]])
    if built.get("torso"):
        bases.append(sdt.mixins.HasTorso[built["torso"][0]])
    bases.extend(_arms_mixin(sdt, built.get("arms", [])))
    if built.get("neck"):
        bases.append(sdt.mixins.HasNeck[built["neck"][0]])
    if built.get("sensors"):
        bases.append(sdt.mixins.HasSensors[tuple(built["sensors"])])
    return bases, _sides(built.get("arms", []))


def _states(sdt: Any, part: PartRecipe) -> Callable[[Any], list[Any]]:
    def setup_joint_states(self: Any) -> list[Any]:
        out = []
        for s in part.states:
            kind = getattr(sdt.definitions, s.kind[0])[s.kind[1]]
            mapping = {self._world.get_connection_by_name(j): v for j, v in s.joints}
            name = sdt.PrefixedName(f"{part.name}_{s.name}", prefix=self.name.name)
            out.append(sdt.JointState.from_mapping(mapping=mapping, state_type=kind, name=name))
        return out

    return setup_joint_states


def _hardware(part: PartRecipe) -> Callable[[Any], None]:
    def setup_hardware_interfaces(self: Any) -> None:
        for joint in part.hardware_joints:
            self._world.get_connection_by_name(joint).has_hardware_interface = True

    return setup_hardware_interfaces


def _factory(sdt: Any, part: PartRecipe) -> Callable[[Any, Any], Any]:
    """``setup_default_configuration_in_world_below_robot_root``: the part from its recipe."""

    def setup(cls: Any, robot_root: Any) -> Any:
        def body(name: str) -> Any:
            return robot_root._world.get_body_in_branch_by_name(robot_root, name)

        kwargs: dict[str, Any] = {"root": body(part.root)}
        if part.tip is not None:
            kwargs["tip"] = body(part.tip)
        if part.kind == "end_effector":
            assert part.tool_frame is not None and part.front_facing_orientation is not None
            kwargs["tool_frame"] = body(part.tool_frame)
            kwargs["front_facing_orientation"] = sdt.Quaternion(*part.front_facing_orientation)
        if part.kind == "camera":
            assert part.forward_facing_axis is not None and part.field_of_view is not None
            vertical, horizontal = part.field_of_view
            kwargs.update(
                forward_facing_axis=sdt.Vector3(*part.forward_facing_axis),
                field_of_view=sdt.FieldOfView(horizontal_angle=horizontal, vertical_angle=vertical),
                minimal_height=part.minimal_height,
                maximal_height=part.maximal_height,
                default_camera=part.default_camera,
            )
        return cls(**kwargs)

    return setup


def _part_class(sdt: Any, part: PartRecipe, robot: str, digest: str) -> type:
    built = {slot: [_part_class(sdt, p, robot, digest) for p in ps] for slot, ps in part.children}
    kind = {
        "mobile_base": sdt.parts.MobileBase,
        "torso": sdt.parts.Torso,
        "finger": sdt.parts.Finger,
        "camera": sdt.parts.Camera,
        "sensor": sdt.parts.Sensor,
        "end_effector": sdt.parts.EndEffector,
    }
    namespace: dict[str, Any] = {
        "setup_default_configuration_in_world_below_robot_root": classmethod(_factory(sdt, part)),
        "setup_hardware_interfaces": _hardware(part),
        "setup_joint_states": _states(sdt, part),
    }
    bases: list[Any]
    if part.kind == "neck":
        bases = [sdt.parts.Neck[tuple(built["sensors"])]]
    elif part.kind == "arm":
        bases = [sdt.parts.Arm[built["end_effector"][0]]]
        if built.get("sensors"):
            bases.append(sdt.mixins.HasSensors[tuple(built["sensors"])])
    elif part.kind == "end_effector":
        bases = [kind["end_effector"]]
        fingers = built.get("fingers", [])
        if len(fingers) == 2:
            bases.append(sdt.mixins.HasTwoFingers[fingers[0], fingers[1]])
        elif len(fingers) > 2:
            bases.append(sdt.mixins.HasFingers[tuple(fingers)])
        axis = part.front_facing_axis

        def post_init(self: Any) -> None:
            kind["end_effector"].__post_init__(self)
            if axis is not None:  # robotspec's axis, stated in the spec, not derived
                self.front_facing_axis = sdt.Vector3(*axis)

        namespace["__post_init__"] = post_init
    else:
        upper, sides = _upper_mixins(sdt, built)
        bases = [kind[part.kind], *upper]
        namespace.update(sides)
    name = f"{robot}_{_camel(part.kind)}_{_camel(part.name)}_{digest}"
    return _BUILT.get(name) or _make(name, tuple(bases), namespace)


# ------------------------------------------------------------------------------- robot
def robot_class(recipe: RobotRecipe) -> type:
    """The SDT robot class of ``recipe`` (and its part classes): built once per process."""
    from robotspec.interop.sdt import sdt_api

    digest = recipe.digest()
    name = f"{recipe.name}_{digest}"
    if name in _BUILT:
        return _BUILT[name]
    sdt = sdt_api()
    built = {
        slot: [_part_class(sdt, p, recipe.name, digest) for p in ps] for slot, ps in recipe.children
    }
    upper, sides = _upper_mixins(sdt, built)

    def get_ros_file_path(cls: Any) -> str:
        return recipe.source

    def _get_root_body_name(cls: Any) -> str:
        return recipe.root

    def _setup_velocity_limits(self: Any) -> None:
        """Nothing to do: the world already holds robotspec's (tightened) velocity limits."""

    def _setup_collision_rules(self: Any) -> None:
        world = self._world

        def body(n: str) -> Any:
            return world.get_body_in_branch_by_name(self.root, n)

        # SDT counts a body as colliding only above its size thresholds (a 1 mm box is not);
        # like SDT's own SRDF reader, pairs with a body it does not count are left out.
        pairs = [(body(a), body(b)) for a, b in recipe.disabled_pairs]
        rule = sdt.SelfCollisionMatrixRule(
            allowed_collision_pairs={
                sdt.CollisionCheck.create_and_validate(a, b)
                for a, b in pairs
                if a.has_collision() and b.has_collision()
            },
            allowed_collision_bodies={body(n) for n in recipe.disabled_bodies},
        )
        world.collision_manager.add_ignore_collision_rule(rule)
        if recipe.collisions_disabled:
            return
        distances = {
            "buffer_zone_distance": recipe.buffer_zone_distance,
            "violated_distance": recipe.violated_distance,
        }
        world.collision_manager.extend_default_rules(
            [
                sdt.AvoidExternalCollisions(robot=self, **distances),
                sdt.AvoidSelfCollisions(robot=self, **distances),
            ]
        )

    namespace: dict[str, Any] = {
        "get_ros_file_path": classmethod(get_ros_file_path),
        "_get_root_body_name": classmethod(_get_root_body_name),
        "_setup_velocity_limits": _setup_velocity_limits,
        "_setup_collision_rules": _setup_collision_rules,
        **sides,
    }
    return _make(name, (sdt.parts.AbstractRobot, *upper), namespace)


# ------------------------------------------------------------------- fresh processes
def class_store() -> Path:
    """Where recipes are kept for fresh processes: ``$ROBOTSPEC_SDT_CLASSES`` or the cache."""
    env = os.environ.get("ROBOTSPEC_SDT_CLASSES")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "robotspec" / "sdt-classes"


def remember(recipe: RobotRecipe) -> Path:
    """Store ``recipe`` (once, atomically) so another process can rebuild its classes."""
    folder = class_store()
    path = folder / f"{recipe.digest()}.json"
    if not path.is_file():
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(recipe.to_json(), f)
        os.replace(tmp, path)
    return path


def __getattr__(name: str) -> type:
    """A class this process has not built yet, rebuilt from its stored recipe."""
    match = re.search(r"_([0-9a-f]{10})$", name)
    path = None if match is None else class_store() / f"{match.group(1)}.json"
    if path is None or not path.is_file():
        raise AttributeError(
            f"module {__name__!r} has no class {name!r}: it is made by "
            "robotspec.interop.sdt.to_sdt(robot), and no stored recipe has its digest"
        )
    robot_class(RobotRecipe.from_json(json.loads(path.read_text(encoding="utf-8"))))
    if name not in _BUILT:
        raise AttributeError(f"the stored recipe {path} makes no class {name!r}")
    return _BUILT[name]
