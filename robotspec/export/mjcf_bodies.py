"""The bodies of an MJCF export: joints, inertials, geoms, sites and cameras, one body at a time.

Why apart from :mod:`robotspec.export.mjcf`: this is the part that walks the world's tree and
decides how each robotspec record is spelled in MJCF; the file-level sections (servos,
couplings, keyframes) only need its result, the joints in MuJoCo's order.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from lxml import etree

from robotspec.arrays import F64
from robotspec.errors import RobotSpecError
from robotspec.export.mjcf_dynamics import Inertial, urdf_dynamics, urdf_inertials
from robotspec.export.mjcf_meshes import MeshAssets
from robotspec.model.entities import Body, Connection, ConnectionType
from robotspec.model.geometry import Box, Capsule, Cylinder, Mesh, Shape, Sphere
from robotspec.model.kinematics import _in_plane_axes as in_plane_axes
from robotspec.model.rotations import matrix_to_quat_wxyz
from robotspec.semantic import AbstractRobot
from robotspec.semantic.sensors import Camera

__all__ = ["BodyWriter", "MjcfJoint", "TINY_MASS", "camera_frame", "num", "nums", "place"]

#: Mass and inertia given to a moving body that, with what is welded to it, has none: MuJoCo
#: refuses a massless moving body (URDF frames on a joint, links without ``<inertial>``).
TINY_MASS, TINY_INERTIA = 1e-6, 1e-9


@dataclass(frozen=True)
class MjcfJoint:
    """A joint of the MJCF and the robotspec configuration entry it reads.

    ``dof`` is the world's DOF index (the leader's for a mimic joint, with its ``multiplier``
    and ``offset``); a ``free`` joint reads the six DOFs of ``connection``.
    """

    name: str
    kind: str  # "hinge", "slide" or "free"
    dof: int
    multiplier: float = 1.0
    offset: float = 0.0
    connection: int = -1


def num(value: float) -> str:
    """A float as MJCF text, exact (``repr``: MuJoCo parses it back to the same double)."""
    return repr(float(value)) if value != 0.0 else "0"


def nums(values: Sequence[float] | F64) -> str:
    """Floats as one space-separated MJCF attribute."""
    return " ".join(num(float(v)) for v in values)


def place(el: etree._Element, pose: F64) -> None:
    """``pos``/``quat`` of a 4x4 pose, left out where they are the identity."""
    if np.any(pose[:3, 3] != 0.0):
        el.set("pos", nums(pose[:3, 3]))
    if not np.array_equal(pose[:3, :3], np.eye(3)):
        el.set("quat", nums(matrix_to_quat_wxyz(pose[:3, :3])))


class BodyWriter:
    """One export: the document as it grows, and what the joints and notes are."""

    def __init__(self, robot: AbstractRobot, tree: etree._Element, mesh_folder: str) -> None:
        self.robot = robot
        self.world = robot.world
        self.inertials: dict[str, Inertial] = urdf_inertials(tree)
        self.dynamics = urdf_dynamics(tree)
        self.assets = MeshAssets(mesh_folder)
        self.joints: dict[str, MjcfJoint] = {}
        self.notes: list[str] = []
        self.drive = robot.drive
        self.disabled = set(robot.disabled_collision_bodies)
        self.tool_frames = {m.tool_frame.name for m in robot.manipulators}
        self.cameras: dict[str, list[Camera]] = {}
        for camera in robot.cameras:
            self.cameras.setdefault(camera.root.name, []).append(camera)

    # ------------------------------------------------------------------------- bodies
    def body(self, parent: etree._Element, body: Body, via: Connection | None) -> None:
        """``body`` below ``parent``, entered ``via`` its connection, and its subtree."""
        if body.name == "world" and body.index != 0:
            raise RobotSpecError(
                "a body named 'world' that is not the robot's root cannot be exported to MJCF "
                "(MuJoCo's world body has that name)",
                name=body.name,
                kind="link",
            )
        # A root named 'world' is MuJoCo's world body itself (static, at the origin).
        el = parent if body.name == "world" else etree.SubElement(parent, "body", name=body.name)
        if via is not None:
            place(el, via.origin)
            self.add_joints(el, via)
        self.add_inertial(el, body, moving=via is not None and not via.is_fixed)
        for shape in body.visuals:
            self.geom(el, shape, "visual", body)
        for shape in body.collisions:
            self.geom(el, shape, "collision", body)
        if body.name in self.tool_frames:
            etree.SubElement(el, "site", name=body.name)
        for camera in self.cameras.get(body.name, []):
            self.camera(el, camera)
        for child in self.world.child_bodies(body):
            conn = self.world.parent_connection(child)
            assert conn is not None
            if conn.type is ConnectionType.FLOATING and body.index == 0:
                continue  # a free joint must be on a top-level body: placed by the caller
            self.body(el, child, conn)

    def add_joints(self, el: etree._Element, c: Connection) -> None:
        """The MJCF joints of ``c`` (a planar connection is two slides and a hinge)."""
        t = c.type
        if t is ConnectionType.FIXED:
            return
        if t is ConnectionType.FLOATING:
            etree.SubElement(el, "freejoint", name=c.name)
            self.joints[c.name] = MjcfJoint(c.name, "free", -1, connection=c.index)
            return
        if t is ConnectionType.PLANAR:
            u, w = in_plane_axes(c.axis)
            names = [self.world.degrees_of_freedom[d].name for d in c.dofs]
            axes: tuple[F64, F64, F64] = (u, w, np.asarray(c.axis, dtype=np.float64))
            for name, kind, axis, index in zip(
                names, ("slide", "slide", "hinge"), axes, c.dofs, strict=True
            ):
                etree.SubElement(el, "joint", name=name, type=kind, axis=nums(axis))
                self.joints[name] = MjcfJoint(name, kind, index)
            return
        kind = "slide" if t is ConnectionType.PRISMATIC else "hinge"
        joint = etree.SubElement(el, "joint", name=c.name, type=kind, axis=nums(c.axis))
        if c.mimic is not None:
            self.joints[c.name] = MjcfJoint(
                c.name, kind, c.dofs[0], c.mimic.multiplier, c.mimic.offset
            )
        else:
            self.joints[c.name] = MjcfJoint(c.name, kind, c.dofs[0])
            dof = self.world.degrees_of_freedom[c.dofs[0]]
            if t is not ConnectionType.CONTINUOUS and dof.is_bounded:
                joint.set("range", nums((dof.lower, dof.upper)))
        dyn = self.dynamics.get(c.name)
        if dyn is not None and dyn.damping > 0.0:
            joint.set("damping", num(dyn.damping))
        if dyn is not None and dyn.friction > 0.0:
            joint.set("frictionloss", num(dyn.friction))

    def welded_mass(self, body: Body) -> float:
        """The mass of ``body`` and of what fixed joints weld to it (MuJoCo's moving unit)."""
        total = self.inertials[body.name].mass if body.name in self.inertials else 0.0
        for child in self.world.child_bodies(body):
            conn = self.world.parent_connection(child)
            if conn is not None and conn.is_fixed:
                total += self.welded_mass(child)
        return total

    def add_inertial(self, el: etree._Element, body: Body, *, moving: bool) -> None:
        """The URDF inertial in principal axes (MuJoCo checks the tensor), or a tiny one."""
        inertial = self.inertials.get(body.name)
        if inertial is None:
            if moving and self.welded_mass(body) == 0.0:
                etree.SubElement(
                    el,
                    "inertial",
                    pos="0 0 0",
                    mass=num(TINY_MASS),
                    diaginertia=nums((TINY_INERTIA,) * 3),
                )
                self.notes.append(
                    f"body '{body.name}' moves but has no mass in the URDF: given "
                    f"{TINY_MASS} kg (MuJoCo refuses massless moving bodies)"
                )
            return
        values, vectors = np.linalg.eigh(inertial.tensor)
        if np.linalg.det(vectors) < 0.0:
            vectors[:, 0] = -vectors[:, 0]
        if values[0] < -1e-9 * max(float(values[-1]), TINY_INERTIA):
            # Not rounding: a tensor no body can have (MuJoCo would refuse it). Said, not hidden.
            self.notes.append(
                f"body '{body.name}': the URDF inertia has a negative principal moment "
                f"({values[0]:.3g} kg m^2): raised to {TINY_INERTIA} (check the URDF's inertia)"
            )
        values = np.maximum(values, TINY_INERTIA)
        etree.SubElement(
            el,
            "inertial",
            pos=nums(inertial.com),
            quat=nums(matrix_to_quat_wxyz(vectors)),
            mass=num(inertial.mass),
            diaginertia=nums(values),
        )

    # ------------------------------------------------------------------------- geometry
    def geom(self, el: etree._Element, shape: Shape, cls: str, body: Body) -> None:
        """One visual or collision shape (a mesh cut in pieces is one geom per piece)."""
        g = shape.geometry
        attrs: dict[str, str]
        if isinstance(g, Box):
            attrs = {"type": "box", "size": nums([s / 2.0 for s in g.size])}
        elif isinstance(g, Sphere):
            attrs = {"type": "sphere", "size": num(g.radius)}
        elif isinstance(g, Cylinder | Capsule):
            kind = "cylinder" if isinstance(g, Cylinder) else "capsule"
            attrs = {"type": kind, "size": nums((g.radius, g.length / 2.0))}
        elif isinstance(g, Mesh):
            if g.path is None:
                why = f": {g.problem.message}" if g.problem is not None else ""
                self.notes.append(f"{cls} mesh '{g.uri}' of body '{body.name}' left out{why}")
                return
            for asset in self.assets.assets(g.path, g.scale):
                self.add_geom(el, shape, cls, body, {"type": "mesh", "mesh": asset})
            return
        else:  # pragma: no cover - GeometryShape is closed
            return
        self.add_geom(el, shape, cls, body, attrs)

    def add_geom(
        self, el: etree._Element, shape: Shape, cls: str, body: Body, attrs: dict[str, str]
    ) -> None:
        """A geom of class ``cls``; a disabled body's collision geoms collide with nothing."""
        geom = etree.SubElement(el, "geom", {"class": cls, **attrs})
        place(geom, shape.origin)
        if cls == "visual" and shape.rgba is not None:
            geom.set("rgba", nums(shape.rgba))
        if cls == "collision" and body.name in self.disabled:
            geom.set("contype", "0")
            geom.set("conaffinity", "0")

    def camera(self, el: etree._Element, camera: Camera) -> None:
        """A ``<camera>`` at :func:`camera_frame` in the camera's body, with its fovy."""
        cam = etree.SubElement(el, "camera", name=camera.name)
        place(cam, camera_frame(camera))
        cam.set("fovy", num(math.degrees(camera.field_of_view.vertical_angle)))


def camera_frame(camera: Camera) -> F64:
    """The MuJoCo camera's pose in its body: looking along the forward axis (MuJoCo looks -z).

    Up is the body's +z, or -y when the camera looks along z (an optical frame, whose y
    points down), so an optical frame's image is the same picture in both. One function for
    the export and ``annotate mjcf``, so both put a spec's camera the same way.
    """
    forward = np.asarray(camera.forward_facing_axis, dtype=np.float64)
    forward = forward / np.linalg.norm(forward)
    z = -forward
    up = np.array([0.0, -1.0, 0.0]) if abs(forward[2]) > 0.9 else np.array([0.0, 0.0, 1.0])
    y = up - (up @ z) * z
    y = y / np.linalg.norm(y)
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack((np.cross(y, z), y, z))
    return pose
