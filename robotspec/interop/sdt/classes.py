"""The generated SDT classes live in this module: one class per part, made from a recipe.

Why generated classes at all: SDT's robot parts are abstract and wired by generic type
parameters, so a robot *is* a set of classes (``Arm[Gripper]``, ``Torso, HasNeck[Neck]``), and
``from_world`` builds parts from those parameters. Why here: SDT copies a world by replaying its
history and serialises parts by class path, so each class must be found again as
``robotspec.interop.sdt.classes.<Name>``. Names end in the recipe's digest, which holds no
machine path: the same robot gives the same classes (built once per process, on any machine),
two different robots of one name never clash.

A class pickles with its recipe (its metaclass's reducer), so an unpickle in a fresh process
rebuilds it with nothing stored. A fresh process that meets a class by its path alone (a world
replayed from its JSON history, SDT's ORM) asks :func:`__getattr__`, which rebuilds it from a
recipe :func:`remember` stored, only where the user asked for it (``to_sdt(...,
class_store=...)`` or ``$ROBOTSPEC_SDT_CLASSES``; docs/sdt.md says why nothing is written
otherwise). The registry is guarded by a lock: two threads never build one class twice.
"""

from __future__ import annotations

import copyreg
import re
import sys
import threading
import types
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from robotspec.errors import RobotSpecError
from robotspec.interop.sdt.backref import robot_of
from robotspec.interop.sdt.recipe import PartRecipe, RobotRecipe
from robotspec.interop.sdt.rules import setup_collision_rules
from robotspec.interop.sdt.store import class_store, remember, stored, stores

if TYPE_CHECKING:
    # Not used here: krrood resolves the type hints SDT's classes import only for type
    # checking by parsing the imports of each class's module, this one first for a generated
    # class; found here, they cost one parse of this file instead of a re-parse of every
    # module in the class's hierarchy per name (about half a second per first to_sdt).
    from krrood.entity_query_language.explanation.explanation import (  # type: ignore[import-not-found, unused-ignore]  # noqa: F401
        InferenceExplanation,
    )
    from semantic_digital_twin.world import World  # noqa: F401

__all__ = ["class_store", "part_classes", "remember", "robot_class"]

_MODULE = sys.modules[__name__]
_BUILT: dict[str, type] = {}
#: Guards ``_BUILT``, the module's attributes and the metaclasses (re-entrant: a robot's
#: class builds its part classes inside it).
_LOCK = threading.RLock()
#: One metaclass per SDT metaclass: the generated classes' own, whose reducer pickles a class
#: with its recipe.
_METAS: dict[type, type] = {}


def _camel(name: str) -> str:
    return "".join(w[:1].upper() + w[1:] for w in re.split(r"[^0-9A-Za-z]+", name) if w)


def _register(name: str, cls: type) -> type:
    cls.__module__ = __name__
    cls.__qualname__ = name
    setattr(_MODULE, name, cls)
    _BUILT[name] = cls
    return cls


def _rebuild(data: dict[str, Any], name: str) -> type:
    """The class ``name`` of the recipe ``data``: what an unpickle calls (see :func:`_reduce`)."""
    with _LOCK:
        if name not in _BUILT:
            robot_class(RobotRecipe.from_json(data))
        if name not in _BUILT:
            raise RobotSpecError(
                f"the pickled recipe makes no SDT class {name!r} (pickled by another robotspec?)",
                kind="dependency",
                name=name,
            )
        return _BUILT[name]


def _reduce(cls: type) -> Any:
    """A generated class pickles as its recipe and name, so any process can rebuild it."""
    recipe: RobotRecipe | None = cls.__dict__.get("_robotspec_recipe")
    if recipe is None:  # a user's subclass of a generated class: by reference, as any class
        return cls.__qualname__
    return _rebuild, (recipe.to_json(), cls.__name__)


def _metaclass(sdt_meta: type) -> type:
    """SDT's metaclass with the pickle reducer of the generated classes (made once)."""
    with _LOCK:
        meta = _METAS.get(sdt_meta)
        if meta is None:
            meta = types.new_class(f"RobotspecSdt{sdt_meta.__name__}", (sdt_meta,))
            meta.__module__ = __name__
            copyreg.pickle(meta, _reduce)
            _METAS[sdt_meta] = meta
        return meta


def _make(
    sdt: Any,
    name: str,
    bases: tuple[Any, ...],
    namespace: dict[str, Any],
    *,
    recipe: RobotRecipe,
    sdt_name: str,
    after_init: Callable[[Any], None] | None = None,
) -> type:
    """A dataclass of SDT's kind (``eq=False`` as all of SDT's parts), registered here.

    Its SDT ``name`` is ``sdt_name`` (the spec's robot or part name), not SDT's default, the
    class name, which ends in the digest: joint-state names and world histories name the
    robot as its spec does. ``after_init`` runs after SDT's ``__post_init__``.
    """
    resolved = types.resolve_bases(bases)
    sdt_meta, _, _ = types.prepare_class(name, resolved)
    cell: list[Any] = []  # the class, once made (super() needs it)

    def __post_init__(self: Any) -> None:  # noqa: N807 - the dataclass hook
        unnamed = self.name is None
        super(cell[0], self).__post_init__()
        if unnamed:
            self.name = sdt.PrefixedName(sdt_name, prefix=self.name.prefix)
        if after_init is not None:
            after_init(self)

    namespace = {
        **namespace,
        "__module__": __name__,  # already while SDT's __init_subclass__ resolves its hints
        "__qualname__": name,
        "_robotspec_recipe": recipe,
        "__post_init__": __post_init__,
    }
    cls = types.new_class(
        name, bases, {"metaclass": _metaclass(sdt_meta)}, lambda ns: ns.update(namespace)
    )
    cell.append(cls)
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


def _part_class(sdt: Any, part: PartRecipe, recipe: RobotRecipe, digest: str) -> type:
    built = {slot: [_part_class(sdt, p, recipe, digest) for p in ps] for slot, ps in part.children}
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
        "_robot": property(robot_of),  # SDT's back-reference without a query (.backref)
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

        def after_init(self: Any) -> None:
            if axis is not None:  # robotspec's axis, stated in the spec, not derived
                self.front_facing_axis = sdt.Vector3(*axis)
    else:
        upper, sides = _upper_mixins(sdt, built)
        bases = [kind[part.kind], *upper]
        namespace.update(sides)
    name = f"{recipe.name}_{_camel(part.kind)}_{_camel(part.name)}_{digest}"
    return _BUILT.get(name) or _make(
        sdt,
        name,
        tuple(bases),
        namespace,
        recipe=recipe,
        sdt_name=part.name,
        after_init=after_init if part.kind == "end_effector" else None,
    )


# ------------------------------------------------------------------------------- robot
def robot_class(recipe: RobotRecipe) -> type:
    """The SDT robot class of ``recipe`` (and its part classes): built once per process."""
    from robotspec.interop.sdt import sdt_api

    digest = recipe.digest()
    name = f"{recipe.name}_{digest}"
    with _LOCK:
        if name in _BUILT:
            return _BUILT[name]
        return _robot_class(sdt_api(), recipe, name, digest)


def part_classes(recipe: RobotRecipe) -> dict[str, list[type]]:
    """The classes of the robot's own slots (``mobile_base``, ``arms``, ...): built once."""
    from robotspec.interop.sdt import sdt_api

    with _LOCK:
        return _part_classes(sdt_api(), recipe, recipe.digest())


def _part_classes(sdt: Any, recipe: RobotRecipe, digest: str) -> dict[str, list[type]]:
    return {slot: [_part_class(sdt, p, recipe, digest) for p in ps] for slot, ps in recipe.children}


def _robot_class(sdt: Any, recipe: RobotRecipe, name: str, digest: str) -> type:
    built = _part_classes(sdt, recipe, digest)
    upper, sides = _upper_mixins(sdt, built)

    def get_ros_file_path(cls: Any) -> str:
        return recipe.source

    def _get_root_body_name(cls: Any) -> str:
        return recipe.root

    def _setup_velocity_limits(self: Any) -> None:
        """Nothing to do: the world already holds robotspec's (tightened) velocity limits."""

    def _setup_collision_rules(self: Any) -> None:
        setup_collision_rules(sdt, recipe, self)

    namespace: dict[str, Any] = {
        "get_ros_file_path": classmethod(get_ros_file_path),
        "_get_root_body_name": classmethod(_get_root_body_name),
        "_setup_velocity_limits": _setup_velocity_limits,
        "_setup_collision_rules": _setup_collision_rules,
        **sides,
    }
    return _make(
        sdt, name, (sdt.parts.AbstractRobot, *upper), namespace, recipe=recipe, sdt_name=recipe.name
    )


# ------------------------------------------------------------------- fresh processes
def __getattr__(name: str) -> type:
    """A class this process has not built yet, rebuilt from its stored recipe."""
    match = re.search(r"_([0-9a-f]{10})$", name)
    with _LOCK:
        paths = [] if match is None else [s / f"{match.group(1)}.json" for s in stores()]
        path = next((p for p in paths if p.is_file()), None)
        if path is None:
            raise AttributeError(
                f"module {__name__!r} has no class {name!r}: it is made by "
                "robotspec.interop.sdt.to_sdt(robot) (or an unpickle of it), and no stored "
                "recipe has its digest (docs/sdt.md: where class recipes are kept)"
            )
        robot_class(stored(path))
        if name not in _BUILT:
            raise AttributeError(f"the stored recipe {path} makes no class {name!r}")
        return _BUILT[name]
