"""Faults over Robot Raconteur, and the generators' one-completion rule, with a real RR client.

A client reaches the simulator's faults through ``setf_param("fault.NAME", value)`` and reads them
with ``getf_param``: the conformance scenarios 37, 42, 44 and 45 of the reference note run here
over RR on the note's robot (the ABB IRB1200), and 42 and 44 again with ``reset_errors()`` on the
Sawyer, which declares ``software_reset_errors``. The waits are bounded; the assertions use the
robot's published state, never timing.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip(
    "RobotRaconteur",
    reason="robotraconteur is not installed (pip install robotspec[robotraconteur])",
)
pytest.importorskip(
    "RobotRaconteurCompanion",
    reason="robotraconteurcompanion is not installed (pip install robotspec[robotraconteur])",
)

import RobotRaconteur as RR

from robotspec.driver.faults import Fault
from robotspec.driver.state import (
    ActionStatus,
    CommandMode,
    ControllerState,
    OperationalMode,
    StateFlags,
)

from .driver_support import RRP, robotinfo
from .service_support import (
    WAIT,
    Served,
    client_node,
    rr_exception,
    serve,
    short_tmp,
    wait_until,
)

__all__ = ["client_node", "short_tmp"]  # fixtures from service_support, used by the tests below

HEALTHY = 0x60000
PERIOD = 0.01  # the note's period


@pytest.fixture
def abb(short_tmp: Path, client_node: Any) -> Iterator[Served]:
    with serve(robotinfo("abb_irb1200_5_90.yml"), short_tmp / "rr", client_node, PERIOD) as s:
        yield s


@pytest.fixture
def sawyer(short_tmp: Path, client_node: Any) -> Iterator[Served]:
    with serve(robotinfo("sawyer.yml"), short_tmp / "rr", client_node, PERIOD) as s:
        yield s


@pytest.fixture
def rrp(short_tmp: Path, client_node: Any) -> Iterator[Served]:
    with serve(RRP, short_tmp / "rr", client_node, PERIOD) as s:
        yield s


def fault(s: Served, name: str, on: bool) -> None:
    s.robot.setf_param(f"fault.{name}", RR.VarValue(on, "bool"))


def is_set(s: Served, name: str) -> bool:
    value = s.robot.getf_param(f"fault.{name}")
    return bool(np.asarray(value.data).reshape(-1)[0])


def next_state(s: Served) -> None:
    """Wait for the next published state."""
    before = int(s.state().seqno)
    wait_until(lambda: s.state().seqno > before)


def wait_state(s: Served, **want: int) -> Any:
    """Wait for a published state whose fields have these values; return it."""
    found: list[Any] = []

    def match() -> bool:
        st = s.state()
        if all(int(getattr(st, k)) == v for k, v in want.items()):
            found.append(st)
            return True
        return False

    wait_until(match)
    return found[-1]


def test_every_fault_is_a_parameter_read_back_by_getf_param(rrp: Served) -> None:
    for f in Fault:
        assert not is_set(rrp, f.value)
        fault(rrp, f.value, True)
        assert is_set(rrp, f.value)
        fault(rrp, f.value, False)
        assert not is_set(rrp, f.value)
    # The reference note's script name for the drive error is an alias of it.
    fault(rrp, "sim_error", True)
    assert is_set(rrp, "drive_error") and is_set(rrp, "sim_error")
    fault(rrp, "drive_error", False)
    assert not is_set(rrp, "sim_error")
    # Clients in other languages send numbers: 1 and 0 work too (as int32[] on the wire).
    rrp.robot.setf_param("fault.frozen", RR.VarValue(np.array([1], dtype=np.int32), "int32[]"))
    assert is_set(rrp, "frozen")
    rrp.robot.setf_param("fault.frozen", RR.VarValue(0.0, "double"))
    assert not is_set(rrp, "frozen")


def test_unknown_parameter_or_value_names_the_valid_ones(rrp: Served) -> None:
    with pytest.raises(rr_exception("InvalidArgumentException")) as exc:
        rrp.robot.setf_param("fault.estpo", RR.VarValue(True, "bool"))
    text = str(exc.value)
    assert "Invalid parameter 'fault.estpo'; did you mean 'fault.estop'" in text
    for f in Fault:
        assert f"fault.{f.value}" in text
    assert "fault.sim_error" in text
    with pytest.raises(rr_exception("InvalidArgumentException"), match="Invalid parameter 'x'"):
        rrp.robot.getf_param("x")
    with pytest.raises(rr_exception("InvalidArgumentException"), match="must be true or false"):
        rrp.robot.setf_param("fault.estop", RR.VarValue("yes", "string"))
    with pytest.raises(rr_exception("InvalidArgumentException"), match="must be true or false"):
        rrp.robot.setf_param("fault.estop", RR.VarValue(2, "int32"))
    assert not is_set(rrp, "estop")  # nothing changed


def test_param_changed_event(rrp: Served) -> None:
    seen: list[str] = []
    got = threading.Event()

    def on_changed(name: str) -> None:
        seen.append(name)
        got.set()

    rrp.robot.param_changed += on_changed
    fault(rrp, "disabled", True)
    assert got.wait(WAIT)
    assert seen == ["fault.disabled"]
    fault(rrp, "disabled", False)


def test_37_frozen_arm_fails_the_trajectory_and_halts(abb: Served) -> None:
    r = abb.robot
    r.command_mode = int(CommandMode.trajectory)
    fault(abb, "frozen", True)
    gen = r.execute_trajectory(abb.trajectory(np.array([0.6, 0, 0.4, 0, 0, 0]), 1.0))
    with pytest.raises(rr_exception("OperationFailedException"), match="tolerance failure"):
        gen.Next()
    # [deviate] the reference keeps the trajectory active (trajectory_running) forever.
    st = wait_state(abb, command_mode=int(CommandMode.halt))
    assert not st.robot_state_flags & int(StateFlags.trajectory_running)
    # Robot Raconteur ends a generator whose Next() raised: it is gone ("Invalid generator").
    with pytest.raises(rr_exception("InvalidOperationException"), match="Invalid generator"):
        gen.Next()
    fault(abb, "frozen", False)


@pytest.mark.parametrize("name", ["sim_error", "drive_error"])
def test_42_drive_error(abb: Served, name: str) -> None:
    r = abb.robot
    fault(abb, name, True)
    st = wait_state(abb, command_mode=int(CommandMode.invalid_state))
    assert st.robot_state_flags == 0x20001
    assert r.controller_state == int(ControllerState.guard_stop)
    r.command_mode = int(CommandMode.halt)  # accepted; the next step forces invalid_state again
    with pytest.raises(rr_exception("InvalidOperationException"), match="Cannot set robot"):
        r.command_mode = int(CommandMode.jog)
    assert abb.state().command_mode == int(CommandMode.invalid_state)
    # [deviate 8] the IRB1200 lacks software_reset_errors: reset_errors() is refused, and the
    # error is cleared at the (simulated) controller instead.
    with pytest.raises(rr_exception("InvalidOperationException"), match="reset errors"):
        r.reset_errors()
    fault(abb, name, False)
    st = wait_state(abb, command_mode=int(CommandMode.halt))
    assert st.robot_state_flags == HEALTHY


def test_42_44_reset_errors_clears_the_fault(sawyer: Served) -> None:
    r = sawyer.robot
    for name, flags in (("sim_error", 0x20001), ("estop", 0x2000C)):
        fault(sawyer, name, True)
        st = wait_state(sawyer, command_mode=int(CommandMode.invalid_state))
        assert st.robot_state_flags & flags == flags
        r.reset_errors()  # the simulated operator clears the drive error and the e-stop
        wait_state(sawyer, command_mode=int(CommandMode.halt))
        assert not is_set(sawyer, name)


def test_44_estop(abb: Served) -> None:
    r = abb.robot
    fault(abb, "estop", True)
    st = wait_state(abb, command_mode=int(CommandMode.invalid_state))
    assert st.robot_state_flags == 0x2000C  # estop | estop_button1 | enabled
    assert r.controller_state == int(ControllerState.emergency_stop)
    fault(abb, "estop", False)
    st = wait_state(abb, command_mode=int(CommandMode.halt))
    assert st.robot_state_flags == HEALTHY


def test_45_lost_feedback(abb: Served) -> None:
    r = abb.robot
    fault(abb, "lost_feedback", True)
    st = wait_state(abb, robot_state_flags=0x200000)  # communication_failure alone
    assert st.command_mode == int(CommandMode.invalid_state)
    assert len(st.joint_position) == 0
    assert len(st.kin_chain_tcp) == 0
    assert r.operational_mode == int(OperationalMode.undefined)
    assert r.controller_state == int(ControllerState.undefined)
    with pytest.raises(rr_exception("InvalidOperationException"), match="Cannot set robot"):
        r.command_mode = int(CommandMode.halt)
    fault(abb, "lost_feedback", False)
    st = wait_state(abb, command_mode=int(CommandMode.halt))
    assert st.robot_state_flags == HEALTHY
    assert len(st.joint_position) == 6


def test_step_exception_over_rr(rrp: Served) -> None:
    r = rrp.robot
    fault(rrp, "step_exception", True)
    wait_state(rrp, command_mode=int(CommandMode.invalid_state))
    assert any("injected fault" in e.message for e in r.current_errors)
    fault(rrp, "step_exception", False)
    r.reset_errors()
    wait_state(rrp, command_mode=int(CommandMode.halt))


# ----------------------------------------------------------------- one completion per generator


def _async_next_twice(gen: Any) -> list[tuple[str, Any]]:
    """Two concurrent Next() calls on one generator; their outcomes (kind, value)."""
    results: list[tuple[str, Any]] = []
    done = threading.Event()
    lock = threading.Lock()

    def handler(value: Any, err: Any) -> None:
        with lock:
            results.append(("error", err) if err is not None else ("value", value))
            if len(results) == 2:
                done.set()

    gen.AsyncNext(None, handler)
    gen.AsyncNext(None, handler)
    assert done.wait(WAIT), results
    return results


def test_two_concurrent_next_calls_get_one_completion(rrp: Served) -> None:
    r = rrp.robot
    r.command_mode = int(CommandMode.trajectory)
    gen = r.execute_trajectory(rrp.trajectory(np.array([0.1, 0.05, 0.0]), 0.5))
    results = _async_next_twice(gen)
    values = [v for kind, v in results if kind == "value"]
    errors = [v for kind, v in results if kind == "error"]
    assert [v.action_status for v in values] == [int(ActionStatus.complete)], results
    assert len(errors) == 1 and isinstance(errors[0], rr_exception("StopIterationException"))


def test_two_concurrent_homing_next_calls_get_one_completion(rrp: Served) -> None:
    r = rrp.robot
    r.command_mode = int(CommandMode.homing)
    results = _async_next_twice(r.home())
    values = [v for kind, v in results if kind == "value"]
    errors = [v for kind, v in results if kind == "error"]
    assert values == [int(ActionStatus.complete)], results
    assert len(errors) == 1 and isinstance(errors[0], rr_exception("StopIterationException"))


# ----------------------------------------------------------------------------- the position stream


def test_huge_seqno_over_rr_does_not_lock_the_position_stream(rrp: Served) -> None:
    r = rrp.robot
    r.command_mode = int(CommandMode.position_command)
    wire = r.position_command.Connect()
    try:
        cmd = rrp.struct("com.robotraconteur.robotics.robot.RobotJointCommand")
        cmd.units = np.array([], dtype=np.uint8)
        cmd.command = rrp.q()

        def send(seqno: int, state_seqno: int | None = None) -> None:
            cmd.seqno = seqno
            cmd.state_seqno = rrp.state().seqno if state_seqno is None else state_seqno
            wire.OutValue = cmd

        def accepted_once(seqno: int) -> None:
            """Send ``seqno`` until the loop has taken it (the flag on a later state)."""
            for _ in range(500):
                send(seqno)
                next_state(rrp)
                next_state(rrp)
                if rrp.state().robot_state_flags & int(StateFlags.valid_position_command):
                    return
            raise AssertionError(f"seqno {seqno} never accepted")

        # A sample with the largest uint64 seqno, taken by the loop; then one with the largest
        # state_seqno (stale, ignored).
        accepted_once(2**64 - 1)
        send(5, state_seqno=2**64 - 1)
        # The client's ordinary count afterwards drives the arm (the reference ignores it all).
        target = rrp.q() + np.array([0.03, 0.0, 0.0])
        cmd.command = target
        reached = False
        for seqno in range(1, 300):
            send(seqno)
            st = rrp.state()
            if st.robot_state_flags & int(StateFlags.valid_position_command) and np.allclose(
                st.joint_position, target, atol=1e-4
            ):
                reached = True
                break
            next_state(rrp)
        assert reached, (rrp.q(), target)
    finally:
        wire.Close()
