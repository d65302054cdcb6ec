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
    """Check every part of the spec, then (if nothing failed) create the robot."""
    spec = b.spec
    diag = b.diag
    root = b.body(("root",), spec.root)
    b.robot_root = root
    check_forward(b)
    robot_joints: list[Connection] = []
    if root is not None:
        robot_joints = subtree_joints(b.world, root)
    robot_joint_names = {c.name for c in robot_joints}
    # Torso and neck.
    torso_ends: tuple[Body, Body] | None = None
    neck_ends: tuple[Body, Body] | None = None
    if spec.torso is not None:
        t = spec.torso
        tr, tt = b.body(("torso", "root"), t.root), b.body(("torso", "tip"), t.tip)
        if b.chain_ok(("torso",), "torso", tr, tt) and tr is not None and tt is not None:
            torso_ends = (tr, tt)
            conns = b.world.compute_chain_of_connections(tr, tt)
            b.add_states(
                "torso",
                check_states(
                    b, ("torso", "states"), "the torso", t.states, moved_by(b.world, conns)
                ),
            )
    if spec.neck is not None:
        n = spec.neck
        nr, nt = b.body(("neck", "root"), n.root), b.body(("neck", "tip"), n.tip)
        for key in ("pitch_body", "yaw_body"):
            body = b.body(("neck", key), getattr(n, key))
            if (
                body is not None
                and nr is not None
                and nt is not None
                and not (b.world.is_ancestor(nr, body) and b.world.is_ancestor(body, nt))
            ):
                diag.error(
                    ("neck", key),
                    f"'{body.name}' is not on the neck chain '{n.root}' -> '{n.tip}'",
                    name=body.name,
                )
        if b.chain_ok(("neck",), "neck", nr, nt) and nr is not None and nt is not None:
            neck_ends = (nr, nt)
            conns = b.world.compute_chain_of_connections(nr, nt)
            b.add_states(
                "neck",
                check_states(b, ("neck", "states"), "the neck", n.states, moved_by(b.world, conns)),
            )
        if not n.sensors:
            diag.error(("neck",), "a neck must carry at least one sensor")
    # Manipulators and sensors.
    manip_ends: dict[str, tuple[Body, Body]] = {}
    for name, manip in spec.manipulators.items():
        ends = check_manipulator(b, name, manip)
        if ends is not None:
            manip_ends[name] = ends
    cameras: dict[str, CameraValues] = {}
    for name, sensor in spec.sensors.items():
        b.body(("sensors", name, "body"), sensor.body)
        if isinstance(sensor, CameraSpec):
            values = camera_values(b, name, sensor)
            if values is not None:
                cameras[name] = values
    # Chains.
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
            if c.manipulator not in spec.manipulators:
                diag.not_found(
                    (*loc, "manipulator"),
                    "manipulator",
                    c.manipulator,
                    spec.manipulators,
                    "the spec's manipulators",
                )
            elif c.manipulator in used_manip:
                diag.error(
                    (*loc, "manipulator"),
                    f"manipulator '{c.manipulator}' is already "
                    f"carried by chain '{used_manip[c.manipulator]}'",
                )
            else:
                used_manip[c.manipulator] = name
                me = manip_ends.get(c.manipulator)
                if me is not None and ends is not None and not b.world.is_ancestor(ends[1], me[0]):
                    diag.error(
                        (*loc, "manipulator"),
                        f"manipulator '{c.manipulator}' (root "
                        f"'{me[0].name}') is not below the chain's tip '{ends[1].name}'",
                    )
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
    # Robot-level states, velocity limits, controlled joints, collision bodies.
    b.states.update(
        check_states(
            b,
            ("states",),
            "the robot",
            spec.states,
            robot_joint_names if root is not None else None,
        )
    )
    velocity = check_velocity(b, robot_joints)
    if spec.controlled_joints is not None:
        check_controlled(b, robot_joints, spec.controlled_joints)
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
    diag.raise_if_failed()
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
