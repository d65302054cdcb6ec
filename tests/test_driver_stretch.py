"""Trajectories within the acceleration limits: the curve through the waypoints' velocities, slowed
just enough where it would exceed a joint's velocity or acceleration limit (issue 24, item 6).

The property tests draw random feasible waypoint sets (random limits, 1 to 7 joints, gaps up to
100 ms, a speed ratio, velocities none, planner-like or random, on every waypoint or some) and
check the curve the driver samples (:meth:`TrajectoryInterpolator.evaluate`), densely:

* its acceleration (second divided differences) and velocity never exceed the limits;
* it passes through every waypoint at its (possibly stretched) time, which is never earlier than
  planned;
* its velocity at every waypoint is the given one (times the speed ratio) scaled by that
  waypoint's one speed scale, from both sides (C1), and each segment lasts its planned duration
  over the mean speed scale of its ends;
* it is stretched exactly when the planned curve exceeds a limit (computed exactly here), and an
  unstretched trajectory without velocities is the PCHIP curve of before, bit for bit.

Tolerances are for floating-point round-off only.
"""

from __future__ import annotations

import bisect
import json
import math
from pathlib import Path
from unittest.mock import patch

import numpy as np
import pytest
from hypothesis import assume, event, given, settings
from hypothesis import strategies as st

from robotspec.arrays import F64
from robotspec.driver import stretch as stretch_module
from robotspec.driver.clock import SimClock
from robotspec.driver.commands import JointLimitArrays
from robotspec.driver.errors import InvalidArgumentError
from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.script import load_scenario, run_scenario
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import ActionStatus, CommandMode
from robotspec.driver.statelog import StateLog
from robotspec.driver.stretch import LIMIT_TOLERANCE
from robotspec.driver.trajectory import (
    JointTrajectory,
    TrajectoryInterpolator,
    Waypoint,
    load_trajectory,
)
from tests.driver_support import RRP, make_sim

#: Round-off allowance, relative to a limit.
REL = 1e-6


def limits_of(lower: F64, upper: F64, velocity: F64, acceleration: F64) -> JointLimitArrays:
    """Joint limits from arrays (no RobotInfo needed)."""
    n = lower.shape[0]
    return JointLimitArrays(
        lower=lower,
        upper=upper,
        velocity=velocity,
        acceleration=acceleration,
        reduced_velocity=velocity,
        reduced_acceleration=acceleration,
        home=np.zeros(n),
        prismatic=np.zeros(n, dtype=bool),
    )


@st.composite
def waypoint_sets(
    draw: st.DrawFn, velocities: str | None = None, gentle: bool = False
) -> tuple[JointLimitArrays, JointTrajectory, float, F64 | None]:
    """Limits, a trajectory feasible for the load checks, its speed ratio and its velocities.

    ``velocities``: ``"none"``, ``"planner"`` (finite differences of the positions, as a smooth
    reference gives), ``"random"``; None draws one. ``gentle``: slow changes, mostly unstretched.
    """
    n = draw(st.integers(1, 7))
    floats = st.floats
    vmax = np.array(draw(st.lists(floats(0.2, 3.0), min_size=n, max_size=n)))
    # Gentle: slow changes on stiff joints, so most are unstretched.
    gain = floats(50.0, 200.0) if gentle else floats(1.0, 10.0)
    amax = vmax * np.array(draw(st.lists(gain, min_size=n, max_size=n)))
    lower = -np.array(draw(st.lists(floats(0.5, 3.0), min_size=n, max_size=n)))
    upper = np.array(draw(st.lists(floats(0.5, 3.0), min_size=n, max_size=n)))
    limits = limits_of(lower, upper, vmax, amax)
    m = draw(st.integers(5, 14))
    gaps = np.array(draw(st.lists(floats(0.01, 0.1), min_size=m - 1, max_size=m - 1)))
    ratio = draw(st.sampled_from([1.0, 0.5, 2.0]))
    times = np.concatenate([[0.0], np.cumsum(gaps)])
    span = upper - lower
    inner_lo, inner_hi = lower + 0.2 * span, upper - 0.2 * span
    q = inner_lo + np.array(draw(st.lists(floats(0, 1), min_size=n, max_size=n))) * 0.6 * span
    rows = [q]
    speed = 0.05 if gentle else 0.9
    for i in range(m - 1):
        w = np.array(draw(st.lists(floats(-1, 1), min_size=n, max_size=n)))
        if gentle:  # rest to rest, slowly changing
            w *= np.sin(np.pi * (i + 0.5) / (m - 1)) ** 2
        q = np.clip(q + w * speed * vmax * gaps[i] / ratio, inner_lo, inner_hi)
        rows.append(q)
    pos = np.array(rows)
    kind = velocities or draw(st.sampled_from(["none", "planner", "random"]))
    vel = None
    if kind != "none":
        if kind == "planner":
            vel = np.gradient(pos, times, axis=0)
        else:
            vel = np.array(draw(st.lists(floats(-1, 1), min_size=m * n, max_size=m * n))).reshape(
                m, n
            )
            vel *= vmax
        vel = np.clip(vel, -0.9 * vmax / ratio, 0.9 * vmax / ratio)
        some = draw(st.booleans())
        if some:
            keep = np.array(draw(st.lists(st.booleans(), min_size=m, max_size=m)))
            vel[~keep] = np.nan
    wps = tuple(
        Waypoint(
            joint_position=tuple(pos[i].tolist()),
            time_from_start=float(times[i]),
            joint_velocity=() if vel is None or np.isnan(vel[i, 0]) else tuple(vel[i].tolist()),
        )
        for i in range(m)
    )
    return limits, JointTrajectory(waypoints=wps), ratio, vel


def names(limits: JointLimitArrays) -> tuple[str, ...]:
    return tuple(f"j{i}" for i in range(limits.count))


def samples(interp: TrajectoryInterpolator, per_segment: int = 12) -> tuple[F64, F64]:
    """Times and positions of the executed curve, ``per_segment`` per segment and the end."""
    t = interp.times
    s = np.linspace(0.0, 1.0, per_segment, endpoint=False)
    ts = np.concatenate([(t[:-1, None] + s[None, :] * np.diff(t)[:, None]).ravel(), t[-1:]])
    return ts, np.array([interp.evaluate(float(x))[0] for x in ts])


def exact_peaks(times: F64, pos: F64, vel: F64, limits: JointLimitArrays) -> float:
    """The planned curve's largest acceleration or velocity over its limit, computed exactly.

    Independent of the driver's code: the Hermite cubic's acceleration at both ends of each
    segment, its velocity at the ends and at the vertex.
    """
    worst = 0.0
    for i in range(times.shape[0] - 1):
        h = times[i + 1] - times[i]
        dq = pos[i + 1] - pos[i]
        m0, m1 = vel[i] * h, vel[i + 1] * h
        a0 = (6 * dq - 4 * m0 - 2 * m1) / h**2
        a1 = (-6 * dq + 2 * m0 + 4 * m1) / h**2
        worst = max(worst, float(np.max(np.maximum(abs(a0), abs(a1)) / limits.acceleration)))
        for s in np.linspace(0, 1, 201):  # velocity: a quadratic, sampled finely
            v = (6 * (s - s * s) * dq + m0 * (3 * s * s - 4 * s + 1) + m1 * (3 * s * s - 2 * s)) / h
            worst = max(worst, float(np.max(np.abs(v) / limits.velocity)))
    return worst


def check_curve(
    interp: TrajectoryInterpolator,
    limits: JointLimitArrays,
    ratio: float,
    vel: F64 | None,
) -> None:
    """Every property of the executed curve the module docstring lists."""
    amax, vmax = limits.acceleration, limits.velocity
    ts, q = samples(interp)
    d1 = np.diff(q, axis=0) / np.diff(ts)[:, None]
    d2 = 2 * np.diff(d1, axis=0) / (ts[2:] - ts[:-2])[:, None]
    assert np.all(np.abs(d2) <= amax * (1 + REL) + 1e-6), np.max(np.abs(d2) / amax)
    assert np.all(np.abs(d1) <= vmax * (1 + REL)), np.max(np.abs(d1) / vmax)
    assert np.all(q >= limits.lower - 1e-9) and np.all(q <= limits.upper + 1e-9)
    # Through every waypoint at its time; never earlier than planned.
    t, planned = interp.times, interp.planned_times
    for j in range(interp.n_waypoints):
        assert np.array_equal(interp.evaluate(float(t[j]))[0], interp.positions[j])
    assert np.all(np.diff(t) >= np.diff(planned) * (1 - 1e-12))
    # The planner's velocities at the waypoints, one speed scale per waypoint.
    sigma = np.ones(interp.n_waypoints) if interp.speed_scale is None else interp.speed_scale
    assert np.all((sigma > 0) & (sigma <= 1))
    assert np.allclose(np.diff(t), 2 * np.diff(planned) / (sigma[:-1] + sigma[1:]), rtol=1e-12)
    v = interp.velocities
    assert np.all(v[0] == 0) and np.all(v[-1] == 0)
    if vel is not None:
        for j in range(1, interp.n_waypoints - 1):
            if not np.isnan(vel[j, 0]):
                assert np.allclose(v[j], vel[j] * ratio * sigma[j], rtol=1e-12, atol=1e-15)
    # ... from both sides (C1).
    delta = 1e-7 * float(np.min(np.diff(t)))
    for j in range(1, interp.n_waypoints - 1):
        tj = float(t[j])
        right = (interp.evaluate(tj + delta)[0] - interp.positions[j]) / delta
        left = (interp.positions[j] - interp.evaluate(tj - delta)[0]) / delta
        # The one-sided difference quotient carries the positions' rounding over delta: two
        # positions near 2.2 rad, each within an ulp, differ by ~4e-16 more or less than exact.
        rounding = (
            4 * np.finfo(float).eps * max(1.0, float(np.max(np.abs(interp.positions)))) / delta
        )
        tol = amax * delta + 1e-6 * vmax + rounding
        assert np.all(np.abs(right - v[j]) <= tol) and np.all(np.abs(left - v[j]) <= tol)
    # Stretched exactly when the planned curve exceeds a limit.
    planned_v = v / sigma[:, None]
    over = exact_peaks(planned, interp.positions, planned_v, limits)
    if interp.stretch is None:
        assert over <= 1 + 2 * LIMIT_TOLERANCE
        assert interp.segment_stretch is None and t is planned
    else:
        assert over > 1 + 0.5 * LIMIT_TOLERANCE
        st_ = interp.stretch
        assert interp.segment_stretch is not None
        assert st_.factor == pytest.approx(float(np.max(interp.segment_stretch))) and st_.factor > 1
        assert st_.duration == t[-1] and st_.planned_duration == planned[-1]
        assert st_.segments == int(np.sum(interp.segment_stretch > 1 + 1e-12)) >= 1


@settings(max_examples=60, deadline=None)
@given(case=waypoint_sets())
def test_curve_stays_within_the_limits_through_the_waypoints(
    case: tuple[JointLimitArrays, JointTrajectory, float, F64 | None],
) -> None:
    limits, traj, ratio, vel = case
    try:
        interp = load_trajectory(traj, names(limits), limits, ratio)
    except InvalidArgumentError as exc:  # only a curve that leaves the position limits
        assert vel is not None and "leaves joint" in str(exc)
        event("refused: off the position limits")
        return
    event("stretched" if interp.stretch is not None else "as planned")
    check_curve(interp, limits, ratio, vel)


@settings(max_examples=40, deadline=None)
@given(case=waypoint_sets(velocities="planner"))
def test_planner_velocities_are_honoured(
    case: tuple[JointLimitArrays, JointTrajectory, float, F64 | None],
) -> None:
    limits, traj, ratio, vel = case
    interp = load_trajectory(traj, names(limits), limits, ratio)  # never refused
    event("stretched" if interp.stretch is not None else "as planned")
    check_curve(interp, limits, ratio, vel)


@settings(max_examples=25, deadline=None)
@given(case=waypoint_sets())
def test_the_fallback_for_the_whole_trajectory_is_within_the_limits_too(
    case: tuple[JointLimitArrays, JointTrajectory, float, F64 | None],
) -> None:
    # Ramps that do not settle within MAX_ROUNDS: one factor for the whole trajectory.
    limits, traj, ratio, vel = case
    with patch.object(stretch_module, "MAX_ROUNDS", 0):
        try:
            interp = load_trajectory(traj, names(limits), limits, ratio)
        except InvalidArgumentError:
            return
    if interp.speed_scale is not None:
        assert np.all(interp.speed_scale == interp.speed_scale[0])
    check_curve(interp, limits, ratio, vel)


class _PchipBefore:
    """The driver's interpolation before velocities were honoured (robotspec 0.x, verbatim).

    The oracle of "an unstretched trajectory runs exactly as before".
    """

    def __init__(self, times: F64, positions: F64) -> None:
        self.times = times
        self.positions = positions
        self.max_time = float(times[-1])
        self.n_waypoints = int(times.shape[0])
        h = np.diff(times)
        delta = np.diff(positions, axis=0) / h[:, None]
        d = np.zeros_like(positions)
        if positions.shape[0] > 2:
            h0 = h[:-1, None]
            h1 = h[1:, None]
            w1 = 2.0 * h1 + h0
            w2 = h1 + 2.0 * h0
            d0, d1 = delta[:-1], delta[1:]
            same = d0 * d1 > 0.0
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                hm = (w1 + w2) / (w1 / d0 + w2 / d1)
            d[1:-1] = np.where(same & np.isfinite(hm), hm, 0.0)
        self._slopes = d
        self._times_l: list[float] = times.tolist()
        self._h_l: list[float] = h.tolist()

    def evaluate(self, t: float) -> tuple[F64, int]:
        if t >= self.max_time:
            return self.positions[-1].copy(), self.n_waypoints - 1
        if t <= 0.0:
            return self.positions[0].copy(), 0
        k = bisect.bisect_right(self._times_l, t) - 1
        h = self._h_l[k]
        s = (t - self._times_l[k]) / h
        s2 = s * s
        s3 = s2 * s
        h00 = 2 * s3 - 3 * s2 + 1
        h10 = s3 - 2 * s2 + s
        h01 = -2 * s3 + 3 * s2
        h11 = s3 - s2
        hh10 = h10 * h
        hh11 = h11 * h
        p0, p1 = self.positions[k].tolist(), self.positions[k + 1].tolist()
        m0, m1 = self._slopes[k].tolist(), self._slopes[k + 1].tolist()
        out = [p0[i] * h00 + (hh10 * m0[i] + h01 * p1[i] + hh11 * m1[i]) for i in range(len(p0))]
        return np.array(out), k


@settings(max_examples=40, deadline=None)
@given(case=waypoint_sets(velocities="none", gentle=True), frac=st.floats(0.0, 1.0))
def test_an_unstretched_trajectory_runs_exactly_as_before(
    case: tuple[JointLimitArrays, JointTrajectory, float, F64 | None], frac: float
) -> None:
    limits, traj, ratio, _ = case
    interp = load_trajectory(traj, names(limits), limits, ratio)
    assume(interp.stretch is None)
    before = _PchipBefore(interp.times, interp.positions)
    ts, q = samples(interp, per_segment=7)
    for x in [*ts.tolist(), frac * interp.max_time, -1.0, interp.max_time + 1.0]:
        now, k = interp.evaluate(x)
        then, k_before = before.evaluate(x)
        assert np.array_equal(now, then) and k == k_before


def test_ends_are_at_rest_whatever_their_velocities() -> None:
    # np.gradient gives the first and last waypoints a velocity: the curve still starts and ends
    # at rest (the arm starts from rest; the driver holds the end), slowed into the end.
    limits = limits_of(np.array([-2.0]), np.array([2.0]), np.array([1.0]), np.array([4.0]))
    t = np.linspace(0, 1.0, 11)
    q = 0.5 * t
    v = np.full_like(t, 0.5)
    wps = tuple(Waypoint((float(q[i]),), float(t[i]), (float(v[i]),)) for i in range(11))
    interp = load_trajectory(JointTrajectory(waypoints=wps), ("j0",), limits, 1.0)
    assert interp.velocities[0, 0] == 0.0 and interp.velocities[-1, 0] == 0.0
    assert interp.stretch is not None  # 0.5 rad/s to rest in 0.1 s needs more than 4 rad/s²
    assert interp.stretch.first_segment == 0 and interp.stretch.last_segment == 9
    check_curve(interp, limits, 1.0, v[:, None])


def test_a_curve_off_the_position_limits_is_refused_with_its_waypoint() -> None:
    limits = limits_of(np.array([-1.0]), np.array([1.0]), np.array([5.0]), np.array([500.0]))
    q = [0.0, 0.3, 0.6, 0.95, 0.95]
    v = [0.0, 3.0, 3.0, 4.9, 0.0]  # at 0.95 with 4.9 rad/s: up to 1.02 before waypoint 4
    wps = tuple(Waypoint((q[i],), 0.1 * i, (v[i],)) for i in range(5))
    with pytest.raises(InvalidArgumentError, match="Waypoint 4: the curve through the given"):
        load_trajectory(JointTrajectory(waypoints=wps), ("j0",), limits, 1.0)


# ------------------------------------------------------------------ reported, end to end


def fast_move(robot: SimRobot) -> JointTrajectory:
    """0.5 rad of the RRP arm's base in 0.5 s: 11.5 rad/s² at the peak, over its 8 rad/s²."""
    q = np.array(robot.robot_state.joint_position)
    return JointTrajectory.smooth_move(q, q + np.array([0.5, 0.0, 0.0]), 0.5)


def test_the_stretch_is_reported_in_status_state_and_log(tmp_path: Path) -> None:
    robot = make_sim(RRP)
    log = StateLog(tmp_path / "s.jsonl", robot.joint_names, 1)
    csv = StateLog(tmp_path / "s.csv", robot.joint_names, 1)
    robot.add_state_listener(log)
    robot.add_state_listener(csv)
    robot.command_mode = CommandMode.trajectory
    robot.step()
    statuses = list(robot.execute_trajectory(fast_move(robot)))
    log.close()
    csv.close()
    final = statuses[-1]
    assert final.action_status is ActionStatus.complete
    stretch = final.stretch
    assert stretch is not None and stretch.factor > 1.2
    assert stretch.duration > stretch.planned_duration == 0.5
    assert final.trajectory_time == pytest.approx(stretch.duration)
    assert stretch.describe(robot.joint_names).startswith(
        "slowed to stay within the acceleration limit of joint 'base_yaw': "
    )
    rows = [json.loads(x) for x in (tmp_path / "s.jsonl").read_text().splitlines()]
    stretched = [r["trajectory_stretch"] for r in rows if r["trajectory_stretch"] > 1.0]
    assert stretched and max(stretched) == pytest.approx(stretch.factor)
    assert max(r["trajectory_max_time"] for r in rows) == pytest.approx(stretch.duration)
    lines = (tmp_path / "s.csv").read_text().splitlines()
    assert lines[0].endswith(",error,trajectory_stretch")
    assert max(float(x.rsplit(",", 1)[1]) for x in lines[1:]) == pytest.approx(stretch.factor)
    q = np.array(robot.robot_state.joint_position)
    assert q[0] == pytest.approx(0.6, abs=1e-3)  # home 0.1, then 0.5 further


def test_the_stretch_is_reported_in_the_scenario(tmp_path: Path) -> None:
    script = tmp_path / "s.yaml"
    script.write_text(
        "- call: command_mode\n  args: {mode: trajectory}\n"
        "- call: execute_trajectory\n  args: {to: [0.6, 0.0, 0.0], duration: 0.5}\n"
        "  expect: {status: complete}\n"
        "- call: execute_trajectory\n  args: {to: [0.1, 0.0, 0.0], duration: 4.0}\n"
        "  expect: {status: complete}\n"
    )
    robot = SimRobot(load_robot_info(RRP), clock=SimClock(), initial_position=[0.1, 0.0, 0.0])
    robot.step()
    results = run_scenario(robot, load_scenario(script))
    assert [r.ok for r in results] == [True, True, True]
    assert results[1].note.startswith("slowed to stay within the acceleration limit")
    assert results[2].note == ""  # 4 s is well within the limits: not stretched


def test_cli_summary_names_the_slowed_trajectories(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from robotspec.cli.app import app
    from robotspec.cli.output import run_app

    script = tmp_path / "s.yaml"
    script.write_text(
        "- call: command_mode\n  args: {mode: trajectory}\n"
        "- call: execute_trajectory\n  args: {to: [0.6, 0.0, 0.0], duration: 0.5}\n"
    )
    code = run_app(app, ["drive", "--sim", str(RRP), "--virtual-time", "--script", str(script)])
    out = capsys.readouterr().out.splitlines()
    assert code == 0
    assert out[1].startswith(
        "ok   step 2 execute_trajectory: slowed to stay within the acceleration limit of joint "
        "'base_yaw': "
    )
    assert out[-1] == (
        "scenario: 2 of 2 steps as expected; 1 trajectory slowed to stay within the joint "
        "limits (step 2)"
    )


def test_scenario_waypoints_may_carry_velocities(tmp_path: Path) -> None:
    script = tmp_path / "s.yaml"
    rows = []
    for i in range(6):  # 0.1 -> 0.35 rad on the base, cosine law over 0.5 s
        t = 0.1 * i
        q = 0.1 + 0.125 * (1 - math.cos(math.pi * t / 0.5))
        v = 0.125 * math.pi / 0.5 * math.sin(math.pi * t / 0.5)
        rows.append(
            f"    - {{time_from_start: {t:.1f}, joint_position: [{q!r}, 0, 0], "
            f"joint_velocity: [{v!r}, 0, 0]}}\n"
        )
    script.write_text(
        "- call: command_mode\n  args: {mode: trajectory}\n"
        "- call: execute_trajectory\n  args:\n    waypoints:\n"
        + "".join(rows)
        + "  expect: {status: complete}\n"
        "- check: {joint_position: [0.35, 0.0, 0.0]}\n"
    )
    robot = SimRobot(load_robot_info(RRP), clock=SimClock(), initial_position=[0.1, 0.0, 0.0])
    robot.step()
    results = run_scenario(robot, load_scenario(script))
    assert [(r.ok, r.note) for r in results] == [(True, ""), (True, ""), (True, "")]
