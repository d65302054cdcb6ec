"""Spec + world -> AbstractRobot: resolve every name, check what the reference never checked.

The compiler runs in two passes over the spec. The first resolves and checks everything,
recording each problem in :class:`Diagnostics` and carrying on; only when there is none does the
second pass (``assemble``) create the semantic parts, so no half-built robot ever exists.
"""

from __future__ import annotations

from robotspec.compiler.assemble import Resolved, assemble, check_forward
from robotspec.compiler.context import Build, moved_by, subtree_joints
from robotspec.compiler.joints import (
    check_controlled,
    check_states,
    check_velocity,
    srdf_state_values,
)
from robotspec.compiler.kinematic_checks import KinematicInputs, check_kinematics
from robotspec.compiler.part_checks import check_parts
from robotspec.compiler.parts import (
    CameraValues,
    camera_values,
    chain_ends,
    check_manipulator,
    use_sensor,
)
from robotspec.diagnostics import Loc
from robotspec.model.world import Body, Connection
from robotspec.semantic import AbstractRobot
from robotspec.spec.models import CameraSpec

__all__ = ["Build", "build_robot"]


def build_robot(b: Build, robot_class: type[AbstractRobot] = AbstractRobot) -> AbstractRobot:
    """Check every part of the spec, then (if nothing failed) create the robot.

    The parts are checked in the spec's order (torso, neck, manipulators, sensors, chains, the
    robot as a whole), so problems are reported in the order a reader meets them.
    """
    spec = b.spec
    root = b.body(("root",), spec.root)
    b.robot_root = root
    check_forward(b)
    robot_joints: list[Connection] = []
    if root is not None:
        robot_joints = subtree_joints(b.world, root)
    torso_ends = _torso(b)
    neck_ends = _neck(b)
    manip_ends: dict[str, tuple[Body, Body]] = {}
    for name, manip in spec.manipulators.items():
        ends = check_manipulator(b, name, manip)
        if ends is not None:
            manip_ends[name] = ends
    cameras = _sensors(b)
    chain_ends_by_name = _chains(b, manip_ends)
    velocity = _robot_wide(b, robot_joints if root is not None else None)
    # Checks across parts and with the robot's kinematics, over what resolved.
    check_parts(b, cameras)
    if root is not None:
        check_kinematics(
            b,
            KinematicInputs(
                root=root,
                torso=torso_ends,
                neck=neck_ends,
                chains=chain_ends_by_name,
                manipulators=manip_ends,
                cameras=cameras,
            ),
        )
    b.diag.raise_if_failed()
    assert root is not None  # no errors means the root resolved
    resolved = Resolved(
        root=root,
        torso=torso_ends,
        neck=neck_ends,
        manipulators=manip_ends,
        chains=chain_ends_by_name,
        cameras=cameras,
        velocity=velocity,
    )
    return assemble(b, resolved, robot_class)


def _torso(b: Build) -> tuple[Body, Body] | None:
    """The torso's ends and states, when the spec has a torso that resolves."""
    t = b.spec.torso
    if t is None:
        return None
    tr, tt = b.body(("torso", "root"), t.root), b.body(("torso", "tip"), t.tip)
    if not (b.chain_ok(("torso",), "torso", tr, tt) and tr is not None and tt is not None):
        return None
    conns = b.world.compute_chain_of_connections(tr, tt)
    b.add_states(
        "torso",
        check_states(b, ("torso", "states"), "the torso", t.states, moved_by(b.world, conns)),
    )
    return tr, tt


def _neck(b: Build) -> tuple[Body, Body] | None:
    """The neck's ends and states; its pitch and yaw bodies on it; at least one sensor."""
    n = b.spec.neck
    if n is None:
        return None
    nr, nt = b.body(("neck", "root"), n.root), b.body(("neck", "tip"), n.tip)
    for key in ("pitch_body", "yaw_body"):
        body = b.body(("neck", key), getattr(n, key))
        if (
            body is not None
            and nr is not None
            and nt is not None
            and not (b.world.is_ancestor(nr, body) and b.world.is_ancestor(body, nt))
        ):
            b.diag.error(
                ("neck", key),
                f"'{body.name}' is not on the neck chain '{n.root}' -> '{n.tip}'",
                name=body.name,
            )
    ends: tuple[Body, Body] | None = None
    if b.chain_ok(("neck",), "neck", nr, nt) and nr is not None and nt is not None:
        ends = (nr, nt)
        conns = b.world.compute_chain_of_connections(nr, nt)
        b.add_states(
            "neck",
            check_states(b, ("neck", "states"), "the neck", n.states, moved_by(b.world, conns)),
        )
    if not n.sensors:
        b.diag.error(("neck",), "a neck must carry at least one sensor")
    return ends


def _sensors(b: Build) -> dict[str, CameraValues]:
    """Every sensor's body resolved; each camera's values (frame, field of view)."""
    cameras: dict[str, CameraValues] = {}
    for name, sensor in b.spec.sensors.items():
        b.body(("sensors", name, "body"), sensor.body)
        if isinstance(sensor, CameraSpec):
            values = camera_values(b, name, sensor)
            if values is not None:
                cameras[name] = values
    return cameras


def _chains(b: Build, manip_ends: dict[str, tuple[Body, Body]]) -> dict[str, tuple[Body, Body]]:
    """Each chain's ends and states, and what it carries: each manipulator and sensor once."""
    spec, diag = b.spec, b.diag
    chain_ends_by_name: dict[str, tuple[Body, Body]] = {}
    used_manip: dict[str, str] = {}
    used_sensor: dict[str, str] = {}
    if spec.neck is not None:
        for i, s_name in enumerate(spec.neck.sensors):
            use_sensor(b, ("neck", "sensors", i), s_name, "neck", used_sensor)
    for name, c in spec.chains.items():
        loc: Loc = ("chains", name)
        ends = chain_ends(b, name, c)
        if ends is not None and b.chain_ok(loc, f"chain '{name}'", *ends):
            chain_ends_by_name[name] = ends
            conns = b.world.compute_chain_of_connections(*ends)
            b.add_states(
                name,
                check_states(
                    b, (*loc, "states"), f"chain '{name}'", c.states, moved_by(b.world, conns)
                ),
            )
        if c.manipulator is not None:
            _carry_manipulator(b, loc, name, c.manipulator, ends, manip_ends, used_manip)
        for i, s_name in enumerate(c.sensors):
            use_sensor(b, (*loc, "sensors", i), s_name, f"chain '{name}'", used_sensor)
        if c.manipulator is None and not c.sensors and c.kind == "arm":
            diag.warning(
                loc,
                f"chain '{name}' has neither a manipulator nor a sensor (not an arm? say "
                "'kind: leg' or 'kind: chain')",
            )
    for name in spec.manipulators:
        if name not in used_manip:
            diag.warning(("manipulators", name), f"manipulator '{name}' is on no chain")
    return chain_ends_by_name


def _carry_manipulator(
    b: Build,
    loc: Loc,
    chain: str,
    manipulator: str,
    ends: tuple[Body, Body] | None,
    manip_ends: dict[str, tuple[Body, Body]],
    used_manip: dict[str, str],
) -> None:
    """Chain ``chain`` carries ``manipulator``: it exists, no other chain has it, it is below."""
    diag = b.diag
    if manipulator not in b.spec.manipulators:
        diag.not_found(
            (*loc, "manipulator"),
            "manipulator",
            manipulator,
            b.spec.manipulators,
            "the spec's manipulators",
        )
    elif manipulator in used_manip:
        diag.error(
            (*loc, "manipulator"),
            f"manipulator '{manipulator}' is already carried by chain '{used_manip[manipulator]}'",
        )
    else:
        used_manip[manipulator] = chain
        me = manip_ends.get(manipulator)
        if me is not None and ends is not None and not b.world.is_ancestor(ends[1], me[0]):
            diag.error(
                (*loc, "manipulator"),
                f"manipulator '{manipulator}' (root "
                f"'{me[0].name}') is not below the chain's tip '{ends[1].name}'",
            )


def _robot_wide(b: Build, robot_joints: list[Connection] | None) -> dict[str, float]:
    """The robot as a whole: states, velocity limits, controlled joints, collision, SRDF states.

    ``robot_joints`` is None when the root did not resolve (states then name joints unchecked).
    """
    spec, diag = b.spec, b.diag
    joints = robot_joints or []
    b.states.update(
        check_states(
            b,
            ("states",),
            "the robot",
            spec.states,
            {c.name for c in joints} if robot_joints is not None else None,
        )
    )
    velocity = check_velocity(b, joints)
    if spec.controlled_joints is not None:
        check_controlled(b, joints, spec.controlled_joints)
    for i, body_name in enumerate(spec.collision.disabled_bodies):
        body = b.body(("collision", "disabled_bodies", i), body_name)
        if body is not None and not body.has_collision:
            diag.warning(
                ("collision", "disabled_bodies", i),
                f"'{body_name}' has no collision geometry; disabling it changes nothing",
            )
    if b.srdf is not None and spec.import_srdf_group_states:
        for gs in b.srdf.group_states:
            if gs.group is None:
                continue  # a group-less state (lenient SRDF read) belongs to no part
            single = srdf_state_values(b, gs)
            b.add_states(
                gs.group,
                check_states(
                    b,
                    ("import_srdf_group_states",),
                    f"SRDF group '{gs.group}'",
                    {gs.name: single},
                    None,
                ),
            )
    return velocity
