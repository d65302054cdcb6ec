"""Wheels and the drive as a URDF's control blocks state them (transmissions, drive plugins).

Why: a wheel is known by its name or its shape (``base.wheel_joints``), but a continuous joint
commanded in velocity only, turning about a level axis and carrying nothing that moves, is a
wheel whatever its name and mesh; and which wheels are driven decides the drive better than
their count: MiR's two driven wheels among six (four on casters) make a differential base, a
Scout's four driven wheels on one axle direction a skid-steered (differential) one, HSR-B's two
on a turntable an omnidirectional one. A Gazebo
drive plugin (``diff_drive``, ``skid_steer_drive``, ``planar_move``, gz-sim's ``DiffDrive``,
``MecanumDrive``) states the kind itself: no question left.
"""

from __future__ import annotations

import numpy as np

from robotspec.model.entities import Connection, ConnectionType
from robotspec.model.world import World
from robotspec.spec.draft.confidence import DRIVE_PLUGIN, drive_plugin_question
from robotspec.spec.draft.facts import FileFacts
from robotspec.spec.draft.model import DraftDrive
from robotspec.spec.draft.tree import Tree, words

__all__ = ["counted_drive", "stated_drive", "stated_wheels"]

#: The cosine within which two wheel axes are one direction (an axle), or an axis is level.
_PARALLEL = 0.99
_LEVEL = 0.3


def _driven_wheel(tree: Tree, c: Connection) -> bool:
    """A continuous joint about a level axis below which nothing moves."""
    if c.type is not ConnectionType.CONTINUOUS or tree.moves_below(tree.world.bodies[c.child]):
        return False
    return abs(float(tree.axis_in_root(c)[2])) < _LEVEL


def stated_wheels(tree: Tree, facts: FileFacts, found: list[Connection]) -> list[Connection]:
    """``found`` and the wheels the files state: drive plugins' wheels, velocity-only joints."""
    world = tree.world
    names = {c.name for c in found}
    extra: list[Connection] = []
    plugin_wheels = {w for d in facts.actuation.drives for w in d.wheels}
    for c in world.connections:
        if c.name in names or c.is_fixed or c.is_mimic:
            continue
        said = c.name in plugin_wheels or facts.actuation.velocity_only(c.name)
        if said and _driven_wheel(tree, c):
            extra.append(c)
    return [*found, *extra] or _axle_pairs(tree)


#: How closely (cosine) two wheels' axes, and the line between them, must agree to be one axle.
_AXLE = 0.95


def _axle_pairs(tree: Tree) -> list[Connection]:
    """Unnamed wheels on the chassis: continuous joints about level axes, paired on an axle.

    Why: when neither a name, a shape nor a control block says which joints are wheels (a
    mesh named by a part number), the axle still does: two continuous joints on the chassis
    (only fixed joints above them), nothing moving below, turning about parallel level axes
    with the line between them along those axes. A gripper's jaws turn about parallel axes
    too, but lie apart across them, not along them.
    """
    world = tree.world
    cands = [c for c in world.connections if _on_chassis(tree, c)]
    paired: set[str] = set()
    for i, a in enumerate(cands):
        for b in cands[i + 1 :]:
            if _one_axle(tree, a, b):
                paired |= {a.name, b.name}
    return [c for c in cands if c.name in paired]


def _on_chassis(tree: Tree, c: Connection) -> bool:
    """A continuous joint about a level axis, fixed to the root, nothing moving below it."""
    world = tree.world
    above = world.bodies[c.parent]
    if c.type is not ConnectionType.CONTINUOUS or not c.is_active:
        return False
    if tree.moves_below(world.bodies[c.child]) or words(c.name) & {"caster", "castor"}:
        return False
    if abs(float(tree.axis_in_root(c)[2])) >= _LEVEL or not world.is_ancestor(tree.root, above):
        return False
    return all(k.is_fixed for k in world.compute_chain_of_connections(tree.root, above))


def _one_axle(tree: Tree, a: Connection, b: Connection) -> bool:
    """Whether two joints turn about one axle: parallel axes, the line between them along it."""
    ax, bx = tree.axis_in_root(a), tree.axis_in_root(b)
    ax = ax / (np.linalg.norm(ax) or 1.0)
    if abs(float(ax @ bx)) / (np.linalg.norm(bx) or 1.0) < _AXLE:
        return False
    apart = tree.position(tree.world.bodies[b.child]) - tree.position(tree.world.bodies[a.child])
    n = float(np.linalg.norm(apart))
    return n > 1e-3 and abs(float(apart @ ax)) / n > _AXLE


def _steered(tree: Tree, c: Connection) -> bool:
    """Whether a joint moves the wheel's axle (HSR-B's turntable, a steered caster)."""
    world = tree.world
    above = world.bodies[c.parent]
    if above is tree.root or not world.is_ancestor(tree.root, above):
        return False
    return any(not k.is_fixed for k in world.compute_chain_of_connections(tree.root, above))


def _one_axle_direction(tree: Tree, wheels: list[Connection]) -> bool:
    axes = [tree.axis_in_root(c) for c in wheels]
    first = axes[0] / (np.linalg.norm(axes[0]) or 1.0)
    return all(abs(float(a @ first)) / (np.linalg.norm(a) or 1.0) > _PARALLEL for a in axes)


#: Words a wheel's link or mesh carries when it rolls sideways too (rollers on its rim).
_OMNI_WORDS = frozenset({"omni", "mecanum", "swedish"})


def _omni_wheels(world: World, wheels: list[Connection]) -> bool:
    """Whether every wheel's link or mesh file is named as an omni or mecanum wheel.

    Parallel axles cannot tell a skid-steer base from a mecanum one; the wheel's own model
    can (Summit-XLS's 'omni_wheel_1.dae').
    """

    def named(c: Connection) -> bool:
        body = world.bodies[c.child]
        found = set(words(body.name))
        for shape in (*body.visuals, *body.collisions):
            uri = getattr(shape.geometry, "uri", None)
            if isinstance(uri, str):
                found |= words(uri.rsplit("/", 1)[-1].rsplit(".", 1)[0])
        return bool(found & _OMNI_WORDS)

    return bool(wheels) and all(named(c) for c in wheels)


def _plugin_drive(tree: Tree, facts: FileFacts) -> DraftDrive | None:
    """The drive a Gazebo drive plugin of the URDF states, on wheels the URDF has (else None)."""
    world = tree.world
    for plugin in facts.actuation.drives:
        if all(world.has_connection(w) for w in plugin.wheels):
            why = drive_plugin_question(plugin.plugin)  # Ackermann: not a kind robotspec has
            return DraftDrive(
                plugin.kind,
                source=f"the Gazebo drive plugin '{plugin.plugin}'",
                decide=why,
                stated=DRIVE_PLUGIN if why is None else None,
            )
    return None


def stated_drive(tree: Tree, facts: FileFacts, wheels: list[Connection]) -> DraftDrive | None:
    """The drive the files state (a Gazebo drive plugin) or their driven wheels suggest.

    None when they say nothing about the wheels (the count of wheels decides, as before).
    """
    world = tree.world
    plugin = _plugin_drive(tree, facts)
    if plugin is not None:
        return plugin
    names = {c.name for c in wheels}
    driven = [c for c in wheels if facts.actuation.velocity_only(c.name)]
    if not driven or len(driven) == len(names) == 2:
        return None
    if _omni_wheels(world, driven):
        kind = "omni"
        why = f"{len(driven)} wheel joints driven in velocity, their wheels named omni or mecanum"
    elif any(_steered(tree, c) for c in driven):
        kind = "omni"
        why = f"{len(driven)} wheel joints driven in velocity on a turning base: omni?"
    elif _one_axle_direction(tree, driven):
        kind = "differential"
        why = (
            f"{len(driven)} of {len(wheels)} wheel joints driven in velocity, on parallel axles:"
            f" differential{' (skid steer)' if len(driven) > 2 else ''}? (mecanum wheels: omni)"
        )
    else:
        kind, why = "omni", f"{len(driven)} wheel joints driven in velocity, axles turned: omni?"
    return DraftDrive(kind, source="the URDF's transmissions", decide=why)


def counted_drive(tree: Tree, wheels: list[Connection]) -> str:
    """The drive the wheels' shape suggests when no file says which are driven (asked).

    Two wheels: differential. More, each at the end of a leg (moving joints above it, none
    about the vertical) on parallel axles: a wheel-legged robot rolling skid steer, a
    differential drive (LimX's P311D). Otherwise omni: four wheels on a chassis may be
    mecanum whatever their names (RoboMaster S1's), asked either way.
    """
    if len(wheels) == 2:
        return "differential"
    world = tree.world
    if _omni_wheels(world, wheels) or not _one_axle_direction(tree, wheels):
        return "omni"
    for c in wheels:
        above = world.bodies[c.parent]
        if above is tree.root or not world.is_ancestor(tree.root, above):
            return "omni"
        moving = [k for k in world.compute_chain_of_connections(tree.root, above) if not k.is_fixed]
        if not moving or any(abs(float(tree.axis_in_root(k)[2])) >= 1 - _LEVEL for k in moving):
            return "omni"  # on the chassis, or steered about the vertical (a swerve module)
    return "differential"
