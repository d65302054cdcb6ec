"""A robot whose class *is* one of SDT's own (``PR2``, ``Stretch``) or a user's SDT class.

Why: PyCRAM/coraplex choose robot-specific motions by class identity
(``AlternativeMotion.check_for_alternative`` compares ``original_class() ==
robot.__class__``), so a generated class, however faithful, never gets the Stretch's
differential move or the HSR-B's navigation. Here the robot is an instance of the named class
itself; only its *parts* are robotspec's generated classes, built from the recipe (the spec's
bodies, states, sides and axes, never SDT's hand-written name lookups).

The robot is set up as SDT's ``from_branch_in_world`` sets one up, step for step, but the
class's own ``setup_robot_part_semantic_annotations`` (which would build its hand-written
parts), ``_setup_collision_rules`` (which reads an SRDF SDT's wheel lacks) and
``_setup_velocity_limits`` (hand-written values) are not called: the parts are given, the
collision rules are the spec's (:mod:`.rules`), the world already holds the spec's velocity
limits.

Fitting the recipe to the class: the robot's own slots (``mobile_base``, ``torso``, ``arms``,
``neck``, ``sensors``) go into the class's fields of those names; a slot the class has no field
for hangs on the mobile base instead (SDT's PR2 has no robot-level sensors; a base laser then is
the mobile base's), and with no mobile base it is an error naming the slot.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
from dataclasses import replace
from typing import Any

from robotspec.errors import RobotSpecError
from robotspec.interop.sdt.recipe import RobotRecipe
from robotspec.spec.sdt import SDT_ROBOT_CLASSES

__all__ = ["build", "checked_class", "fit", "named_class"]

#: The recipe's slots of a robot, in the order they are set.
_SLOTS = ("mobile_base", "torso", "arms", "neck", "sensors")


def named_class(name: str) -> type:
    """SDT's robot class ``name``, from the static list (never a module a file names)."""
    module = SDT_ROBOT_CLASSES.get(name)
    if module is None:  # the spec refuses it; a Python caller may still pass a bad name
        from robotspec.errors import closest_names, did_you_mean

        raise RobotSpecError(
            f"the semantic digital twin 26.7 has no robot class '{name}'"
            f"{did_you_mean(closest_names(name, SDT_ROBOT_CLASSES))}",
            kind="sdt class",
            name=name,
        )
    cls: type = getattr(importlib.import_module(f"semantic_digital_twin.robots.{module}"), name)
    return cls


def checked_class(sdt: Any, cls: Any) -> type:
    """``cls`` if a robot can be an instance of it: a concrete dataclass of SDT's AbstractRobot."""
    if not (
        inspect.isclass(cls)
        and issubclass(cls, sdt.parts.AbstractRobot)
        and dataclasses.is_dataclass(cls)
    ):
        raise RobotSpecError(
            f"sdt_class must be a dataclass subclass of SDT's AbstractRobot, got {cls!r}",
            kind="sdt class",
            name=getattr(cls, "__name__", repr(cls)),
        )
    if inspect.isabstract(cls):
        missing = ", ".join(sorted(getattr(cls, "__abstractmethods__", ())))
        raise RobotSpecError(
            f"sdt_class {cls.__qualname__} is abstract (it lacks {missing})",
            kind="sdt class",
            name=cls.__qualname__,
        )
    return cls


def _fields(cls: type) -> set[str]:
    return {f.name for f in dataclasses.fields(cls)}


def fit(recipe: RobotRecipe, cls: type) -> RobotRecipe:
    """``recipe`` with the robot's slots that ``cls`` has no field for moved to the mobile base."""
    fields = _fields(cls)
    keep = [(slot, parts) for slot, parts in recipe.children if slot in fields]
    move = [(slot, parts) for slot, parts in recipe.children if slot not in fields]
    if not move:
        return recipe
    bases = dict(keep).get("mobile_base", ())
    if len(bases) != 1:
        slot, parts = move[0]
        names = ", ".join(p.name for p in parts)
        raise RobotSpecError(
            f"SDT's {cls.__qualname__} has no field '{slot}' for robotspec's {names}, and no "
            f"mobile base to hang it on (its fields: {', '.join(sorted(fields))}); name "
            "another class (sdt: {class: ...}) or pass sdt_class=... of your own",
            kind="sdt class",
            name=cls.__qualname__,
        )
    (base,) = bases
    children = dict(base.children)
    for slot, parts in move:
        children[slot] = (*children.get(slot, ()), *parts)
    moved = replace(base, children=tuple(children.items()))
    return replace(
        recipe,
        children=tuple(
            (slot, (moved,) if slot == "mobile_base" else parts) for slot, parts in keep
        ),
    )


def _nested(part: Any, slot: str) -> Any:
    """The part in ``slot`` anywhere below ``part`` (a torso inside the mobile base), or None."""
    value = getattr(part, slot, None)
    if value:
        return value
    for name in _SLOTS:
        child = getattr(part, name, None)
        for c in child if isinstance(child, list) else [child]:
            if c is not None and c is not part:
                found = _nested(c, slot)
                if found:
                    return found
    return None


def build(sdt: Any, cls: type, recipe: RobotRecipe, world: Any) -> Any:
    """An instance of ``cls`` in ``world``, its parts the generated classes of ``recipe``.

    ``recipe`` is already fitted (:func:`fit`). The steps are SDT's ``from_branch_in_world``'s
    (see the module docstring for the three it leaves to the spec).
    """
    from robotspec.interop.sdt.classes import part_classes
    from robotspec.interop.sdt.rules import setup_collision_rules

    classes = part_classes(recipe)
    fields = _fields(cls)
    root = world.get_body_in_branch_by_name(branch_root=world.root, name=recipe.root)
    with world.modify_world():
        values: dict[str, Any] = {}
        for slot in _SLOTS:
            parts = []
            part_cls: Any
            for part_cls in classes.get(slot, []):
                part = part_cls.setup_default_configuration_in_world_below_robot_root(root)
                part.setup_robot_part_semantic_annotations()
                parts.append(part)
            if parts:
                values[slot] = parts if slot in ("arms", "sensors") else parts[0]
        for slot in ("torso", "neck"):  # a field of the class the recipe fills lower down
            if slot in fields and slot not in values:
                found = next((_nested(v, slot) for v in values.values() if v), None)
                if found is not None:
                    values[slot] = found
        robot = cls(root=root, **values)
        robot.name = sdt.PrefixedName(recipe.name, prefix=robot.name.prefix)
        world.add_semantic_annotation_recursively(robot)
        for part in robot._robot_parts:
            part.setup_hardware_interfaces()
            part.add_joint_states(part.setup_joint_states())
        setup_collision_rules(sdt, recipe, robot)
    return robot
