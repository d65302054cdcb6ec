"""Their MJCF matched to the compiled robot: joints and bodies paired, the pairing proved.

Why apart from :mod:`robotspec.interop.mujoco_annotate`: this is the judgement (which of their
joints and bodies is which of ours, which must be matched, the root, the configurations to
compare at, and which joint to blame when a body does not fit); the annotation only places
elements once the match holds.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from robotspec.arrays import F64
from robotspec.errors import RobotSpecError, raise_collected
from robotspec.export.mjcf import named_states
from robotspec.interop.mujoco_fit import TOLERANCE, FrameFit, fit_frames, inverse
from robotspec.interop.mujoco_model import TheirModel
from robotspec.interop.mujoco_names import (
    best_prefixes,
    check_map,
    match_names,
    unmatched_error,
)
from robotspec.model.entities import ConnectionType
from robotspec.semantic import AbstractRobot

__all__ = ["Matcher"]

_MOVING = {ConnectionType.REVOLUTE, ConnectionType.CONTINUOUS, ConnectionType.PRISMATIC}


class Matcher:
    """One annotation: the robot, their model, the matches and the proved offsets."""

    def __init__(
        self,
        robot: AbstractRobot,
        their: TheirModel,
        mapping: Mapping[str, str],
        tolerance: float = TOLERANCE,
    ):
        self.tolerance = tolerance
        self.robot, self.world, self.their = robot, robot.world, their
        self.notes: list[str] = []
        our_joints = [c.name for c in self.world.connections if c.type in _MOVING]
        our_bodies = [b.name for b in self.world.bodies]
        joint_map, body_map = check_map(
            mapping, their.joints, their.bodies, our_joints, our_bodies, their.shown
        )
        self.prefixes = best_prefixes([*their.joints, *their.bodies], [*our_joints, *our_bodies])
        self.joints = match_names("joint", their.joints, our_joints, joint_map, self.prefixes)
        self.bodies = match_names("body", their.bodies, our_bodies, body_map, self.prefixes)
        self._require_joints()
        self.pairs = self._body_pairs()  # our body index -> their body name
        depth = {i: len(self._ancestors(i)) for i in self.pairs}
        self.root = min(self.pairs, key=lambda i: (depth[i], i))

    # ------------------------------------------------------------------ matching
    def _require_joints(self) -> None:
        """Every joint of a chain or a named state must be matched; all misses reported."""
        theirs = self.joints.theirs_of()
        needed: dict[str, str] = {}
        for chain in self.robot.all_chains:
            for c in chain.active_connections:
                needed.setdefault(c.name, f"of chain '{chain.name}'")
        for key, state in named_states(self.robot).items():
            for name in state.as_dict():
                needed.setdefault(name, f"of state '{key}'")
        matched = self.joints.ours_of()
        free = [j for j in self.their.joints if j not in matched]
        errors = [
            unmatched_error(
                "joint", n, role, self.their.joints, free, self.prefixes, self.their.shown
            )
            for n, role in needed.items()
            if n not in theirs
        ]
        raise_collected(errors, summary=f"{len(errors)} joints of the spec unmatched")
        for m in self.joints.pairs:
            c = self.world.get_connection_by_name(m.ours)
            kind = self.their.joint_kind[m.theirs]
            want = "slide" if c.type is ConnectionType.PRISMATIC else "hinge"
            if kind != want:
                raise RobotSpecError(
                    f"joint '{m.theirs}' of {self.their.shown} is a {kind} joint but the robot's "
                    f"'{m.ours}' is {c.type.value} (a {want} in MJCF)",
                    file=self.their.shown,
                    kind="joint",
                    name=m.theirs,
                )

    def _body_pairs(self) -> dict[int, str]:
        """Our body to theirs: each matched joint's child, then names, then joints' parents."""
        pairs: dict[int, str] = {}
        parents: dict[int, str] = {}
        for m in self.joints.pairs:
            c = self.world.get_connection_by_name(m.ours)
            pairs[c.child] = self.their.joint_body[m.theirs]
            parents.setdefault(c.parent, self.their.body_parent[self.their.joint_body[m.theirs]])
        for m in self.bodies.pairs:
            b = self.world.get_body_by_name(m.ours).index
            if b in pairs and pairs[b] != m.theirs:
                self.notes.append(
                    f"body '{m.theirs}' has the name of '{m.ours}' but '{pairs[b]}' holds its "
                    "joint: the joint decides"
                )
                continue
            pairs[b] = m.theirs
        for b, name in parents.items():
            pairs.setdefault(b, name)
        return {b: name for b, name in pairs.items() if name}

    def _ancestors(self, body: int) -> list[int]:
        out = []
        c = self.world.parent_connection(self.world.bodies[body])
        while c is not None:
            out.append(c.parent)
            c = self.world.parent_connection(self.world.bodies[c.parent])
        return out

    def owner(self, body: int, what: str) -> int:
        """The nearest matched body rigidly holding ``body`` (itself first)."""
        b = body
        while b not in self.pairs:
            c = self.world.parent_connection(self.world.bodies[b])
            if c is None:
                break
            if not c.is_fixed:
                raise RobotSpecError(
                    f"{what} hangs below joint '{c.name}', which no joint of "
                    f"{self.their.shown} matches (add --map THEIRS={c.name})",
                    file=self.their.shown,
                    kind="joint",
                    name=c.name,
                )
            b = c.parent
        if b not in self.pairs:
            raise RobotSpecError(
                f"{what}: no body above it matches one of {self.their.shown}",
                file=self.their.shown,
                kind="body",
                name=self.world.bodies[body].name,
            )
        return b

    # ------------------------------------------------------------------ kinematics
    def qpos(self, q: F64, only: set[int] | None = None) -> F64:
        """Their ``qpos`` for our configuration: matched joints set, the others at qpos0.

        ``only``: set just the joints driven by these DOFs (a named state's), the rest at qpos0.
        """
        out = np.array(self.their.qpos0, dtype=np.float64)
        for m in self.joints.pairs:
            c = self.world.get_connection_by_name(m.ours)
            if only is not None and c.dofs[0] not in only:
                continue
            value = float(q[c.dofs[0]])
            if c.mimic is not None:
                value = c.mimic.multiplier * value + c.mimic.offset
            out[self.their.joint_qpos[m.theirs]] = value
        return out

    def configurations(self, n: int, seed: int) -> list[F64]:
        """The default configuration, then ``n`` random ones over the matched joints' DOFs."""
        rng = np.random.default_rng(seed)
        dofs = sorted(
            {self.world.get_connection_by_name(m.ours).dofs[0] for m in self.joints.pairs}
        )
        out = [self.world.default_configuration()]
        for _ in range(n):
            q = out[0].copy()
            for d in dofs:
                dof = self.world.degrees_of_freedom[d]
                lo = dof.lower if math.isfinite(dof.lower) else -math.pi
                hi = dof.upper if math.isfinite(dof.upper) else math.pi
                q[d] = rng.uniform(lo, hi)
            out.append(q)
        return out

    def relative(
        self, qs: list[F64], poses: list[dict[str, F64]]
    ) -> tuple[dict[str, list[F64]], dict[str, list[F64]]]:
        """Per matched body, our and their poses relative to the root, at each configuration."""
        ours: dict[str, list[F64]] = {}
        theirs: dict[str, list[F64]] = {}
        root = self.pairs[self.root]
        for q, their_poses in zip(qs, poses, strict=True):
            fk = self.robot.kinematics.forward(q)
            back_o, back_t = inverse(fk[self.root]), inverse(their_poses[root])
            for b, name in self.pairs.items():
                key = self.world.bodies[b].name
                ours.setdefault(key, []).append(back_o @ fk[b])
                theirs.setdefault(key, []).append(back_t @ their_poses[name])
        return ours, theirs

    def diagnose(self, fit: FrameFit, qs: list[F64]) -> RobotSpecError:
        """Name the joint that makes the first failing body (nearest the root) misfit."""
        bad = fit.failing(self.tolerance)
        index = {self.world.bodies[b].name: b for b in self.pairs}
        first = min(bad, key=lambda k: (len(self._ancestors(index[k])), index[k]))
        body = index[first]
        above = [self.world.parent_connection(self.world.bodies[body])]
        above += [self.world.parent_connection(self.world.bodies[a]) for a in self._ancestors(body)]
        theirs = self.joints.theirs_of()
        chain = [c for c in above if c is not None and c.name in theirs]
        err = fit.errors[first]
        for c in chain:  # nearest the body first: does flipping it make the body fit?
            flipped = self._flip(c.name, qs)
            if flipped.errors.get(first, math.inf) <= self.tolerance:
                return RobotSpecError(
                    f"joint '{theirs[c.name]}' of {self.their.shown} turns the opposite way to "
                    f"the robot's '{c.name}' (body '{self.pairs[body]}' off by {err:.3g} m/rad; "
                    "flipped, it fits): refused, the spec's states would be mirrored",
                    file=self.their.shown,
                    kind="joint",
                    name=theirs[c.name],
                )
        names = ", ".join(f"'{theirs[c.name]}'" for c in chain[:2]) or "none matched"
        return RobotSpecError(
            f"body '{self.pairs[body]}' of {self.their.shown} does not move as the robot's "
            f"'{first}' (off by {err:.3g} m/rad at some configuration): a joint above it has "
            f"another zero, axis or origin (nearest: {names}); check --map",
            file=self.their.shown,
            kind="body",
            name=self.pairs[body],
        )

    def _flip(self, joint: str, qs: list[F64]) -> FrameFit:
        their = self.joints.theirs_of()[joint]
        adr = self.their.joint_qpos[their]
        poses = []
        for q in qs:
            qpos = self.qpos(q)
            qpos[adr] = -qpos[adr]
            poses.append(self.their.body_poses(qpos))
        return fit_frames(*self.relative(qs, poses), self.tolerance)
