"""A spec's semantics on a user's own MJCF: tool sites, cameras, keyframes, excluded pairs.

Why not ``robotspec export mjcf``: a robot-learning user already has a tuned model (Menagerie's,
robosuite's, or one MuJoCo compiled from the URDF, which drops the fixed tool frames) and wants
the spec's meaning on it, not a replacement. So their model is read with MuJoCo's ``MjSpec``,
matched to the compiled robot (:mod:`robotspec.interop.mujoco_matcher`), the match proved by
forward kinematics at random configurations (:mod:`robotspec.interop.mujoco_fit`: every
matched body is the same rigid body up to a constant re-framing), and only then are elements
added. Each site is placed from both models' kinematics, so the tool frame lands where the spec
says whatever their body frames are, and is checked again on the compiled result (1e-6 m).
Nothing of theirs is changed: a name already taken gets a ``_robotspec`` suffix and a note.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.errors import RobotSpecError
from robotspec.export.mjcf import named_states
from robotspec.export.mjcf_bodies import camera_frame
from robotspec.interop.mujoco_fit import TOLERANCE, FrameFit, fit_frames, inverse
from robotspec.interop.mujoco_matcher import Matcher
from robotspec.interop.mujoco_model import TheirModel, read_model
from robotspec.interop.mujoco_names import NameMatch
from robotspec.semantic import AbstractRobot

__all__ = ["Annotation", "Placed", "annotate_mjcf"]


@dataclass(frozen=True)
class Placed:
    """A site or camera added: its name, their body it sits on, and what it stands for."""

    name: str
    body: str
    of: str


@dataclass(frozen=True)
class Annotation:
    """The annotated MJCF and what was matched, added and measured.

    ``site_error`` is the largest misfit (distance in m, or angle in rad) between an added
    site or camera of the compiled result and where robotspec's kinematics puts it (tool
    frame, camera frame), over the verification configurations; ``body_error`` the largest
    misfit of a matched body (m or rad) once the constant offsets are taken out.
    """

    xml: str
    joints: NameMatch
    bodies: NameMatch
    root: tuple[str, str]
    sites: tuple[Placed, ...]
    cameras: tuple[Placed, ...]
    keys: tuple[str, ...]
    excludes: tuple[tuple[str, str], ...]
    site_error: float
    body_error: float
    notes: tuple[str, ...]
    #: Measure ``site_error`` again on the written file, read back by MuJoCo (m).
    check_file: Callable[[Path], float] = field(repr=False, compare=False)


def annotate_mjcf(
    robot: AbstractRobot,
    model: Path,
    *,
    mapping: Mapping[str, str] | None = None,
    excludes: bool = False,
    output: Path | None = None,
    samples: int = 8,
    seed: int = 0,
    tolerance: float = TOLERANCE,
) -> Annotation:
    """Add ``robot``'s tool sites, cameras, named states (and excluded pairs) to ``model``.

    ``mapping`` is ``{their name: our name}`` for what names cannot match; ``output`` the file
    the result will be written to (mesh folders are re-pointed when it is in another folder).
    ``tolerance`` (m, and rad): how far a matched body may stray from a rigid re-framing of
    ours, and a site from its tool frame; a hand-rounded model (robosuite's ``0.924``
    quaternion) needs a looser one than the default 1e-6.
    Raises a RobotSpecError naming the unmatched joint with its closest names, a joint turning
    the other way, or MuJoCo's own complaint about the model.
    """
    their = read_model(model)
    if not (math.isfinite(tolerance) and tolerance > 0.0):
        raise RobotSpecError(
            f"the tolerance must be a positive number of metres, not {tolerance}",
            kind="option",
            name="--tolerance",
        )
    a = Matcher(robot, their, mapping or {}, tolerance)
    qs = a.configurations(samples, seed)
    fit = fit_frames(*a.relative(qs, [their.body_poses(a.qpos(q)) for q in qs]), tolerance)
    if fit.failing(tolerance):
        raise a.diagnose(fit, qs)
    sites, cameras, targets = _place_frames(robot, their, a, fit, qs[0])
    keys = _add_keys(robot, their, a)
    added = _add_excludes(robot, their, a) if excludes else []

    def measure(model: Any = None) -> float:
        root = a.pairs[a.root]
        return their.site_error(targets, qs, a.qpos, robot, a.root, root, fit, model)

    site_error = measure()
    if site_error > tolerance:
        raise RobotSpecError(  # pragma: no cover - the fit proved it; a bug if it fails
            f"a site or camera added to {their.shown} is {site_error:.3g} m/rad from its frame",
            file=their.shown,
            kind="site",
        )
    xml = their.to_xml(output, a.notes)

    def check_file(path: Path) -> float:
        """The site error measured on the written file, read back by MuJoCo."""
        return measure(read_model(path).model)

    return Annotation(
        xml=xml,
        joints=a.joints,
        bodies=a.bodies,
        root=(robot.world.bodies[a.root].name, a.pairs[a.root]),
        sites=tuple(sites),
        cameras=tuple(cameras),
        keys=tuple(keys),
        excludes=tuple(added),
        site_error=site_error,
        body_error=fit.worst,
        notes=tuple(a.notes),
        check_file=check_file,
    )


def _add_keys(robot: AbstractRobot, their: TheirModel, a: Matcher) -> list[str]:
    """One keyframe per named state of the robot, over the joints the state names."""
    keys = []
    for key, state in named_states(robot).items():
        values = state.as_dict()
        dofs = {robot.world.get_degree_of_freedom_by_name(n).index for n in values}
        qpos = a.qpos(robot.world.configuration(values), only=dofs)
        keys.append(their.add_key(key, qpos, a.notes))
    return keys


def _add_excludes(robot: AbstractRobot, their: TheirModel, a: Matcher) -> list[tuple[str, str]]:
    """The robot's disabled pairs as ``<exclude>`` of their bodies (those they have)."""
    added: list[tuple[str, str]] = []
    for pair in sorted(tuple(sorted(p)) for p in robot.disabled_collision_pairs if len(p) == 2):
        try:
            ends = [a.pairs[a.owner(robot.world.get_body_by_name(n).index, n)] for n in pair]
        except RobotSpecError:
            continue  # a body below an unmatched joint: their model has no such body
        if their.add_exclude(ends[0], ends[1]):
            added.append((ends[0], ends[1]))
    return added


def _place_frames(
    robot: AbstractRobot, their: TheirModel, a: Matcher, fit: FrameFit, q0: F64
) -> tuple[list[Placed], list[Placed], list[tuple[str, str, int, F64]]]:
    """A site at each tool frame and a camera at each camera, in their bodies that hold ours.

    Returns the sites, the cameras, and what each must match (kind, their name, our body,
    the frame in our body) for the site error.
    """
    fk0 = robot.kinematics.forward(q0)
    root_inv = inverse(fk0[a.root])

    def local(body: int, frame: F64) -> tuple[str, F64]:
        """``frame`` (world pose at q0) in their body that rigidly holds ``body``."""
        b = a.owner(body, f"'{robot.world.bodies[body].name}'")
        key = robot.world.bodies[b].name
        return a.pairs[b], inverse(fit.offsets[key]) @ inverse(root_inv @ fk0[b]) @ (
            root_inv @ frame
        )

    sites: list[Placed] = []
    targets: list[tuple[str, str, int, F64]] = []
    for m in robot.manipulators:
        tool = m.tool_frame
        body, pose = local(tool.index, fk0[tool.index])
        name = their.add_site(tool.name, body, pose, a.notes)
        sites.append(Placed(name, body, tool.name))
        targets.append(("site", name, tool.index, np.eye(4)))
    cameras: list[Placed] = []
    for cam in robot.cameras:
        frame = fk0[cam.root.index] @ camera_frame(cam)
        body, pose = local(cam.root.index, frame)
        fovy = math.degrees(cam.field_of_view.vertical_angle)
        name = their.add_camera(cam.name, body, pose, fovy, a.notes)
        cameras.append(Placed(name, body, cam.name))
        targets.append(("camera", name, cam.root.index, camera_frame(cam)))
    return sites, cameras, targets
