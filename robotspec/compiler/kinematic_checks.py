"""Checks that need the robot's kinematics: camera heights, optical frames, immobile parts.

Named states in the wrong order are found the same way (FK of each state).

Why after the name checks: every check here evaluates forward kinematics over resolved bodies, so
it runs once the first pass has resolved them (a part whose names failed is skipped, its error is
already recorded). Policy: an error when FK proves the spec wrong (exact bounds, a configuration
that reaches a height, a state that is measurably higher), a warning when it is only suspicious.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from robotspec.arrays import F64
from robotspec.compiler.context import Build
from robotspec.compiler.heights import HeightRange, chain_fk_batch, height_range
from robotspec.compiler.parts import CameraValues
from robotspec.diagnostics import Loc
from robotspec.model.world import Body
from robotspec.spec.models import CameraSpec, FingerSpec, HandSpec, ParallelGripperSpec

__all__ = ["HEIGHT_TOL", "KinematicInputs", "check_kinematics"]


#: Heights (m) agree when they differ by less than this.
HEIGHT_TOL = 0.01
#: REP 103's optical frame in its body frame: z forward (body x), x right (-y), y down (-z).
OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
_ROT_TOL = 1e-3
#: Named states ordered by the height of the part's tip, and gripper states by their opening.
_HEIGHT_ORDER = ("low", "mid", "high")
_OPEN, _CLOSED = ("open", "opened"), ("close", "closed")


@dataclass(frozen=True)
class KinematicInputs:
    """What the first pass resolved, by part."""

    root: Body
    torso: tuple[Body, Body] | None = None
    neck: tuple[Body, Body] | None = None
    chains: Mapping[str, tuple[Body, Body]] = field(default_factory=dict)
    manipulators: Mapping[str, tuple[Body, Body]] = field(default_factory=dict)
    cameras: Mapping[str, CameraValues] = field(default_factory=dict)


def check_kinematics(b: Build, r: KinematicInputs) -> None:
    """Run every kinematic check, recording problems in ``b.diag``."""
    base = b.world.configuration()
    _immobile_parts(b, r)
    for name, values in r.cameras.items():
        spec = b.spec.sensors[name]
        assert isinstance(spec, CameraSpec)
        if not b.world.has_body(spec.body):
            continue
        body = b.world.get_body_by_name(spec.body)
        _optical(b, name, spec, body, values, base, r.root)
        _camera_heights(b, name, spec, body, values, base, r.root)
    _state_order(b, r, base)


# ------------------------------------------------------------------------ parts that cannot move


def _immobile_parts(b: Build, r: KinematicInputs) -> None:
    spec = b.spec
    parts: list[tuple[Loc, str, tuple[Body, Body], bool]] = []
    if r.torso is not None:
        parts.append((("torso",), "the torso", r.torso, True))
    if r.neck is not None:
        parts.append((("neck",), "the neck", r.neck, True))
    for name, ends in r.chains.items():
        c = spec.chains[name]
        arm = c.kind == "arm" or c.manipulator is not None
        parts.append((("chains", name), f"chain '{name}'", ends, arm))
    for name, m in spec.manipulators.items():
        fingers: list[tuple[Loc, str, FingerSpec]] = []
        if isinstance(m, ParallelGripperSpec):
            fingers = [(("manipulators", name, r), r, getattr(m, r)) for r in ("thumb", "finger")]
        elif isinstance(m, HandSpec):
            fingers = [(("manipulators", name, "thumb"), "thumb", m.thumb)]
            fingers += [
                (("manipulators", name, "fingers", k), f"finger '{k}'", f)
                for k, f in m.fingers.items()
            ]
        for floc, role, f in fingers:
            if b.world.has_body(f.root) and b.world.has_body(f.tip):
                ends = (b.world.get_body_by_name(f.root), b.world.get_body_by_name(f.tip))
                if ends[0].index != ends[1].index and b.world.is_ancestor(*ends):
                    parts.append((floc, f"{role} of '{name}'", ends, False))
    for loc, what, (root, tip), must_move in parts:
        if root.index == tip.index:
            continue
        conns = b.world.compute_chain_of_connections(root, tip)
        if not conns or any(not c.is_fixed for c in conns):
            continue
        names = ", ".join(f"'{c.name}'" for c in conns)
        message = (
            f"{what} cannot move: every joint from '{root.name}' to '{tip.name}' is fixed ({names})"
        )
        above = b.world.parent_connection(root)
        if above is not None and not above.is_fixed:
            parent = b.world.bodies[above.parent].name
            message += f"; '{above.name}' moves '{root.name}': start at '{parent}'?"
        if must_move:
            b.diag.error(loc, message, name=root.name)
        else:
            b.diag.warning(loc, message, name=root.name)


# ------------------------------------------------------------------------------ optical frames


def _rotation_in(b: Build, body: Body, ref: Body, base: F64) -> F64:
    conns = b.world.compute_chain_of_connections(ref, body)
    rot: F64 = chain_fk_batch(conns, base[None])[0, :3, :3]
    return rot


def _optical(
    b: Build,
    name: str,
    spec: CameraSpec,
    body: Body,
    values: CameraValues,
    base: F64,
    root: Body,
) -> None:
    """A frame whose rotation is REP 103's optical rotation looks along +z."""
    axis = np.asarray(values.forward_facing_axis)
    if np.linalg.norm(axis - (0.0, 0.0, 1.0)) <= 1e-6:
        return
    parent_conn = b.world.parent_connection(body)
    why = None
    if parent_conn is not None:
        parent = b.world.bodies[parent_conn.parent]
        if np.allclose(parent_conn.origin[:3, :3], OPTICAL, atol=_ROT_TOL):
            why = f"its rotation in '{parent.name}'"
    if why is None and b.world.is_ancestor(root, body):
        if np.allclose(_rotation_in(b, body, root, base), OPTICAL, atol=_ROT_TOL):
            why = f"its rotation in '{root.name}' at the zero configuration"
    if why is None:
        return
    looks = {
        (1, 0, 0): "to the robot's right",
        (-1, 0, 0): "to the robot's left",
        (0, 1, 0): "down",
        (0, -1, 0): "up",
        (0, 0, -1): "backwards",
    }.get(_rounded(axis), "away from the lens")
    if spec.body.endswith("_optical_frame"):
        # The name-based warning of the first pass already points here; the rotation proves it.
        b.diag.warnings[:] = [
            w
            for w in b.diag.warnings
            if w.detail.location != ("sensors", name, "forward_facing_axis")
        ]
    b.diag.error(
        ("sensors", name, "forward_facing_axis")
        if spec.forward_facing_axis is not None
        else ("sensors", name),
        f"'{spec.body}' is an optical frame by {why} (REP 103: z forward, x right, y down), so "
        f"the camera looks along +z; the axis {_vec(axis)} looks {looks}",
        name=spec.body,
    )


def _rounded(axis: F64) -> tuple[int, int, int]:
    x, y, z = (int(round(float(c))) for c in axis)
    return (x, y, z)


def _vec(v: object) -> str:
    return "[" + ", ".join(f"{float(x):g}" for x in np.asarray(v)) + "]"


# ------------------------------------------------------------------------------ camera heights


def _where(values: Mapping[str, float]) -> str:
    return ", ".join(f"{k}={v:.4g}" for k, v in values.items()) or "any configuration"


def _camera_heights(
    b: Build,
    name: str,
    spec: CameraSpec,
    body: Body,
    values: CameraValues,
    base: F64,
    root: Body,
) -> None:
    """The spec's height range against the range FK gives over the carrying joints' limits."""
    preset = b.presets.get(spec.preset or "", {})
    given = spec.minimal_height is not None or spec.maximal_height is not None
    if not given and "minimal_height" not in preset and "maximal_height" not in preset:
        return  # no heights claimed (the defaults 0-1 are placeholders)
    if not b.world.is_ancestor(root, body) and root.index != body.index:
        return
    fk = height_range(b.world, root, body, base)
    if fk is None:
        return
    lo, hi = values.minimal_height, values.maximal_height
    unreachable = lo < fk.low - HEIGHT_TOL or hi > fk.high + HEIGHT_TOL
    missed = lo > fk.low + HEIGHT_TOL or hi < fk.high - HEIGHT_TOL
    if not (unreachable or missed):
        return
    loc: Loc = ("sensors", name)
    if spec.minimal_height is not None:
        loc = (*loc, "minimal_height")
    elif spec.maximal_height is not None:
        loc = (*loc, "maximal_height")
    message = f"{_fk_text(fk, root)}; the spec says {lo:g}-{hi:g}"
    reasons = []
    if lo > fk.low + HEIGHT_TOL:
        reasons.append(f"it is at {fk.low:.3f} m at {_where(fk.lowest_at)}")
    if hi < fk.high - HEIGHT_TOL:
        reasons.append(f"it is at {fk.high:.3f} m at {_where(fk.highest_at)}")
    if lo < fk.low - HEIGHT_TOL or hi > fk.high + HEIGHT_TOL:
        reasons.append(
            "it never reaches the spec's "
            + " and ".join(
                w
                for w, bad in (
                    (f"{lo:g} m", lo < fk.low - HEIGHT_TOL),
                    (f"{hi:g} m", hi > fk.high + HEIGHT_TOL),
                )
                if bad
            )
            + ("" if fk.method != "sampled" else " in the samples")
        )
    if fk.method == "fixed":
        reasons = []  # the first sentence already says where it is
    detail = " (" + "; ".join(reasons) + ")" if reasons else ""
    message += f"{detail}; use {fk.low:.3f}-{fk.high:.3f}"
    if fk.method == "sampled" and not missed:
        b.diag.warning(loc, message, name=spec.body)
    else:
        b.diag.error(loc, message, name=spec.body)


def _fk_text(fk: HeightRange, root: Body) -> str:
    joints = ", ".join(f"'{j}'" for j in fk.joints)
    how = {
        "exact": "exact: lifts, pans and one last joint",
        "sampled": f"sampled: {fk.samples} configurations, refined joint by joint",
        "fixed": "no joint moves it",
    }[fk.method]
    if fk.method == "fixed":
        return f"FK puts '{fk.body}' at {fk.low:.3f} m above '{root.name}' ({how})"
    return (
        f"FK puts '{fk.body}' between {fk.low:.3f} and {fk.high:.3f} m above '{root.name}' over "
        f"the limits of {joints} ({how})"
    )


# --------------------------------------------------------------------------- named state order


def _state_config(b: Build, base: F64, values: Mapping[str, float]) -> F64 | None:
    q = base.copy()
    for joint, v in values.items():
        if not b.world.has_connection(joint):
            return None
        c = b.world.get_connection_by_name(joint)
        if c.type.dof_count != 1 or c.mimic is not None:
            return None
        q[c.dofs[0]] = v
    return q


def _state_order(b: Build, r: KinematicInputs, base: F64) -> None:
    spec = b.spec
    parts: list[tuple[Loc, str, Mapping[str, Mapping[str, float]], tuple[Body, Body]]] = []
    if spec.torso is not None and r.torso is not None:
        parts.append((("torso", "states"), "the torso", spec.torso.states, r.torso))
    if spec.neck is not None and r.neck is not None:
        parts.append((("neck", "states"), "the neck", spec.neck.states, r.neck))
    for name, ends in r.chains.items():
        parts.append(
            (("chains", name, "states"), f"chain '{name}'", spec.chains[name].states, ends)
        )
    for loc, what, states, (_, tip) in parts:
        named = [s for s in _HEIGHT_ORDER if s in states]
        if len(named) < 2 or not b.world.is_ancestor(r.root, tip):
            continue
        conns = b.world.compute_chain_of_connections(r.root, tip)
        heights: dict[str, float] = {}
        for s in named:
            q = _state_config(b, base, states[s])
            if q is not None:
                heights[s] = float(chain_fk_batch(conns, q[None])[0, 2, 3])
        _order(b, loc, what, f"the height of '{tip.name}'", heights, "m")
    for name, m in spec.manipulators.items():
        if not isinstance(m, ParallelGripperSpec) or name not in r.manipulators:
            continue
        w = b.world
        if not all(w.has_body(x) for x in (m.thumb.tip, m.finger.tip)):
            continue
        mroot = r.manipulators[name][0]
        tips = [w.get_body_by_name(m.thumb.tip), w.get_body_by_name(m.finger.tip)]
        if not all(w.is_ancestor(mroot, t) for t in tips):
            continue
        chains = [w.compute_chain_of_connections(mroot, t) for t in tips]
        opening: dict[str, float] = {}
        for aliases in (_CLOSED, _OPEN):
            state = next((a for a in aliases if a in m.states), None)
            q = None if state is None else _state_config(b, base, m.states[state])
            if state is not None and q is not None:
                p = [chain_fk_batch(c, q[None])[0, :3, 3] for c in chains]
                opening[state] = float(np.linalg.norm(p[0] - p[1]))
        _order(
            b,
            ("manipulators", name, "states"),
            f"manipulator '{name}'",
            f"the distance between '{m.thumb.tip}' and '{m.finger.tip}'",
            opening,
            "m",
        )


def _order(
    b: Build, loc: Loc, what: str, measure: str, values: Mapping[str, float], unit: str
) -> None:
    """States given in increasing order must give increasing values (ties: a warning)."""
    items = list(values.items())
    for (s1, v1), (s2, v2) in zip(items, items[1:], strict=False):
        text = (
            f"state '{s2}' of {what} gives {measure} {v2:.3f} {unit}, state '{s1}' {v1:.3f} {unit}"
        )
        if v2 < v1 - 1e-6:
            b.diag.error(
                (*loc, s2), f"{text}: '{s2}' must give more than '{s1}' (swapped?)", name=s2
            )
        elif v2 <= v1 + 1e-6:
            b.diag.warning((*loc, s2), f"{text}: the two states give the same value", name=s2)
