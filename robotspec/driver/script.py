"""Scenario scripts: YAML lists of client calls, each with the outcome expected.

Why: a user can rehearse a sequence of driver calls (modes, jogs, trajectories, faults) against
the simulator, with the reactions they expect, before running it on a robot. A mismatch is a
located error (``scenario.yaml:12:3: error: step 4 (command_mode): expected ...``).

A scenario is a list of steps; each step has exactly one of ``call``, ``wait``, ``fault``,
``clear_fault`` or ``check``::

    - call: command_mode
      args: {mode: jog}
    - call: jog_freespace
      args: {joint_position: [0.2, 0, 0, 0, 0, 0], max_velocity: [1, 1, 1, 1, 1, 1]}
    - call: command_mode
      args: {mode: trajectory}
      expect: {error: InvalidOperation, message: 'Must switch to "halt"'}
    - fault: drive_error
    - wait: 0.1
    - check: {command_mode: invalid_state, flags: [error, enabled]}
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from robotspec.driver.errors import error_kind
from robotspec.driver.robot_driver import RobotDriver
from robotspec.driver.robot_info import PayloadInfo, Pose, ToolInfo
from robotspec.driver.sim import Fault, SimRobot
from robotspec.driver.state import StateFlags
from robotspec.driver.stretch import Stretch
from robotspec.driver.trajectory import JointTrajectory, Waypoint
from robotspec.errors import RobotSpecError, RobotSpecErrors, closest_names
from robotspec.files.validation import validation_errors
from robotspec.files.yamlio import LocatedYaml, load_yaml

__all__ = ["CALLS", "Scenario", "StepResult", "load_scenario", "run_scenario"]

#: Client calls a scenario may make: name -> (required args, optional args).
CALLS: dict[str, tuple[frozenset[str], frozenset[str]]] = {
    "command_mode": (frozenset({"mode"}), frozenset()),
    "halt": (frozenset(), frozenset()),
    "speed_ratio": (frozenset({"value"}), frozenset()),
    "enable": (frozenset(), frozenset()),
    "disable": (frozenset(), frozenset()),
    "reset_errors": (frozenset(), frozenset()),
    "home": (frozenset(), frozenset()),
    "jog_freespace": (frozenset({"joint_position", "max_velocity"}), frozenset({"wait"})),
    "jog_joint": (frozenset({"joint_velocity", "timeout"}), frozenset({"wait"})),
    "jog_cartesian": (frozenset({"velocity", "timeout"}), frozenset({"wait", "chain"})),
    "execute_trajectory": (
        frozenset(),
        frozenset({"waypoints", "to", "duration", "joint_names"}),
    ),
    "tool_attached": (frozenset({"tool"}), frozenset({"chain"})),
    "tool_detached": (frozenset(), frozenset({"chain", "name"})),
    "payload_attached": (frozenset({"payload"}), frozenset({"chain", "pose"})),
    "payload_detached": (frozenset(), frozenset({"chain", "name"})),
}


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Expect(_Model):
    """The outcome a call should have: an error kind (and message part), or a status."""

    error: (
        Literal[
            "InvalidArgument",
            "InvalidOperation",
            "OperationAborted",
            "OperationFailed",
            "NotImplemented",
        ]
        | None
    ) = None
    message: str | None = None
    status: Literal["complete", "running", "queued"] | None = None


class Check(_Model):
    """State to compare after a step; every given field must match."""

    command_mode: str | None = None
    flags: tuple[str, ...] | None = None
    flags_exact: bool = False
    joint_position: tuple[float, ...] | None = None
    tolerance: float = Field(default=1e-3, gt=0.0)
    error_message: str | None = None


class Step(_Model):
    """One scenario step (exactly one of call, wait, fault, clear_fault, check)."""

    call: str | None = None
    args: dict[str, Any] = Field(default_factory=dict)
    expect: Literal["ok"] | Expect = "ok"
    wait: float | None = Field(default=None, ge=0.0)
    fault: Fault | None = None
    clear_fault: Fault | Literal["all"] | None = None
    check: Check | None = None

    @model_validator(mode="after")
    def _one_action(self) -> Step:
        given = [
            k
            for k in ("call", "wait", "fault", "clear_fault", "check")
            if getattr(self, k) is not None
        ]
        if len(given) != 1:
            raise ValueError(
                "a step needs exactly one of call, wait, fault, clear_fault or check"
                + (f" (got {', '.join(given)})" if given else "")
            )
        return self


class Scenario(_Model):
    """A whole scenario file."""

    steps: tuple[Step, ...]


@dataclass(frozen=True)
class StepResult:
    """What happened at one step."""

    index: int
    line: int | None
    description: str
    ok: bool
    detail: str = ""
    #: What the step did that the run should show though it was as expected (a trajectory
    #: slowed to stay within the joint limits).
    note: str = ""


@dataclass(frozen=True)
class LoadedScenario:
    """A validated scenario and the YAML positions of its steps."""

    scenario: Scenario
    doc: LocatedYaml

    def line_of(self, index: int) -> int | None:
        """The 1-based line of step ``index``."""
        return self.doc.position(("steps", index))[0]


def load_scenario(path: str | Path) -> LoadedScenario:
    """Load and validate a scenario; unknown calls and arguments are located errors."""
    raw = load_yaml(path)
    if not isinstance(raw.data, list):
        raise RobotSpecError("a scenario must be a YAML list of steps", file=raw.file, line=1)
    # Steps live under a synthetic "steps" key so pydantic locations map back to the YAML.
    doc = LocatedYaml(
        data={"steps": raw.data},
        file=raw.file,
        marks={("steps", *k): v for k, v in raw.marks.items()},
        key_marks={("steps", *k): v for k, v in raw.key_marks.items()},
    )
    try:
        scenario = Scenario.model_validate(doc.data)
    except ValidationError as exc:
        raise validation_errors(exc, doc, Scenario) from None
    errors: list[RobotSpecError] = []
    for i, step in enumerate(scenario.steps):
        if step.call is None:
            continue
        if step.call not in CALLS:
            line, col = doc.position(("steps", i, "call"))
            near = closest_names(step.call, CALLS)
            hint = f"; did you mean '{near[0]}'?" if near else ""
            errors.append(
                RobotSpecError(
                    f"step {i + 1}: unknown call '{step.call}'{hint}",
                    file=doc.file,
                    line=line,
                    column=col,
                    name=step.call,
                    suggestions=near,
                )
            )
            continue
        required, optional = CALLS[step.call]
        for key in step.args:
            if key not in required | optional:
                line, col = doc.key_position(("steps", i, "args", key))
                near = closest_names(key, required | optional)
                hint = f"; did you mean '{near[0]}'?" if near else ""
                errors.append(
                    RobotSpecError(
                        f"step {i + 1}: {step.call} has no argument '{key}'{hint}",
                        file=doc.file,
                        line=line,
                        column=col,
                    )
                )
        for key in sorted(required - set(step.args)):
            line, col = doc.position(("steps", i))
            errors.append(
                RobotSpecError(
                    f"step {i + 1}: {step.call} needs argument '{key}'",
                    file=doc.file,
                    line=line,
                    column=col,
                )
            )
    if errors:
        if len(errors) == 1:
            raise errors[0]
        raise RobotSpecErrors(errors, summary=f"{doc.file}: {len(errors)} problems")
    return LoadedScenario(scenario=scenario, doc=doc)


def _trajectory(driver: RobotDriver, args: dict[str, Any]) -> JointTrajectory:
    names = tuple(args.get("joint_names", ()))
    if "waypoints" in args:
        wps = []
        for w in args["waypoints"]:
            if isinstance(w, dict):
                wps.append(
                    Waypoint(
                        joint_position=tuple(float(x) for x in w["joint_position"]),
                        time_from_start=float(w["time_from_start"]),
                        joint_velocity=tuple(float(x) for x in w.get("joint_velocity", ())),
                    )
                )
            else:
                t, *q = w
                wps.append(Waypoint(joint_position=tuple(float(x) for x in q), time_from_start=t))
        return JointTrajectory(joint_names=names, waypoints=tuple(wps))
    start = driver.robot_state.joint_position
    end = args.get("to", start)
    return JointTrajectory.smooth_move(start, end, float(args.get("duration", 1.0)))


def _do_call(
    driver: RobotDriver, name: str, args: dict[str, Any]
) -> tuple[str | None, Stretch | None]:
    """Perform one call; return a status name and any stretch for trajectories."""
    wait = bool(args.get("wait", True))
    chain = int(args.get("chain", 0))
    if name == "command_mode":
        driver.command_mode = args["mode"]
    elif name == "halt":
        driver.halt()
    elif name == "speed_ratio":
        driver.speed_ratio = args["value"]
    elif name == "enable":
        driver.enable()
    elif name == "disable":
        driver.disable()
    elif name == "reset_errors":
        driver.reset_errors()
    elif name == "home":
        driver.home(wait=True)
    elif name == "jog_freespace":
        driver.jog_freespace(args["joint_position"], args["max_velocity"], wait)
    elif name == "jog_joint":
        driver.jog_joint(args["joint_velocity"], args["timeout"], wait)
    elif name == "jog_cartesian":
        driver.jog_cartesian(args["velocity"], args["timeout"], wait, chain)
    elif name == "execute_trajectory":
        gen = driver.execute_trajectory(_trajectory(driver, args))
        status = None
        stretch = None
        for st in gen:
            status = st.action_status.name
            stretch = st.stretch
        return status, stretch
    elif name == "tool_attached":
        driver.tool_attached(chain, ToolInfo.model_validate(args["tool"]))
    elif name == "tool_detached":
        driver.tool_detached(chain, str(args.get("name", "")))
    elif name == "payload_attached":
        pose = Pose.model_validate(args["pose"]) if "pose" in args else None
        driver.payload_attached(chain, PayloadInfo.model_validate(args["payload"]), pose)
    elif name == "payload_detached":
        driver.payload_detached(chain, str(args.get("name", "")))
    return None, None


def _compare(expect: Literal["ok"] | Expect, status: str | None, exc: Exception | None) -> str:
    """Empty when the outcome matches, else what differs."""
    got = "ok" if exc is None else f"{error_kind(exc)}: {getattr(exc, 'message', str(exc))}"
    if expect == "ok" or (isinstance(expect, Expect) and expect.error is None):
        if exc is not None:
            return f"expected ok, got {got}"
        if isinstance(expect, Expect) and expect.status and status != expect.status:
            return f"expected status {expect.status}, got {status}"
        return ""
    assert isinstance(expect, Expect)
    if exc is None:
        return f"expected {expect.error}, got ok"
    if error_kind(exc) != expect.error:
        return f"expected {expect.error}, got {got}"
    if expect.message and expect.message not in str(getattr(exc, "message", exc)):
        return f"expected message containing {expect.message!r}, got {got}"
    return ""


def _check(driver: RobotDriver, check: Check) -> str:
    st = driver.robot_state
    problems: list[str] = []
    if check.command_mode is not None and st.command_mode.name != check.command_mode:
        problems.append(f"command_mode is {st.command_mode.name}, expected {check.command_mode}")
    if check.flags is not None:
        want = StateFlags.none
        for name in check.flags:
            if name not in StateFlags.__members__:
                return f"unknown flag '{name}'"
            want |= StateFlags[name]
        have = st.flags
        if (check.flags_exact and have != want) or (have & want) != want:
            problems.append(f"flags are {_flag_text(have)}, expected {_flag_text(want)}")
    if check.joint_position is not None:
        q = np.array(check.joint_position)
        if st.joint_position.shape != q.shape:
            problems.append(f"joint_position is {list(st.joint_position)}")
        elif float(np.max(np.abs(st.joint_position - q))) > check.tolerance:
            got = ", ".join(f"{x:.4g}" for x in st.joint_position)
            problems.append(f"joint_position is [{got}], not within {check.tolerance} of expected")
    if check.error_message is not None and check.error_message not in st.error_message:
        problems.append(f"error message is {st.error_message!r}")
    return "; ".join(problems)


def _flag_text(flags: StateFlags) -> str:
    names = [f.name for f in StateFlags if f.value and f.name and (flags & f) == f]
    return "|".join(names) or "none"


def _describe(step: Step) -> str:
    if step.call is not None:
        return step.call
    if step.wait is not None:
        return f"wait {step.wait:g} s"
    if step.fault is not None:
        return f"fault {step.fault.value}"
    if step.clear_fault is not None:
        return f"clear_fault {getattr(step.clear_fault, 'value', step.clear_fault)}"
    return "check"


def run_scenario(
    driver: SimRobot,
    loaded: LoadedScenario,
    on_result: Callable[[StepResult], None] | None = None,
) -> list[StepResult]:
    """Run every step against ``driver``; mismatches are recorded, not raised."""
    results: list[StepResult] = []
    for i, step in enumerate(loaded.scenario.steps):
        line = loaded.line_of(i)
        desc = _describe(step)
        detail = ""
        note = ""
        if step.call is not None:
            exc: Exception | None = None
            status: str | None = None
            try:
                status, stretch = _do_call(driver, step.call, step.args)
                if stretch is not None:
                    note = stretch.describe(driver.joint_names)
            except RobotSpecError as e:
                exc = e
            except (KeyError, TypeError, ValueError) as e:
                exc = e
            detail = _compare(step.expect, status, exc)
            driver.step()
        elif step.wait is not None:
            driver.run_for(step.wait)
        elif step.fault is not None:
            driver.inject_fault(step.fault)
            driver.step()
        elif step.clear_fault is not None:
            driver.clear_fault(None if step.clear_fault == "all" else step.clear_fault)
            driver.step()
        elif step.check is not None:
            detail = _check(driver, step.check)
        result = StepResult(i + 1, line, desc, not detail, detail, note)
        results.append(result)
        if on_result is not None:
            on_result(result)
    return results


def mismatch_errors(loaded: LoadedScenario, results: list[StepResult]) -> list[RobotSpecError]:
    """The failed steps as located errors."""
    return [
        RobotSpecError(
            f"step {r.index} ({r.description}): {r.detail}",
            file=loaded.doc.file,
            line=r.line,
        )
        for r in results
        if not r.ok
    ]
