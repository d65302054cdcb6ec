"""Random client-call sequences against the simulated driver, with safety invariants on every step.

A hypothesis ``RuleBasedStateMachine`` drives a :class:`SimRobot` on simulated time through
random sequences of everything a client (or the robot) can do: mode changes (valid and not),
enable/disable/reset, jogs with random and sometimes NaN, infinite or out-of-limit arguments,
trajectories with Next/Abort/Close, position and velocity streams with random seqnos, speed ratios,
homing, tools and payloads, injected faults, and plain loop steps.

A state listener checks every single step the loop runs -- including the steps a blocking call
runs itself -- and records violations (a listener must not raise: the loop drops listeners that
do). The invariants, from the issue's "Safety and reliability" section:

* no NaN or infinity is ever sent; every position sent is within the joint limits; the implied
  velocity of consecutive position commands, and every velocity command, is within the velocity
  limits (tolerance :data:`VEL_TOL`, relative, for floating-point round-off only);
* the loop never dies: every step publishes a new state (seqno + 1), and an exception inside a step
  gives the error flag and mode ``invalid_state`` with a message;
* state flags agree with the mode (communication failure is reported alone with empty joint
  arrays; motion modes only when enabled and ready; trajectory_running only in trajectory mode;
  valid stream flags only in their streaming mode; errors force ``invalid_state``);
* a refused call raises one of the package's own exceptions (``RobotSpecError``), never a bare
  Python error;
* a waiting jog interrupted by halt, an error, an e-stop or lost communication raises
  OperationAborted, never returns success.

Deterministic: the conftest profile derandomizes, and every clock is simulated.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, event, settings
from hypothesis import strategies as st
from hypothesis.stateful import (
    RuleBasedStateMachine,
    initialize,
    invariant,
    precondition,
    rule,
)

from robotspec.driver.clock import SimClock
from robotspec.driver.errors import OperationAbortedError
from robotspec.driver.loop import RobotJointCommand, TrajectoryGenerator
from robotspec.driver.robot_info import PayloadInfo, Pose, RobotInfo, ToolInfo, load_robot_info
from robotspec.driver.sim import Fault, SimRobot
from robotspec.driver.state import CommandMode, RobotState, StateFlags
from robotspec.driver.trajectory import JointTrajectory, Waypoint
from robotspec.errors import RobotSpecError
from tests.driver_support import ROBOTINFO_DIR, RRP

#: Relative tolerance on velocity checks: floating-point round-off only, no physical slack.
VEL_TOL = 1e-9
#: Absolute tolerance on position-limit checks (round-off of clip/add chains).
POS_TOL = 1e-12

ROBOT_FILES: list[Path] = [RRP] + [
    p for p in (ROBOTINFO_DIR / "sawyer.yml", ROBOTINFO_DIR / "abb_irb1200_5_90.yml") if p.exists()
]
_INFOS: dict[Path, RobotInfo] = {}


def _info(path: Path) -> RobotInfo:
    if path not in _INFOS:
        _INFOS[path] = load_robot_info(path)
    return _INFOS[path]


BAD_VALUES = (math.nan, math.inf, -math.inf)
BAD = st.sampled_from(BAD_VALUES)
#: A fraction of a joint's range (slightly outside it sometimes).
RANGE_FRACTION = st.floats(0.0, 1.0) | st.floats(-0.2, 1.2)
#: A fraction of a velocity limit (over it, zero or negative sometimes).
VEL_FRACTION = st.floats(0.01, 1.0) | st.floats(-1.5, 1.5) | st.just(0.0)


@st.composite
def noisy(
    draw: st.DrawFn, elements: st.SearchStrategy[float], min_size: int = 1, max_size: int = 7
) -> list[float]:
    """A list of ``elements`` in which, one time in three, one entry is NaN or infinite.

    Why not ``elements | BAD``: hypothesis favours the special values so much that nearly every
    call would be refused up front and the motion paths would go unexercised.
    """
    xs = draw(st.lists(elements, min_size=min_size, max_size=max_size))
    bad = draw(st.sampled_from([None, None, None, None, None, None, *BAD_VALUES]))
    if bad is not None:
        xs[draw(st.integers(0, len(xs) - 1))] = bad
    return xs


MODES = st.sampled_from([*CommandMode, -1, 42, "nonsense", "jog", "halt", "trajectory", None, 2.5])
FAULTS = st.sampled_from(list(Fault))
#: Whether a motion rule first switches to its mode (mostly yes).
ENSURE = st.sampled_from([True, True, True, False])


class DriverMachine(RuleBasedStateMachine):
    """The simulated driver under random client calls and faults."""

    def __init__(self) -> None:
        super().__init__()
        self.robot: SimRobot | None = None
        self.violations: list[str] = []
        self.generators: list[TrajectoryGenerator] = []
        self.seen_sent = 0
        self.prev_seqno = -1
        self.prev_sent_pos: np.ndarray | None = None

    # ------------------------------------------------------------------ setup and checking

    @initialize(path=st.sampled_from(ROBOT_FILES), period=st.sampled_from([0.01, 0.004]))
    def start(self, path: Path, period: float) -> None:
        robot = SimRobot(_info(path), clock=SimClock(), update_period=period)
        robot.record_commands = True
        robot.add_state_listener(self._listener)
        self.robot = robot
        robot.step()
        robot.step()

    @property
    def r(self) -> SimRobot:
        assert self.robot is not None
        return self.robot

    def _listener(self, state: RobotState) -> None:
        try:
            self._check_step(state)
        except Exception as exc:  # noqa: BLE001 - a listener that raises is dropped by the loop
            self.violations.append(f"checker crashed: {type(exc).__name__}: {exc}")

    def _fail(self, what: str) -> None:
        self.violations.append(f"t={self.r._stopwatch_ellapsed_s():.4f}: {what}")

    def _check_step(self, s: RobotState) -> None:
        robot = self.r
        lim = robot.limits
        dt = robot.update_period
        # The loop never dies: every step publishes a new state.
        if s.seqno != self.prev_seqno + 1 and self.prev_seqno >= 0:
            self._fail(f"state seqno jumped from {self.prev_seqno} to {s.seqno}")
        self.prev_seqno = s.seqno
        # Commands sent this step (at most one).
        new = robot.sent[self.seen_sent :]
        self.seen_sent = len(robot.sent)
        if len(new) > 1:
            self._fail(f"{len(new)} commands sent in one step")
        sent_pos = None
        for _, pos, vel in new:
            if pos is not None and vel is not None:
                self._fail("position and velocity sent together")
            if pos is not None:
                sent_pos = pos
                if not np.all(np.isfinite(pos)):
                    self._fail(f"non-finite position sent: {pos}")
                    continue
                if np.any(pos < lim.lower - POS_TOL) or np.any(pos > lim.upper + POS_TOL):
                    self._fail(f"position outside limits sent: {pos}")
                ref = self.prev_sent_pos
                if ref is None and s.joint_position.shape[0] == lim.count:
                    ref = np.asarray(s.joint_position)
                if ref is not None:
                    step = np.abs(pos - ref)
                    allowed = lim.velocity * dt * (1 + VEL_TOL) + POS_TOL
                    if np.any(step > allowed):
                        self._fail(
                            f"position step implies {np.max(step / dt / lim.velocity):.6g} x "
                            "the velocity limit"
                        )
            if vel is not None:
                if not np.all(np.isfinite(vel)):
                    self._fail(f"non-finite velocity sent: {vel}")
                    continue
                if np.any(np.abs(vel) > lim.velocity * (1 + VEL_TOL)):
                    self._fail(f"velocity over the limit sent: {vel}")
        # The guard's reference is the last command only when one went out in the previous step.
        self.prev_sent_pos = None if sent_pos is None else np.array(sent_pos)
        # The simulated arm itself stays within its limits.
        q = robot.sim_position
        if np.any(q < lim.lower - POS_TOL) or np.any(q > lim.upper + POS_TOL):
            self._fail(f"arm outside its limits: {q}")
        self._check_flags(s)

    def _check_flags(self, s: RobotState) -> None:
        lim = self.r.limits
        f = s.flags
        mode = s.command_mode
        if not np.all(np.isfinite(s.joint_position)):
            self._fail("non-finite joint_position published")
        if f & StateFlags.communication_failure:
            if f != StateFlags.communication_failure:
                self._fail(f"communication failure not reported alone: {f!r}")
            if mode is not CommandMode.invalid_state:
                self._fail(f"communication failure in mode {mode.name}")
            if s.joint_position.shape[0] != 0 or s.kin_chain_tcp:
                self._fail("joint arrays not emptied on communication failure")
            return
        if s.joint_position.shape[0] != lim.count:
            self._fail(f"joint_position has {s.joint_position.shape[0]} values")
        if f & StateFlags.error and mode is not CommandMode.invalid_state:
            self._fail(f"error flag in mode {mode.name}")
        if self.r._raise_in_step:
            if not (f & StateFlags.error) or "injected fault" not in s.error_message:
                self._fail(f"step exception not reported: flags {f!r}, '{s.error_message}'")
        motion = {
            CommandMode.jog,
            CommandMode.trajectory,
            CommandMode.position_command,
            CommandMode.velocity_command,
        }
        if mode in motion and not (f & StateFlags.ready and f & StateFlags.enabled):
            self._fail(f"mode {mode.name} while not ready/enabled: {f!r}")
        if mode is CommandMode.homing and (
            not (f & StateFlags.enabled) or f & (StateFlags.error | StateFlags.estop)
        ):
            self._fail(f"homing while not enabled or in error/e-stop: {f!r}")
        if f & StateFlags.trajectory_running and mode is not CommandMode.trajectory:
            self._fail(f"trajectory_running in mode {mode.name}")
        if f & StateFlags.valid_position_command and mode is not CommandMode.position_command:
            self._fail(f"valid_position_command in mode {mode.name}")
        if f & StateFlags.valid_velocity_command and mode is not CommandMode.velocity_command:
            self._fail(f"valid_velocity_command in mode {mode.name}")
        if (f & StateFlags.estop) and mode is not CommandMode.invalid_state:
            self._fail(f"e-stop in mode {mode.name}")
        if s.error_message and not (f & StateFlags.error):
            self._fail(f"error message '{s.error_message}' without the error flag")

    @invariant()
    def no_violation(self) -> None:
        if self.robot is None:
            return
        assert not self.violations, "\n".join(self.violations[:10])

    def call(self, fn: Callable[[], Any]) -> Any:
        """Run a client call; a refusal must be one of the package's errors."""
        try:
            return fn()
        except RobotSpecError:
            return None

    # ------------------------------------------------------------------ helpers

    def _ensure(self, mode: CommandMode, ensure: bool) -> None:
        """Usually switch to ``mode`` first (as a client would), so motion rules get exercised."""
        robot = self.r
        if ensure and robot.command_mode is not mode:
            self.call(robot.halt)
            robot.step()
            self.call(lambda: setattr(robot, "command_mode", mode))

    def _positions(self, fractions: list[float]) -> list[float]:
        lim = self.r.limits
        out = []
        for i in range(lim.count):
            f = fractions[i % len(fractions)]
            out.append(lim.lower[i] + f * (lim.upper[i] - lim.lower[i]) if math.isfinite(f) else f)
        return out

    def _velocities(self, fractions: list[float]) -> list[float]:
        lim = self.r.limits
        return [
            fractions[i % len(fractions)] * lim.velocity[i]
            if math.isfinite(fractions[i % len(fractions)])
            else fractions[i % len(fractions)]
            for i in range(lim.count)
        ]

    # ------------------------------------------------------------------ rules: modes and state

    @rule(mode=MODES)
    def set_mode(self, mode: Any) -> None:
        self.call(lambda: setattr(self.r, "command_mode", mode))

    @rule()
    def halt(self) -> None:
        self.call(self.r.halt)

    @rule(
        mode=st.sampled_from(
            [
                CommandMode.jog,
                CommandMode.jog,
                CommandMode.trajectory,
                CommandMode.trajectory,
                CommandMode.position_command,
                CommandMode.velocity_command,
                CommandMode.homing,
            ]
        )
    )
    def enter_mode(self, mode: CommandMode) -> None:
        """Halt, then request ``mode``: random calls alone rarely reach a motion mode."""
        robot = self.r
        self.call(robot.halt)
        robot.step()
        self.call(lambda: setattr(robot, "command_mode", mode))
        event(f"enter {mode.name}: now {robot.command_mode.name}")

    @rule(which=st.sampled_from(["enable", "disable", "reset_errors"]))
    def power(self, which: str) -> None:
        self.call(getattr(self.r, which))

    @rule(value=st.floats(0.05, 10.5) | BAD | st.sampled_from([0.1, 10.0, 0.0, -1.0, "x"]))
    def speed_ratio(self, value: Any) -> None:
        self.call(lambda: setattr(self.r, "speed_ratio", value))

    @rule(n=st.integers(1, 30))
    def step(self, n: int) -> None:
        for _ in range(n):
            self.r.step()
        event(f"stepped in {self.r.command_mode.name}")

    # ------------------------------------------------------------------ rules: jogs

    @rule(
        goal=noisy(RANGE_FRACTION),
        vel=noisy(VEL_FRACTION),
        short=st.booleans(),
        ensure=ENSURE,
    )
    def jog_freespace(self, goal: list[float], vel: list[float], short: bool, ensure: bool) -> None:
        self._ensure(CommandMode.jog, ensure)
        q = self._positions(goal)
        v = self._velocities(vel)
        if short:
            q = q[:-1]
        self.call(lambda: self.r.jog_freespace(q, v, wait=False))

    @rule(
        vel=noisy(VEL_FRACTION),
        timeout=st.floats(0.01, 0.5) | st.sampled_from([0.0, -0.1, *BAD_VALUES]),
        ensure=ENSURE,
    )
    def jog_joint(self, vel: list[float], timeout: float, ensure: bool) -> None:
        self._ensure(CommandMode.jog, ensure)
        v = self._velocities(vel)
        self.call(lambda: self.r.jog_joint(v, timeout, wait=False))

    @rule(
        twist=noisy(st.floats(-0.5, 0.5), 6, 6),
        timeout=st.floats(-0.1, 0.3),
        chain=st.sampled_from([0, 0, 1, -1]),
        ensure=ENSURE,
    )
    def jog_cartesian(self, twist: list[float], timeout: float, chain: int, ensure: bool) -> None:
        self._ensure(CommandMode.jog, ensure)
        self.call(lambda: self.r.jog_cartesian(twist, timeout, wait=False, chain=chain))

    @rule(
        event_name=st.sampled_from(["halt", "drive_error", "estop", "lost_feedback", "disabled"]),
        delay=st.floats(0.0, 0.2),
        ensure=ENSURE,
    )
    def waiting_jog_interrupted(self, event_name: str, delay: float, ensure: bool) -> None:
        """A ``wait=True`` jog interrupted before it arrives raises OperationAborted."""
        robot = self.r
        self._ensure(CommandMode.jog, ensure)
        if robot.command_mode is not CommandMode.jog or not robot.robot_state.ready:
            return
        lim = robot.limits
        q = np.asarray(robot.robot_state.joint_position)
        # The farther limit of each joint, at a tenth of the speed: far from arriving in 0.2 s.
        target = np.where(q - lim.lower > lim.upper - q, lim.lower, lim.upper)
        if np.all(np.abs(target - q) < 0.05 * (lim.upper - lim.lower)):
            return
        fired: list[float] = []
        finished = [False]

        def interrupt() -> None:
            if finished[0]:
                return  # the jog ended (refused or arrived) first: no event after all
            fired.append(robot._stopwatch_ellapsed_s())
            if event_name == "halt":
                self.call(robot.halt)
            else:
                robot.inject_fault(event_name)

        robot.at(robot._stopwatch_ellapsed_s() + delay, interrupt)
        try:
            robot.jog_freespace(target, lim.velocity * 0.1, wait=True)
        except OperationAbortedError:
            event(f"waiting jog aborted by {event_name}")
            return
        except RobotSpecError as exc:
            if not fired:
                return  # refused up front (not ready, ...)
            raise AssertionError(f"interrupted jog raised {type(exc).__name__}: {exc}") from exc
        finally:
            finished[0] = True
        assert not fired, f"a waiting jog interrupted by {event_name} at {fired[0]:.3f} s succeeded"

    # ------------------------------------------------------------------ rules: trajectories

    @rule(
        deltas=st.lists(st.floats(-1.0, 1.0), min_size=1, max_size=7),
        count=st.integers(5, 25),
        spacing=st.floats(0.01, 0.1),
        start_offset=st.floats(-0.04, 0.04),
        defect=st.sampled_from(
            [None] * 8 + ["nan", "names", "empty_names", "first", "far", "few", "gap", "limit"]
        ),
        ensure=ENSURE,
        next_now=st.booleans(),
    )
    def execute_trajectory(
        self,
        deltas: list[float],
        count: int,
        spacing: float,
        start_offset: float,
        defect: str | None,
        ensure: bool,
        next_now: bool,
    ) -> None:
        """A smooth move from near the current position, valid or with one defect."""
        robot = self.r
        self._ensure(CommandMode.trajectory, ensure)
        n = robot.limits.count
        q = np.asarray(robot.robot_state.joint_position)
        if q.shape[0] != n:
            q = robot.limits.home
        start = q + start_offset + (0.2 if defect == "far" else 0.0)
        # Peak speed of the quintic blend is 1.875 x the mean: stay within the velocity limits.
        duration = spacing * (count - 1)
        reach = robot.limits.velocity * duration / 1.875 * 0.9
        d = np.array([deltas[i % len(deltas)] for i in range(n)]) * reach
        lim = robot.limits
        if defect != "far":
            start = np.clip(start, lim.lower, lim.upper)
        d = np.clip(start + d, lim.lower, lim.upper) - start
        if defect == "limit":
            d[0] = robot.limits.upper[0] + 0.01 - start[0]
        count = 3 if defect == "few" else count
        s = np.linspace(0.0, 1.0, count)
        blend = 10 * s**3 - 15 * s**4 + 6 * s**5
        pos = start[None, :] + blend[:, None] * d[None, :]
        if defect == "nan":
            pos[count // 2, n // 2] = math.nan
        times = spacing * np.arange(count) + (0.01 if defect == "first" else 0.0)
        if defect == "gap":
            times[count // 2 :] += 0.15
        joint_names = {
            "names": tuple(reversed(robot.joint_names)),
            "empty_names": (),
        }.get(defect or "", robot.joint_names)
        traj = JointTrajectory(
            joint_names=tuple(joint_names),
            waypoints=tuple(
                Waypoint(joint_position=tuple(float(x) for x in pos[i]), time_from_start=float(t))
                for i, t in enumerate(times)
            ),
        )
        try:
            gen = robot.execute_trajectory(traj)
            event("trajectory accepted")
        except RobotSpecError as exc:
            event(f"trajectory refused: {str(exc)[:40]}")
            gen = None
        if gen is not None:
            self.generators.append(gen)
            if next_now:
                self.call(gen.Next)

    @precondition(lambda self: bool(self.generators))
    @rule(data=st.data(), action=st.sampled_from(["Next", "Next", "Abort", "Close"]))
    def trajectory_action(self, data: st.DataObject, action: str) -> None:
        gen = data.draw(st.sampled_from(self.generators))
        try:
            status = getattr(gen, action)()
            event(f"{action} -> {getattr(status, 'action_status', None)!r}")
        except StopIteration:
            self.generators.remove(gen)
        except RobotSpecError as exc:
            event(f"{action} -> {type(exc).__name__}")

    # ------------------------------------------------------------------ rules: streaming

    @rule(
        kind=st.sampled_from(["position", "velocity"]),
        values=noisy(RANGE_FRACTION),
        seqno=st.integers(-5, 1000),
        seq_offset=st.sampled_from([0, 0, 0, -1, -11, 5, 50]),
        units=st.sampled_from([(), ("degree",), ("bogus",), ("radian",)]),
        steps=st.integers(1, 10),
        ensure=ENSURE,
    )
    def stream(
        self,
        kind: str,
        values: list[float],
        seqno: int,
        seq_offset: int,
        units: tuple[str, ...],
        steps: int,
        ensure: bool,
    ) -> None:
        robot = self.r
        self._ensure(
            CommandMode.position_command if kind == "position" else CommandMode.velocity_command,
            ensure,
        )
        n = robot.limits.count
        if kind == "position":
            cmd = self._positions(values)
        else:
            cmd = self._velocities([2 * v - 0.5 if math.isfinite(v) else v for v in values])
        unit_list = list(units) * n if units else []
        for k in range(steps):
            command = RobotJointCommand(
                seqno + k, robot.robot_state.seqno + seq_offset, cmd, unit_list
            )
            send = robot.set_position_command if kind == "position" else robot.set_velocity_command
            self.call(partial(send, command))
            robot.step()

    # ------------------------------------------------------------------ rules: homing, tools

    @rule(ensure=ENSURE)
    def home(self, ensure: bool) -> None:
        self._ensure(CommandMode.homing, ensure)
        self.call(lambda: self.r.home(wait=False))

    @rule(
        chain=st.sampled_from([0, 0, 0, 1, -1]),
        name=st.sampled_from(["gripper", "probe"]),
        z=st.floats(0.0, 0.3),
    )
    def tool_attached(self, chain: int, name: str, z: float) -> None:
        tool = ToolInfo.model_validate(
            {
                "device_info": {"device": {"name": name}},
                "tcp": {"translation": {"x": 0, "y": 0, "z": z}},
            }
        )
        self.call(lambda: self.r.tool_attached(chain, tool))

    @rule(chain=st.sampled_from([0, 0, 1]), name=st.sampled_from(["", "gripper", "probe", "x"]))
    def tool_detached(self, chain: int, name: str) -> None:
        self.call(lambda: self.r.tool_detached(chain, name))

    @rule(chain=st.sampled_from([0, 0, 1]), name=st.sampled_from(["box", "ball"]))
    def payload_attached(self, chain: int, name: str) -> None:
        payload = PayloadInfo.model_validate({"device_info": {"device": {"name": name}}})
        self.call(lambda: self.r.payload_attached(chain, payload, Pose()))

    @rule(chain=st.sampled_from([0, 0, 1]), name=st.sampled_from(["", "box", "ball", "x"]))
    def payload_detached(self, chain: int, name: str) -> None:
        self.call(lambda: self.r.payload_detached(chain, name))

    # ------------------------------------------------------------------ rules: faults

    @rule(fault=FAULTS, source=st.sampled_from([1, 2, 3, 4]))
    def inject_fault(self, fault: Fault, source: int) -> None:
        self.r.inject_fault(fault, source=source)

    @rule(fault=st.none() | FAULTS)
    def clear_fault(self, fault: Fault | None) -> None:
        self.r.clear_fault(fault)

    @rule()
    def recover(self) -> None:
        """The operator fixes everything: the machine should get back to a healthy halt."""
        robot = self.r
        robot.clear_fault()
        self.call(robot.reset_errors)
        self.call(robot.enable)
        self.call(robot.halt)
        st_ = robot.run_for(0.5)
        if not robot._sim_enabled:
            return  # disabled and the robot has no software enable: nothing to recover
        assert st_.command_mode in (CommandMode.halt, CommandMode.homing), st_
        assert not (st_.flags & (StateFlags.error | StateFlags.communication_failure)), st_.flags


DriverMachine.TestCase.settings = settings(
    max_examples=100,
    stateful_step_count=30,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
TestDriverMachine = DriverMachine.TestCase


@pytest.mark.parametrize("path", ROBOT_FILES, ids=lambda p: p.stem)
def test_step_exception_keeps_reporting(path: Path) -> None:
    """The loop survives an exception in every step, for many steps, and recovers."""
    robot = SimRobot(_info(path), clock=SimClock())
    robot.step()
    robot.inject_fault(Fault.step_exception)
    seq = robot.robot_state.seqno
    for k in range(1, 50):
        s = robot.step()
        assert s.seqno == seq + k
        assert s.command_mode is CommandMode.invalid_state
        assert s.flags & StateFlags.error and "injected fault" in s.error_message
    robot.clear_fault(Fault.step_exception)
    robot.halt()
    s = robot.run_for(0.05)
    assert s.command_mode is CommandMode.halt
    assert not s.flags & StateFlags.error


def test_step_exception_clears_stream_flag() -> None:
    """Regression (found by the machine): a step that raises published a stale
    ``valid_position_command`` flag beside mode ``invalid_state``."""
    robot = SimRobot(_info(RRP), clock=SimClock())
    robot.step()
    robot.step()
    robot.command_mode = CommandMode.position_command
    q = robot.robot_state.joint_position.tolist()
    robot.set_position_command(RobotJointCommand(0, robot.robot_state.seqno + 1, q))
    assert robot.step().flags & StateFlags.valid_position_command
    robot.inject_fault(Fault.step_exception)
    s = robot.step()
    assert s.command_mode is CommandMode.invalid_state
    assert not s.flags & StateFlags.valid_position_command


def _homing_robot() -> SimRobot:
    robot = SimRobot(_info(RRP), clock=SimClock(), initial_position=[1.0, 0.5, 0.2])
    robot.step()
    robot.step()
    robot.command_mode = CommandMode.homing
    robot.step()
    return robot


def test_halt_stops_homing() -> None:
    """Regression: after halting a homing robot, the simulated controller kept homing."""
    robot = _homing_robot()
    done = robot.home(wait=False)
    robot.run_for(0.2)
    robot.halt()
    robot.run_for(1.0)  # brakes to rest
    assert done.done and isinstance(done.error, OperationAbortedError)
    q = robot.sim_position
    robot.run_for(2.0)
    np.testing.assert_array_equal(robot.sim_position, q)
    assert not robot.robot_state.flags & StateFlags.homed


def test_estop_ends_homing() -> None:
    """Regression (found by the machine): homing carried on, in mode homing, through an e-stop,
    and resumed toward home by itself once the e-stop was released."""
    robot = _homing_robot()
    done = robot.home(wait=False)
    robot.run_for(0.2)
    robot.inject_fault(Fault.estop)
    s = robot.step()
    assert s.command_mode is CommandMode.invalid_state
    assert done.done and isinstance(done.error, OperationAbortedError)
    q = robot.sim_position
    robot.reset_errors()
    robot.run_for(1.0)
    np.testing.assert_array_equal(robot.sim_position, q)
    assert robot.robot_state.command_mode is CommandMode.halt


def test_first_command_after_step_exception_is_rate_limited_from_the_arm() -> None:
    """Regression (found by the machine): after a failed step the guard still rate-limited from
    the last command sent before the failure, so the first command after recovery jumped up to
    2.7 x the velocity limit away from where the arm was."""
    robot = SimRobot(_info(RRP), clock=SimClock())
    robot.record_commands = True
    robot.step()
    robot.step()
    robot.command_mode = CommandMode.position_command
    lim = robot.limits
    far = lim.lower.tolist()
    for _ in range(2):
        robot.set_position_command(RobotJointCommand(0, robot.robot_state.seqno + 1, far))
        robot.step()
    robot.inject_fault(Fault.step_exception)
    robot.step()
    robot.clear_fault()
    robot.halt()
    robot.command_mode = CommandMode.position_command
    robot.set_position_command(RobotJointCommand(1, robot.robot_state.seqno + 1, far))
    s = robot.step()
    _, pos, _ = robot.sent[-1]
    assert pos is not None
    step = np.abs(pos - s.joint_position)
    assert np.all(step <= lim.velocity * robot.update_period * (1 + VEL_TOL) + POS_TOL)


def test_denormal_jog_velocity() -> None:
    """Regression (found by the machine): a denormal max_velocity (> 0, so accepted) overflowed
    the jog's move time and raised RuntimeWarnings (NaN scale factors)."""
    robot = SimRobot(_info(RRP), clock=SimClock())
    robot.step()
    robot.step()
    robot.command_mode = CommandMode.jog
    robot.speed_ratio = 0.1
    robot.jog_freespace([0.5, 0.5, 0.1], [5e-324, 1.0, 0.1], wait=False)
    s = robot.run_for(0.5)
    assert s.command_mode is CommandMode.jog
    assert not s.flags & StateFlags.error
