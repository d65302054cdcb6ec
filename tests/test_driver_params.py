"""The simulator's fault parameters and the generators' one-completion rule, in process.

``setf_param("fault.NAME", ...)`` / ``getf_param`` are what a Robot Raconteur client uses to
inject faults (tests/test_service_faults.py runs them over RR); here the same calls drive the
simulated robot directly, in simulated time. Two ``Next()`` calls waiting on one generator run on
threads against the real-time loop: exactly one gets the outcome.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np
import pytest

from robotspec.driver.errors import InvalidArgumentError
from robotspec.driver.faults import FAULT_ALIASES, Fault, fault_param, fault_param_value
from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import ActionStatus, CommandMode, StateFlags
from robotspec.driver.trajectory import JointTrajectory

from .driver_support import RRP, make_sim, q_of


def test_every_fault_and_alias_round_trips() -> None:
    robot = make_sim(RRP)
    for f in Fault:
        name = f"fault.{f.value}"
        assert robot.getf_param(name) is False
        robot.setf_param(name, True)
        assert robot.getf_param(name) is True and robot.fault_active(f)
        robot.setf_param(name, False)
        assert robot.getf_param(name) is False
    for alias, f in FAULT_ALIASES.items():
        robot.setf_param(f"fault.{alias}", True)
        assert robot.fault_active(f) and robot.getf_param(f"fault.{alias}") is True
        robot.clear_fault(f)
        assert robot.getf_param(f"fault.{alias}") is False


def test_fault_params_drive_the_state_machine() -> None:
    robot = make_sim(RRP)
    robot.setf_param("fault.estop", True)
    st = robot.step()
    assert st.command_mode is CommandMode.invalid_state and st.flags & StateFlags.estop
    robot.reset_errors()  # the simulated operator releases the e-stop: the parameter follows
    assert robot.getf_param("fault.estop") is False
    assert robot.step().command_mode is CommandMode.halt


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (True, True),
        (False, False),
        (1, True),
        (0, False),
        (1.0, True),
        (np.array([True]), True),
        (np.array([0], dtype=np.int32), False),
        (np.float64(1.0), True),
    ],
)
def test_values_true_false_or_one_zero(value: Any, expected: bool) -> None:
    assert fault_param_value("fault.estop", value) is expected


@pytest.mark.parametrize("value", [2, -1, 0.5, "true", None, np.array([1, 0]), [True]])
def test_other_values_are_refused(value: Any) -> None:
    with pytest.raises(InvalidArgumentError, match="fault.estop must be true or false"):
        fault_param_value("fault.estop", value)


@pytest.mark.parametrize(
    ("name", "closest"),
    [("fault.estpo", "fault.estop"), ("fault.frozn", "fault.frozen"), ("estop", "fault.estop")],
)
def test_unknown_names_list_the_valid_ones(name: str, closest: str) -> None:
    with pytest.raises(InvalidArgumentError) as exc:
        fault_param(name)
    text = exc.value.message
    assert text.startswith(f"Invalid parameter '{name}'")  # as the reference starts it
    assert f"did you mean '{closest}'" in text
    assert all(f"fault.{f.value}" in text for f in Fault)


def test_the_base_driver_has_no_parameters() -> None:
    robot = make_sim(RRP)
    with pytest.raises(InvalidArgumentError, match="Invalid parameter 'x'"):
        robot.setf_param("x", True)


def _twice(call: Any) -> list[tuple[str, Any]]:
    """``call()`` on two threads at once; each outcome as ("value", v) or ("error", exc)."""
    out: list[tuple[str, Any]] = []
    lock = threading.Lock()

    def run() -> None:
        try:
            value = call()
        except BaseException as exc:  # noqa: BLE001 - recorded for the assertions
            with lock:
                out.append(("error", exc))
            return
        with lock:
            out.append(("value", value))

    threads = [threading.Thread(target=run) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60.0)
    assert len(out) == 2, out
    return out


def test_two_next_calls_on_one_trajectory_get_one_completion() -> None:
    robot = SimRobot(load_robot_info(RRP), update_period=0.004)  # real time, loop thread
    robot._start_robot()
    try:
        deadline = time.monotonic() + 60.0  # a hang bound: a busy machine may take seconds
        while robot.robot_state.joint_position.size == 0:  # the first feedback
            assert time.monotonic() < deadline, "no feedback from the loop thread"
            time.sleep(0.01)
        robot.command_mode = CommandMode.trajectory
        q = q_of(robot)
        gen = robot.execute_trajectory(JointTrajectory.smooth_move(q, q + [0.1, 0.05, 0.0], 0.4))
        out = _twice(gen.Next)
    finally:
        robot._stop_robot()
    values = [v.action_status for kind, v in out if kind == "value"]
    errors = [v for kind, v in out if kind == "error"]
    assert values == [ActionStatus.complete], out
    assert len(errors) == 1 and isinstance(errors[0], StopIteration), out
