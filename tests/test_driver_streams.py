"""The position stream's seqno rule: out-of-order samples ignored, never stuck (in process).

The reference ignores any seqno below the last accepted one, so one sample with a huge seqno (or
a counter near the top of ``uint64``) locks the stream for good. The driver compares seqnos
modulo 2**64 and treats a step back of more than ``STREAM_REORDER_WINDOW`` as a restarted
counter. Runs on the self-made RRP arm (simulated time), so it needs nothing from ../shared.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from robotspec.driver.conversions import (
    SEQNO_MODULUS,
    STREAM_REORDER_WINDOW,
    seqno_out_of_order,
)
from robotspec.driver.loop import RobotJointCommand
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import CommandMode, StateFlags

from .driver_support import RRP, make_sim, q_of

U64 = st.integers(min_value=0, max_value=SEQNO_MODULUS - 1)
VALID = int(StateFlags.valid_position_command)


@given(last=U64, ahead=st.integers(min_value=0, max_value=SEQNO_MODULUS // 2))
def test_a_sample_at_or_after_the_last_is_accepted_across_the_wrap(last: int, ahead: int) -> None:
    assert not seqno_out_of_order((last + ahead) % SEQNO_MODULUS, last)


@given(last=U64, behind=st.integers(min_value=1, max_value=STREAM_REORDER_WINDOW))
def test_a_sample_just_behind_the_last_is_ignored(last: int, behind: int) -> None:
    assert seqno_out_of_order((last - behind) % SEQNO_MODULUS, last)


@given(
    last=U64,
    behind=st.integers(min_value=STREAM_REORDER_WINDOW + 1, max_value=SEQNO_MODULUS - 1),
)
def test_a_far_step_back_is_a_restarted_counter(last: int, behind: int) -> None:
    assert not seqno_out_of_order((last - behind) % SEQNO_MODULUS, last)


@given(seqno=U64)
def test_nothing_is_out_of_order_before_the_first_sample(seqno: int) -> None:
    assert not seqno_out_of_order(seqno, -1)


def _robot() -> SimRobot:
    robot = make_sim(RRP)
    robot.command_mode = CommandMode.position_command
    robot.step()
    return robot


def _send(robot: SimRobot, seqno: int, target: np.ndarray, state_seqno: int | None = None) -> int:
    """Write one sample and step; the step's valid_position_command flag."""
    st_seqno = robot.robot_state.seqno if state_seqno is None else state_seqno
    robot.set_position_command(RobotJointCommand(seqno, st_seqno, target))
    return int(robot.step().flags) & VALID


def test_huge_seqno_does_not_lock_the_stream() -> None:
    robot = _robot()
    target = q_of(robot)
    assert _send(robot, 1, target)
    assert _send(robot, 2**63, target)  # a wild jump forward (a client bug): accepted ...
    assert _send(robot, 3, target)  # ... and the client's own count goes on (the reference: stuck)
    # A restarted counter near the top of uint64 (more than the window behind 3, modulo 2**64) ...
    assert _send(robot, SEQNO_MODULUS - STREAM_REORDER_WINDOW - 2, target)
    assert _send(robot, SEQNO_MODULUS - 2, target)
    assert _send(robot, SEQNO_MODULUS - 1, target)
    assert _send(robot, 0, target)  # ... wraps around and goes on
    assert _send(robot, 1, target)
    assert not _send(robot, 0, target)  # one behind: out of order
    assert not _send(robot, SEQNO_MODULUS - 1, target)  # two behind, across the wrap
    assert _send(robot, 1, target)  # the same sample again: accepted
    target = target + np.array([0.01, 0.0, 0.0])
    for k in range(2, 40):
        assert _send(robot, k, target)
    assert np.allclose(q_of(robot), target, atol=1e-6)


def test_huge_state_seqno_is_stale_and_the_stream_goes_on() -> None:
    robot = _robot()
    target = q_of(robot)
    assert _send(robot, 1, target)
    # A state_seqno nowhere near the current one is stale: ignored, and nothing else changes.
    assert not _send(robot, 2, target, state_seqno=SEQNO_MODULUS - 1)
    assert _send(robot, 3, target)


def test_new_client_restarts_the_seqno_check() -> None:
    robot = _robot()
    target = q_of(robot)
    assert _send(robot, 500, target)
    assert not _send(robot, 10, target)  # the same client going back 490: out of order
    robot.set_position_command(
        RobotJointCommand(10, robot.robot_state.seqno, target), new_client=True
    )
    assert int(robot.step().flags) & VALID  # another client, its own counter


def test_commands_stay_arrays() -> None:
    q = np.array([0.1, 0.2, 0.3])
    cmd = RobotJointCommand(1, 2, q)
    assert cmd.command is q  # taken as is: no copy, no list
    listed = RobotJointCommand(1, 2, [0.1, 0.2, 0.3])  # type: ignore[arg-type]
    assert isinstance(listed.command, np.ndarray) and listed.command.dtype == np.float64
    bad = RobotJointCommand(1, 2, ["x"])  # type: ignore[arg-type]
    assert bad.command.shape == (0,)  # never accepted: wrong length
