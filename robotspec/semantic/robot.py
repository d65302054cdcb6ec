"""``AbstractRobot``: the robot as a semantic view over its world (the seed's API).

The compiler builds robots from specs; this class only holds parts, enforces the ownership and
uniqueness rules of the reference, and answers questions that cut across parts (controlled
connections, the drive, velocity limits, collision configuration).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from robotspec.errors import KinematicsError, NotFoundError
from robotspec.model.world import Body, Connection, World
from robotspec.semantic.base import AssignmentError, JointState, SemanticRobotAnnotation
from robotspec.semantic.chains import KinematicChain, Neck, Torso
from robotspec.semantic.manipulators import Manipulator
from robotspec.semantic.sensors import Camera, Sensor
from robotspec.semantic.states import state_configuration

if TYPE_CHECKING:
    from robotspec.arrays import F64
    from robotspec.description.srdf import Srdf
    from robotspec.model.kinematics import ChainKinematics, Kinematics
    from robotspec.model.pinocchio import PinocchioRobot

__all__ = ["AbstractRobot", "CollisionCheckingConfig", "EmptyChainWarning"]


class EmptyChainWarning(UserWarning):
    """A chain was added that carries neither a manipulator nor a sensor."""


@dataclass(frozen=True)
class CollisionCheckingConfig:
    """Self-collision settings (the seed's ``CollisionCheckingConfig``; distances in m)."""

    buffer_zone_distance: float = 0.05
    violated_distance: float = 0.0
    disabled: bool = False
    max_avoided_bodies: int = 1


@dataclass(eq=False)
class AbstractRobot:
    """A robot rooted at ``root``: torso, neck, chains, manipulators and sensors."""

    name: str
    root: Body
    world: World = field(repr=False)
    torso: Torso | None = None
    neck: Neck | None = None
    manipulators: list[Manipulator] = field(default_factory=list)
    sensors: list[Sensor] = field(default_factory=list)
    manipulator_chains: list[KinematicChain] = field(default_factory=list)
    sensor_chains: list[KinematicChain] = field(default_factory=list)
    kinematic_chains: list[KinematicChain] = field(default_factory=list)
    joint_states: dict[str, JointState] = field(default_factory=dict)
    default_collision_config: CollisionCheckingConfig = field(
        default_factory=CollisionCheckingConfig, kw_only=True
    )
    disabled_collision_pairs: set[frozenset[str]] = field(default_factory=set, kw_only=True)
    disabled_collision_bodies: set[str] = field(default_factory=set, kw_only=True)
    srdf: Srdf | None = field(default=None, kw_only=True, repr=False)
    drive_type: str = field(default="fixed", kw_only=True)
    #: The direction the robot faces in its root's frame (a horizontal unit vector; REP 103: +x).
    forward_axis: tuple[float, float, float] = field(default=(1.0, 0.0, 0.0), kw_only=True)
    controlled_joint_names: tuple[str, ...] | None = field(default=None, kw_only=True)
    #: The semantic digital twin robot class the spec names (``sdt: {class: ...}``), if any.
    sdt_class: str | None = field(default=None, kw_only=True)
    _sides: tuple[tuple[int, ...], tuple[KinematicChain, KinematicChain]] | None = field(
        default=None, init=False, repr=False
    )
    _kinematics: Kinematics | None = field(default=None, init=False, repr=False, compare=False)

    # ----------------------------------------------------------------------- structure
    @property
    def _world(self) -> World:
        return self.world

    @property
    def bodies(self) -> list[Body]:
        """Every body of the branch below (and including) the root."""
        return list(self.world.subtree(self.root))

    kinematic_structure_entities = bodies

    @property
    def connections(self) -> list[Connection]:
        """Connections inside the robot's branch (the drive above the root is not one)."""
        inside = {b.index for b in self.world.subtree(self.root)}
        return [c for c in self.world.connections if c.parent in inside]

    @property
    def bodies_with_collisions(self) -> list[Body]:
        """The robot's bodies that have collision geometry."""
        return [b for b in self.bodies if b.has_collision]

    @property
    def bodies_with_enabled_collision(self) -> list[Body]:
        """Bodies with collision geometry that are not disabled for collision checking."""
        return [
            b for b in self.bodies_with_collisions if b.name not in self.disabled_collision_bodies
        ]

    @property
    def controlled_connections(self) -> list[Connection]:
        """The joints a controller commands: by default every actuated, non-mimic joint.

        Actuated excludes the SRDF's ``passive_joint`` entries (HSRB's caster wheels, bumpers
        and spring joints move but have no motor); a spec's ``controlled_joints`` overrides.
        """
        own = [c for c in self.connections if c.is_active]
        if self.controlled_joint_names is None:
            passive = set() if self.srdf is None else {p.name for p in self.srdf.passive_joints}
            return [c for c in own if c.name not in passive]
        wanted = set(self.controlled_joint_names)
        return [c for c in own if c.name in wanted]

    @property
    def drive(self) -> Connection | None:
        """The connection that moves the base (the root's parent), if it moves."""
        parent = self.world.parent_connection(self.root)
        if parent is None or parent.is_fixed:
            return None
        return parent

    @property
    def arms(self) -> list[KinematicChain]:
        """Chains that carry a manipulator (the seed's ``HasArms``)."""
        return list(self.manipulator_chains)

    @property
    def left_arm(self) -> KinematicChain:
        """The left one of exactly two arms (the seed's ``SpecifiesLeftRightArm``).

        The spec's ``side`` when it names one, else the arm lying on the root's +y side in the
        default pose; a KinematicsError when the robot does not have exactly two arms.
        """
        return self._left_right()[0]

    @property
    def right_arm(self) -> KinematicChain:
        """The right one of exactly two arms (see :attr:`left_arm`)."""
        return self._left_right()[1]

    def _left_right(self) -> tuple[KinematicChain, KinematicChain]:
        from robotspec.semantic.sides import arm_sides

        arms = self.arms
        key = tuple(id(a) for a in arms)
        if self._sides is None or self._sides[0] != key:
            declared = [getattr(a, "side", None) for a in arms]
            self._sides = (
                key,
                arm_sides(self.world, self.root, arms, declared, left=self.left_axis),
            )
        return self._sides[1]

    @property
    def left_axis(self) -> tuple[float, float, float]:
        """The robot's left in its root's frame: up (+z) cross :attr:`forward_axis`."""
        fx, fy, _ = self.forward_axis
        return (-fy, fx, 0.0)

    @property
    def cameras(self) -> list[Camera]:
        """The robot's cameras."""
        return [s for s in self.sensors if isinstance(s, Camera)]

    @property
    def default_camera(self) -> Camera | None:
        """The camera flagged default, else the first camera."""
        cams = self.cameras
        return next((c for c in cams if c.default_camera), cams[0] if cams else None)

    def get_chain(self, name: str) -> KinematicChain:
        """A chain (arm, torso, neck or other) by name; suggestions when missing."""
        chains = {c.name: c for c in self.all_chains}
        if name not in chains:
            raise NotFoundError("chain", name, chains, where=f"robot '{self.name}'")
        return chains[name]

    @property
    def all_chains(self) -> list[KinematicChain]:
        """Torso, neck and every other chain, in that order."""
        out: list[KinematicChain] = []
        if self.torso is not None:
            out.append(self.torso)
        if self.neck is not None:
            out.append(self.neck)
        out.extend(c for c in self.kinematic_chains if c is not self.neck)
        return out

    # ------------------------------------------------------------------------- assembly
    def _register(self, part: SemanticRobotAnnotation) -> None:
        self.world.add_semantic_annotation(part)
        part.assign_to_robot(self)

    def add_manipulator(self, manipulator: Manipulator) -> None:
        """Add a manipulator (once) and assign it to this robot."""
        if manipulator not in self.manipulators:
            self.manipulators.append(manipulator)
        self._register(manipulator)

    def add_sensor(self, sensor: Sensor) -> None:
        """Add a sensor (once) and assign it to this robot."""
        if sensor not in self.sensors:
            self.sensors.append(sensor)
        self._register(sensor)

    def add_torso(self, torso: Torso) -> None:
        """Set the torso; a robot has at most one."""
        if self.torso is not None and self.torso is not torso:
            raise AssignmentError(
                f"robot '{self.name}' already has torso '{self.torso.name}'", name=torso.name
            )
        self.torso = torso
        self._register(torso)

    def add_arm(self, arm: KinematicChain) -> None:
        """Add an arm: a chain that carries a manipulator (the seed's ``HasArms.add_arm``)."""
        if arm.manipulator is None:
            raise AssignmentError(
                f"arm '{arm.name}' carries no manipulator; add it with add_kinematic_chain",
                name=arm.name,
            )
        self.add_kinematic_chain(arm)

    def add_neck(self, neck: Neck) -> None:
        """Set the neck (it must carry a sensor) and add it as a chain."""
        if not neck.sensors:
            raise AssignmentError(
                f"neck '{neck.name}' carries no sensor; a neck is the chain that moves the "
                "head's sensors",
                name=neck.name,
            )
        if self.neck is not None and self.neck is not neck:
            raise AssignmentError(
                f"robot '{self.name}' already has neck '{self.neck.name}'", name=neck.name
            )
        self.neck = neck
        self.add_kinematic_chain(neck)

    def add_kinematic_chain(self, chain: KinematicChain, *, warn: bool = True) -> None:
        """File a chain under manipulator and/or sensor chains, and assign it.

        Unlike the reference, a chain with neither manipulator nor sensor is kept (it may be
        commanded, e.g. a lift); a warning says so, since it is often a mistake.
        """
        if chain.manipulator is None and not chain.sensors and warn:
            warnings.warn(
                f"chain '{chain.name}' has neither a manipulator nor a sensor",
                EmptyChainWarning,
                stacklevel=2,
            )
        if chain not in self.kinematic_chains:
            self.kinematic_chains.append(chain)
        if chain.manipulator is not None and chain not in self.manipulator_chains:
            self.manipulator_chains.append(chain)
        if chain.sensors and chain not in self.sensor_chains:
            self.sensor_chains.append(chain)
        self._register(chain)

    # --------------------------------------------------------------------- limits, SRDF
    def _mimic_of(self, name: str) -> str | None:
        """The leader of the robot's joint ``name`` if it is a mimic joint, else None."""
        for c in self.connections:
            if c.name == name and c.mimic is not None:
                return c.mimic.leader
        return None

    def tighten_dof_velocity_limits_of_1dof_connections(
        self, new_limits: Mapping[Connection | str, float]
    ) -> None:
        """Lower velocity limits of the robot's own 1-DOF active joints; never raise one."""
        own = {c.name: c for c in self.connections if c.is_1dof and c.is_active}
        updates: dict[str, float] = {}
        for key, value in new_limits.items():
            name = key if isinstance(key, str) else key.name
            if name not in own:
                mimic = self._mimic_of(name)
                if mimic is not None:  # the name is right; the joint has no motion of its own
                    raise KinematicsError(
                        f"'{name}' is a mimic joint of '{mimic}'; limit '{mimic}' instead",
                        name=name,
                        suggestions=(mimic,),
                    )
                raise NotFoundError("actuated 1-DOF joint", name, own, where=f"robot '{self.name}'")
            if not (value > 0 and math.isfinite(value)):
                raise KinematicsError(
                    f"velocity limit of '{name}' must be positive and finite, got {value}",
                    name=name,
                )
            dof = self.world.degrees_of_freedom[own[name].dofs[0]]
            updates[dof.name] = value
        self.world.tighten_velocity_limits(updates)

    def load_srdf(self, path: str | Path | None = None) -> None:
        """Apply an SRDF's collision rules (its disabled pairs and bodies) to this robot.

        The reference's rule: a disabled pair counts only when both bodies have collision
        geometry; ``disable_default_collisions`` disables a body entirely.
        """
        from robotspec.description.srdf_reader import load_srdf

        srdf = self.srdf if path is None else load_srdf(path)
        if srdf is None:
            return
        with_geometry = {b.name for b in self.bodies_with_collisions}
        for pair in srdf.disabled_collisions:
            if pair.link1 == pair.link2:
                continue  # a link against itself (validation warns); no pair to disable
            if pair.link1 in with_geometry and pair.link2 in with_geometry:
                self.disabled_collision_pairs.add(frozenset((pair.link1, pair.link2)))
        for item in srdf.disable_default_collisions:
            if self.world.has_body(item.link):
                self.disabled_collision_bodies.add(item.link)

    # ------------------------------------------------------------------------- queries
    @property
    def kinematics(self) -> Kinematics:
        """Forward kinematics of the robot's world, built once (see :class:`Kinematics`).

        ``robot.kinematics.forward(q)`` gives every body's pose, ``.pose(q, name)`` one frame's.
        """
        if self._kinematics is None:
            from robotspec.model.kinematics import Kinematics

            self._kinematics = Kinematics(self.world)
        return self._kinematics

    def chain_kinematics(self, name: str) -> ChainKinematics:
        """The tip pose (``.fk(q)``) and Jacobian (``.jacobian(q)``) of a chain, by chain name."""
        chain = self.get_chain(name)
        return self.kinematics.chain(chain.root, chain.tip)

    def state_configuration(
        self,
        states: Sequence[str] | str = (),
        values: Mapping[str, float] | None = None,
        *,
        base: F64 | None = None,
    ) -> F64:
        """A configuration from named states and joint values: see :func:`state_configuration`.

        Why a method too: the collision room reads a robot through a protocol
        (:class:`robotspec.collision.robot_view.CollisionRobot`) and asks it for its states.
        """
        return state_configuration(self, states, values, base=base)

    def to_pinocchio(self) -> PinocchioRobot:
        """The robot as a pinocchio model and collision model, with its semantic frames' ids.

        Needs pinocchio (``pip install 'robotspec[pinocchio]'``); see
        :mod:`robotspec.interop.pinocchio` for how the world maps onto it.
        """
        from robotspec.interop.pinocchio import robot_to_pinocchio

        return robot_to_pinocchio(self)

    @classmethod
    def from_world(cls, world: World) -> AbstractRobot:
        """Build the robot over ``world``: the seed leaves this to subclasses.

        The semantic model never calls the compiler (it sits below it); the shipped robots
        (:mod:`robotspec.robots`) implement it with their spec, and any spec does the same
        through :func:`robotspec.compile_spec_for_world`.
        """
        raise TypeError(
            f"{cls.__name__} has no spec of its own; use "
            f"robotspec.compile_spec_for_world(spec, world) or a class of robotspec.robots"
        )

    def __hash__(self) -> int:
        return hash((type(self).__name__, tuple(sorted(b.name for b in self.bodies))))

    def __repr__(self) -> str:
        return (
            f"{type(self).__name__}({self.name!r}, root={self.root.name!r}, "
            f"{len(self.kinematic_chains)} chains, {len(self.manipulators)} manipulators, "
            f"{len(self.sensors)} sensors)"
        )
