"""Spec + world -> AbstractRobot: resolve every name, check what the reference never checked.

The compiler runs in two passes over the spec. The first resolves and checks everything,
recording each problem in :class:`Diagnostics` and carrying on; only when there is none does the
second pass create the semantic parts, so no half-built robot ever exists.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from robotspec.compiler.diagnostics import Diagnostics, Loc
from robotspec.semantic import (
    AbstractRobot,
    Arm,
    Camera,
    CollisionCheckingConfig,
    FieldOfView,
    Finger,
    GenericManipulator,
    GenericSensor,
    JointState,
    KinematicChain,
    Manipulator,
    Neck,
    ParallelGripper,
    Sensor,
    Torso,
    front_facing_axis_of,
)
from robotspec.spec import (
    CameraSpec,
    ChainSpec,
    FingerSpec,
    GenericManipulatorSpec,
    LoadedSpec,
    ParallelGripperSpec,
    RobotSpec,
)
from robotspec.srdf import Srdf
from robotspec.world import Body, Connection, World

__all__ = ["Build", "build_robot"]

UNIT_TOL = 1e-3
AXIS_TOL = 1e-3


@dataclass
class Build:
    """The state of one compilation: spec, world, diagnostics and what was resolved."""

    loaded: LoadedSpec
    world: World
    diag: Diagnostics
    srdf: Srdf | None
    presets: Mapping[str, Mapping[str, object]]
    robot_root: Body | None = None
    states: dict[str, JointState] = field(default_factory=dict)

    @property
    def spec(self) -> RobotSpec:
        """The validated spec."""
        return self.loaded.spec

    @property
    def where(self) -> str:
        """How error messages name the robot's description file."""
        src = self.world.source or self.world.name
        return src.rsplit("/", 1)[-1]

    # ------------------------------------------------------------------ name resolution
    def body(self, loc: Loc, name: str | None) -> Body | None:
        """The body called ``name``, or None after recording a located 'not found' error."""
        if name is None:
            return None
        if self.world.has_body(name):
            return self.world.get_body_by_name(name)
        self.diag.not_found(loc, "link", name, self.world.body_names, self.where)
        return None

    def chain_ok(
        self, loc: Loc, what: str, root: Body | None, tip: Body | None, *, allow_empty: bool = False
    ) -> bool:
        """Check that ``root`` is a proper ancestor of ``tip``; name the fix when it is not."""
        if root is None or tip is None:
            return False
        if root.index == tip.index:
            if allow_empty:
                return True
            self.diag.error(
                loc,
                f"{what} is empty: root and tip are both '{root.name}'; a chain needs at least "
                "one joint",
                name=root.name,
            )
            return False
        if self.world.is_ancestor(root, tip):
            return True
        common = self.world.common_ancestor(root, tip)
        if self.world.is_ancestor(tip, root):
            detail = f"'{tip.name}' is above '{root.name}'; swap root and tip"
        else:
            detail = (
                f"they are siblings on different branches; their common ancestor is "
                f"'{common.name}' (did you mean root '{common.name}'?)"
            )
        self.diag.error(
            loc,
            f"{what}: root '{root.name}' is not an ancestor of tip '{tip.name}': {detail}",
            name=root.name,
            suggestions=(common.name,),
        )
        return False

    def joint(self, loc: Loc, name: str) -> Connection | None:
        """The connection called ``name`` or a located 'not found' error."""
        if self.world.has_connection(name):
            return self.world.get_connection_by_name(name)
        self.diag.not_found(loc, "joint", name, self.world.connection_names, self.where)
        return None


def _unit(v: tuple[float, ...]) -> float:
    return math.sqrt(sum(x * x for x in v))


def _check_states(
    b: Build,
    loc: Loc,
    part: str,
    states: Mapping[str, Mapping[str, float]],
    allowed: set[str] | None,
) -> dict[str, JointState]:
    """Joint states: existing, actuated joints within limits, belonging to the part."""
    out: dict[str, JointState] = {}
    for state_name, values in states.items():
        ok = True
        for joint_name, value in values.items():
            jloc = (*loc, state_name, joint_name)
            c = b.joint(jloc, joint_name)
            if c is None:
                ok = False
                continue
            if c.is_fixed:
                b.diag.error(
                    jloc,
                    f"joint '{joint_name}' is fixed; a state can only set joints that move",
                    name=joint_name,
                )
                ok = False
                continue
            if c.mimic is not None:
                leader = c.mimic.leader
                b.diag.error(
                    jloc,
                    f"joint '{joint_name}' mimics '{leader}' (x{c.mimic.multiplier:g}"
                    f"{c.mimic.offset:+g}); set '{leader}' instead",
                    name=joint_name,
                    suggestions=(leader,),
                )
                ok = False
                continue
            if c.type.dof_count != 1:
                b.diag.error(
                    jloc,
                    f"joint '{joint_name}' has {c.type.dof_count} degrees of "
                    "freedom; states set 1-DOF joints",
                    name=joint_name,
                )
                ok = False
                continue
            dof = b.world.degrees_of_freedom[c.dofs[0]]
            if not math.isfinite(value):
                b.diag.error(jloc, f"value of '{joint_name}' must be finite", name=joint_name)
                ok = False
            elif not (dof.lower - 1e-9 <= value <= dof.upper + 1e-9):
                b.diag.error(
                    jloc,
                    f"{value:g} is outside the limits of '{joint_name}' "
                    f"[{dof.lower:g}, {dof.upper:g}]",
                    name=joint_name,
                )
                ok = False
            if allowed is not None and c.name not in allowed:
                b.diag.error(jloc, f"joint '{joint_name}' does not move {part}", name=joint_name)
                ok = False
        if ok:
            out[state_name] = JointState(
                name=state_name, part=part, joints=tuple((j, float(v)) for j, v in values.items())
            )
    return out


def _moved_by(world: World, connections: list[Connection]) -> set[str]:
    """Names of joints whose motion moves these connections (themselves and mimic leaders)."""
    names = {c.name for c in connections if not c.is_fixed}
    for c in connections:
        if c.mimic is not None:
            names.add(c.mimic.leader)
    return names


def _subtree_joints(world: World, root: Body) -> list[Connection]:
    inside = {b.index for b in world.subtree(root)}
    return [c for c in world.connections if c.parent in inside]


# ---------------------------------------------------------------------------- checks


def _check_manipulator(
    b: Build, name: str, m: ParallelGripperSpec | GenericManipulatorSpec
) -> tuple[Body, Body] | None:
    loc: Loc = ("manipulators", name)
    root = b.body((*loc, "root"), m.root)
    tool = b.body((*loc, "tool_frame"), m.tool_frame)
    if root is not None and tool is not None and not b.world.is_ancestor(root, tool):
        b.diag.error(
            (*loc, "tool_frame"),
            f"tool frame '{tool.name}' is not below the manipulator root '{root.name}'",
            name=tool.name,
        )
    q = m.front_facing_orientation
    norm = _unit(q)
    if abs(norm - 1.0) > UNIT_TOL:
        b.diag.error(
            (*loc, "front_facing_orientation"),
            f"must be a unit quaternion [x, y, z, w], its norm is {norm:.4g}",
        )
    elif m.front_facing_axis is not None:
        axis = m.front_facing_axis
        if abs(_unit(axis) - 1.0) > AXIS_TOL:
            b.diag.error(
                (*loc, "front_facing_axis"), f"must be a unit vector, its norm is {_unit(axis):.4g}"
            )
        else:
            derived = front_facing_axis_of(q)
            if np.linalg.norm(np.subtract(axis, derived)) > AXIS_TOL:
                b.diag.error(
                    (*loc, "front_facing_axis"),
                    f"{list(axis)} disagrees with front_facing_orientation, whose axis "
                    f"(R^T x) is {[round(x, 6) for x in derived]}; omit the axis to derive it",
                )
    if isinstance(m, ParallelGripperSpec):
        for role in ("finger", "thumb"):
            f: FingerSpec = getattr(m, role)
            floc = (*loc, role)
            froot = b.body((*floc, "root"), f.root)
            ftip = b.body((*floc, "tip"), f.tip)
            if froot is not None and root is not None and not b.world.is_ancestor(root, froot):
                b.diag.error(
                    (*floc, "root"),
                    f"{role} root '{froot.name}' is not below the gripper root '{root.name}'",
                    name=froot.name,
                )
            b.chain_ok(floc, f"{role} of '{name}'", froot, ftip)
        if m.finger.root == m.thumb.root and m.finger.tip == m.thumb.tip:
            b.diag.error((*loc, "thumb"), "finger and thumb are the same chain")
    if root is None or tool is None:
        return None
    allowed = _moved_by(b.world, _subtree_joints(b.world, root))
    b.states.update(
        {
            f"{name}.{k}": v
            for k, v in _check_states(
                b, (*loc, "states"), f"manipulator '{name}'", m.states, allowed
            ).items()
        }
    )
    return root, tool


def _camera_values(b: Build, name: str, s: CameraSpec) -> dict[str, object]:
    loc: Loc = ("sensors", name)
    values: dict[str, object] = {}
    if s.preset is not None:
        if s.preset not in b.presets:
            b.diag.not_found(
                (*loc, "preset"), "camera preset", s.preset, b.presets, "templates/cameras.yaml"
            )
        else:
            values.update(b.presets[s.preset])
    for key in ("forward_facing_axis", "minimal_height", "maximal_height"):
        v = getattr(s, key)
        if v is not None:
            values[key] = v
    if s.field_of_view is not None:
        values["field_of_view"] = {
            "horizontal": s.field_of_view.horizontal,
            "vertical": s.field_of_view.vertical,
        }
    fov = values.get("field_of_view")
    if not isinstance(fov, Mapping):
        b.diag.error(loc, f"camera '{name}' has no field_of_view (give it or a preset)")
    else:
        for key in ("horizontal", "vertical"):
            a = float(fov[key])
            if not (0.0 < a < math.pi):
                b.diag.error(
                    (*loc, "field_of_view", key), f"angle must lie in (0, pi) radians, got {a:g}"
                )
    axis = tuple(values.get("forward_facing_axis", (0.0, 0.0, 1.0)))  # type: ignore[arg-type]
    values["forward_facing_axis"] = axis
    if abs(_unit(axis) - 1.0) > AXIS_TOL:
        b.diag.error(
            (*loc, "forward_facing_axis"), f"must be a unit vector, its norm is {_unit(axis):.4g}"
        )
    elif s.body.endswith("_optical_frame") and np.linalg.norm(np.subtract(axis, (0, 0, 1))) > 1e-6:
        b.diag.warning(
            (*loc, "forward_facing_axis"),
            f"'{s.body}' is an optical frame (REP 103), whose viewing axis is +z, "
            f"but the axis is {list(axis)}",
        )
    lo = float(values.get("minimal_height", 0.0))  # type: ignore[arg-type]
    hi = float(values.get("maximal_height", 1.0))  # type: ignore[arg-type]
    if lo > hi:
        b.diag.error(
            (*loc, "minimal_height"), f"minimal_height {lo:g} is greater than maximal_height {hi:g}"
        )
    return values


def build_robot(b: Build, robot_class: type[AbstractRobot] = AbstractRobot) -> AbstractRobot:
    """Check every part of the spec, then (if nothing failed) create the robot."""
    spec = b.spec
    diag = b.diag
    root = b.body(("root",), spec.root)
    b.robot_root = root
    robot_joints: list[Connection] = []
    if root is not None:
        robot_joints = _subtree_joints(b.world, root)
    robot_joint_names = {c.name for c in robot_joints}
    # Torso and neck.
    torso_ends = neck_ends = None
    if spec.torso is not None:
        t = spec.torso
        tr, tt = b.body(("torso", "root"), t.root), b.body(("torso", "tip"), t.tip)
        if b.chain_ok(("torso",), "torso", tr, tt):
            torso_ends = (tr, tt)
            conns = b.world.compute_chain_of_connections(tr, tt)  # type: ignore[arg-type]
            b.states.update(
                {
                    f"torso.{k}": v
                    for k, v in _check_states(
                        b, ("torso", "states"), "the torso", t.states, _moved_by(b.world, conns)
                    ).items()
                }
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
        if b.chain_ok(("neck",), "neck", nr, nt):
            neck_ends = (nr, nt)
            conns = b.world.compute_chain_of_connections(nr, nt)  # type: ignore[arg-type]
            b.states.update(
                {
                    f"neck.{k}": v
                    for k, v in _check_states(
                        b, ("neck", "states"), "the neck", n.states, _moved_by(b.world, conns)
                    ).items()
                }
            )
        if not n.sensors:
            diag.error(("neck",), "a neck must carry at least one sensor")
    # Manipulators and sensors.
    manip_ends: dict[str, tuple[Body, Body]] = {}
    for name, m in spec.manipulators.items():
        ends = _check_manipulator(b, name, m)
        if ends is not None:
            manip_ends[name] = ends
    sensor_values: dict[str, dict[str, object]] = {}
    for name, s in spec.sensors.items():
        b.body(("sensors", name, "body"), s.body)
        if isinstance(s, CameraSpec):
            sensor_values[name] = _camera_values(b, name, s)
    # Chains.
    chain_ends: dict[str, tuple[Body, Body]] = {}
    used_manip: dict[str, str] = {}
    used_sensor: dict[str, str] = {}
    if spec.neck is not None:
        for i, s_name in enumerate(spec.neck.sensors):
            _use_sensor(b, ("neck", "sensors", i), s_name, "neck", used_sensor)
    for name, c in spec.chains.items():
        loc: Loc = ("chains", name)
        ends = _chain_ends(b, name, c)
        if ends is not None and b.chain_ok(loc, f"chain '{name}'", *ends):
            chain_ends[name] = ends
            conns = b.world.compute_chain_of_connections(*ends)
            b.states.update(
                {
                    f"{name}.{k}": v
                    for k, v in _check_states(
                        b, (*loc, "states"), f"chain '{name}'", c.states, _moved_by(b.world, conns)
                    ).items()
                }
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
            _use_sensor(b, (*loc, "sensors", i), s_name, f"chain '{name}'", used_sensor)
        if c.manipulator is None and not c.sensors:
            diag.warning(loc, f"chain '{name}' has neither a manipulator nor a sensor")
    for name in spec.manipulators:
        if name not in used_manip:
            diag.warning(("manipulators", name), f"manipulator '{name}' is on no chain")
    # Robot-level states, velocity limits, controlled joints, collision bodies.
    b.states.update(
        _check_states(
            b,
            ("states",),
            "the robot",
            spec.states,
            robot_joint_names if root is not None else None,
        )
    )
    velocity = _check_velocity(b, robot_joints)
    if spec.controlled_joints is not None:
        active = {c.name for c in robot_joints if c.is_active}
        for i, j in enumerate(spec.controlled_joints):
            if j not in active:
                diag.not_found(
                    ("controlled_joints", i),
                    "actuated joint",
                    j,
                    sorted(active),
                    f"robot '{spec.name}'",
                )
    for i, body_name in enumerate(spec.collision.disabled_bodies):
        body = b.body(("collision", "disabled_bodies", i), body_name)
        if body is not None and not body.has_collision:
            diag.warning(
                ("collision", "disabled_bodies", i),
                f"'{body_name}' has no collision geometry; disabling it changes nothing",
            )
    if b.srdf is not None and spec.import_srdf_group_states:
        for gs in b.srdf.group_states:
            values = {j: v[0] for j, v in gs.joint_values if len(v) == 1}
            b.states.update(
                {
                    f"{gs.group}.{k}": v
                    for k, v in _check_states(
                        b,
                        ("import_srdf_group_states",),
                        f"SRDF group '{gs.group}'",
                        {gs.name: values},
                        None,
                    ).items()
                }
            )
    diag.raise_if_failed()
    assert root is not None  # no errors means the root resolved
    return _assemble(
        b, robot_class, root, torso_ends, neck_ends, manip_ends, chain_ends, sensor_values, velocity
    )


def _use_sensor(b: Build, loc: Loc, s_name: str, owner: str, used: dict[str, str]) -> None:
    if s_name not in b.spec.sensors:
        b.diag.not_found(loc, "sensor", s_name, b.spec.sensors, "the spec's sensors")
    elif s_name in used:
        b.diag.error(loc, f"sensor '{s_name}' is already carried by {used[s_name]}")
    else:
        used[s_name] = owner


def _chain_ends(b: Build, name: str, c: ChainSpec) -> tuple[Body, Body] | None:
    loc: Loc = ("chains", name)
    if c.group is not None:
        if c.root is not None or c.tip is not None:
            b.diag.error(loc, "give either an SRDF group or root and tip, not both")
            return None
        if b.srdf is None:
            b.diag.error((*loc, "group"), "names an SRDF group, but the spec has no srdf")
            return None
        groups = {g.name: g for g in b.srdf.groups}
        if c.group not in groups:
            b.diag.not_found(
                (*loc, "group"),
                "SRDF group",
                c.group,
                groups,
                b.srdf.file.rsplit("/", 1)[-1] if b.srdf.file else "the SRDF",
            )
            return None
        group = groups[c.group]
        if len(group.chains) != 1:
            b.diag.error(
                (*loc, "group"),
                f"SRDF group '{c.group}' has {len(group.chains)} "
                "chains; a chain spec needs a group with exactly one <chain>",
            )
            return None
        base, tip = group.chains[0].base_link, group.chains[0].tip_link
        r, t = b.body((*loc, "group"), base), b.body((*loc, "group"), tip)
    else:
        if c.root is None or c.tip is None:
            b.diag.error(loc, "a chain needs root and tip, or an SRDF group")
            return None
        r, t = b.body((*loc, "root"), c.root), b.body((*loc, "tip"), c.tip)
    if r is None or t is None:
        return None
    return r, t


def _check_velocity(b: Build, robot_joints: list[Connection]) -> dict[str, float]:
    """Per-DOF velocity caps; an unknown, fixed or mimic joint is an error."""
    vl = b.spec.velocity_limits
    one_dof = {c.name: c for c in robot_joints if c.is_1dof and c.is_active}
    caps: dict[str, float] = {}
    if vl.default is not None:
        caps = {b.world.degrees_of_freedom[c.dofs[0]].name: vl.default for c in one_dof.values()}
    for j, v in vl.joints.items():
        loc: Loc = ("velocity_limits", "joints", j)
        if j not in one_dof:
            c = b.world.get_connection_by_name(j) if b.world.has_connection(j) else None
            if c is not None and c.mimic is not None:
                b.diag.error(
                    loc,
                    f"joint '{j}' mimics '{c.mimic.leader}'; limit the leader",
                    name=j,
                    suggestions=(c.mimic.leader,),
                )
            else:
                b.diag.not_found(loc, "actuated 1-DOF joint", j, one_dof, f"robot '{b.spec.name}'")
            continue
        dof = b.world.degrees_of_freedom[one_dof[j].dofs[0]]
        if v > dof.velocity:
            b.diag.warning(
                loc,
                f"{v:g} is above the URDF's velocity limit {dof.velocity:g} of "
                f"'{j}'; limits only tighten, so it has no effect",
            )
        caps[dof.name] = v
    return caps


def _assemble(
    b: Build,
    robot_class: type[AbstractRobot],
    root: Body,
    torso_ends: tuple[Body | None, Body | None] | None,
    neck_ends: tuple[Body | None, Body | None] | None,
    manip_ends: dict[str, tuple[Body, Body]],
    chain_ends: dict[str, tuple[Body, Body]],
    sensor_values: dict[str, dict[str, object]],
    velocity: dict[str, float],
) -> AbstractRobot:
    spec, w = b.spec, b.world
    cfg = spec.collision
    robot = robot_class(
        name=spec.name,
        root=root,
        world=w,
        default_collision_config=CollisionCheckingConfig(
            buffer_zone_distance=cfg.buffer_distance, violated_distance=cfg.violated_distance
        ),
        srdf=b.srdf,
        drive_type=_drive_type(b),
        controlled_joint_names=None
        if spec.controlled_joints is None
        else tuple(spec.controlled_joints),
    )
    sensors: dict[str, Sensor] = {}
    for name, s in spec.sensors.items():
        body = w.get_body_by_name(s.body)
        if isinstance(s, CameraSpec):
            v = sensor_values[name]
            fov = v["field_of_view"]
            assert isinstance(fov, Mapping)
            sensors[name] = Camera(
                name=name,
                root=body,
                world=w,
                forward_facing_axis=tuple(v["forward_facing_axis"]),  # type: ignore[arg-type]
                field_of_view=FieldOfView(
                    vertical_angle=float(fov["vertical"]), horizontal_angle=float(fov["horizontal"])
                ),
                minimal_height=float(v.get("minimal_height", 0.0)),  # type: ignore[arg-type]
                maximal_height=float(v.get("maximal_height", 1.0)),  # type: ignore[arg-type]
                default_camera=s.default,
            )
        else:
            sensors[name] = GenericSensor(name=name, root=body, world=w, kind=s.kind)
    manipulators: dict[str, Manipulator] = {}
    for name, m in spec.manipulators.items():
        mroot, tool = manip_ends[name]
        axis = m.front_facing_axis or front_facing_axis_of(m.front_facing_orientation)
        states = {k.split(".", 1)[1]: v for k, v in b.states.items() if k.startswith(name + ".")}
        common = {
            "name": name,
            "root": mroot,
            "world": w,
            "tool_frame": tool,
            "front_facing_orientation": m.front_facing_orientation,
            "front_facing_axis": tuple(axis),
            "states": states,
        }
        if isinstance(m, ParallelGripperSpec):
            fingers = {
                role: Finger(
                    name=f"{name}_{role}",
                    root=w.get_body_by_name(f.root),
                    world=w,
                    tip=w.get_body_by_name(f.tip),
                )
                for role, f in (("finger", m.finger), ("thumb", m.thumb))
            }
            manipulators[name] = ParallelGripper(
                **common,
                finger=fingers["finger"],  # type: ignore[arg-type]
                thumb=fingers["thumb"],
            )
        else:
            assert isinstance(m, GenericManipulatorSpec)
            manipulators[name] = GenericManipulator(**common)  # type: ignore[arg-type]

    def part_states(prefix: str) -> dict[str, JointState]:
        return {k.split(".", 1)[1]: v for k, v in b.states.items() if k.startswith(prefix + ".")}

    if spec.torso is not None and torso_ends is not None:
        tr, tt = torso_ends
        assert tr is not None and tt is not None
        robot.add_torso(Torso(name="torso", root=tr, world=w, tip=tt, states=part_states("torso")))
    if spec.neck is not None and neck_ends is not None:
        n = spec.neck
        nr, nt = neck_ends
        assert nr is not None and nt is not None
        robot.add_neck(
            Neck(
                name="neck",
                root=nr,
                world=w,
                tip=nt,
                sensors=[sensors[s] for s in n.sensors],
                pitch_body=None if n.pitch_body is None else w.get_body_by_name(n.pitch_body),
                yaw_body=None if n.yaw_body is None else w.get_body_by_name(n.yaw_body),
                states=part_states("neck"),
            )
        )
    for name, c in spec.chains.items():
        cr, ct = chain_ends[name]
        cls: type[KinematicChain] = Arm if c.manipulator is not None else KinematicChain
        chain = cls(
            name=name,
            root=cr,
            world=w,
            tip=ct,
            manipulator=None if c.manipulator is None else manipulators[c.manipulator],
            sensors=[sensors[s] for s in c.sensors],
            states=part_states(name),
        )
        robot.add_kinematic_chain(chain, warn=False)
    carried = {s.name for ch in robot.kinematic_chains for s in ch.sensors}
    for name, s in sensors.items():
        if name not in carried:
            robot.add_sensor(s)
    for m in manipulators.values():
        if m not in robot.manipulators:
            robot.add_manipulator(m)
    robot.joint_states.update(b.states)
    if velocity:
        w.tighten_velocity_limits(velocity)
    robot.disabled_collision_bodies.update(spec.collision.disabled_bodies)
    if spec.collision.use_srdf:
        robot.load_srdf()
    return robot


def _drive_type(b: Build) -> str:
    if b.spec.drive is not None:
        return b.spec.drive.type
    root = b.robot_root
    parent = None if root is None else b.world.parent_connection(root)
    if parent is None or parent.is_fixed:
        return "fixed"
    return {"planar": "omni", "floating": "floating"}.get(parent.type.value, parent.type.value)
