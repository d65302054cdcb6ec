"""The simulated driver with MuJoCo as the plant: position servos follow the kinematic profile.

Why keep the kinematic simulation at all: its profile (velocity and acceleration limits, soft
limits at the joint limits, the command watchdog, homing, faults) is what a real arm's
controller does to the driver's commands before its servos see them. Here it becomes the
*reference*: every period :class:`MujocoSimRobot` integrates it exactly as
:class:`~robotspec.driver.sim.SimRobot` does, then MuJoCo steps the robot (its own timestep,
several substeps per period, the reference interpolated across them) with the reference as the
position servos' target, and the state reports what MuJoCo measured: joint positions,
velocities and torques (the servos' actuator forces), gravity on.

The servo target carries the controller's feed-forward, as an industrial arm's joint
controller does: the reference velocity times the servo's damping, and the bias torques
(gravity, Coriolis) MuJoCo computed at the last substep, divided by the stiffness. Without it
a position servo tuned from the joint's inertia sits ``gravity / kp`` short of its target (the
Panda's shoulder: 8 mrad) and lags ``2 v / omega`` behind a moving one, and no waiting jog would
ever arrive within the driver's 1e-4 rad. Gravity compensation (MuJoCo's ``gravcomp``, the
``--gravity-compensation`` option) cancels gravity on the bodies instead; the feed-forward then
leaves it out. A joint whose effort cannot hold its links saturates and sags, as the real one
would. Servos outside the chain (joints the plant model did not weld) hold their default
targets with the same bias feed-forward.

E-stop, drive error, disabled drives and a frozen controller hold the arm where it was measured
when the stop came (the reference jumps there; the servos hold it against gravity, like a
brake), and motion resumes from there.

Time: MuJoCo advances by the same step duration the reference integrates
(:func:`~robotspec.driver.clock.step_duration`), so a stalled loop is a pause for the physics as
it is for the profile, and a run on a :class:`~robotspec.driver.clock.SimClock` gives the same
numbers every time.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.clock import Clock, step_duration
from robotspec.driver.mujoco_model import PlantModel
from robotspec.driver.robot_info import RobotInfo
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import EstopSource
from robotspec.errors import RobotSpecError

__all__ = ["MujocoSimRobot"]


class MujocoSimRobot(SimRobot):
    """A :class:`SimRobot` whose arm is a MuJoCo model under position servos.

    Args:
        robot_info: the robot (its joints are the plant's chain joints, in order).
        plant: the MuJoCo model (:func:`~robotspec.export.physics_model.plant_model`).
        clock, update_period, initial_position, homing_speed, command_timeout: as
            :class:`SimRobot`.
    """

    def __init__(
        self,
        robot_info: RobotInfo,
        plant: PlantModel,
        *,
        clock: Clock | None = None,
        update_period: float = 0.01,
        initial_position: Any = None,
        homing_speed: float = 0.25,
        command_timeout: float = SimRobot.DEFAULT_COMMAND_TIMEOUT,
    ) -> None:
        super().__init__(
            robot_info,
            clock=clock,
            update_period=update_period,
            initial_position=initial_position,
            homing_speed=homing_speed,
            command_timeout=command_timeout,
        )
        import mujoco  # type: ignore[import-untyped, unused-ignore]

        if len(plant.actuator) != self._joint_count:
            raise RobotSpecError(
                f"the plant drives {len(plant.actuator)} joints, the RobotInfo has "
                f"{self._joint_count}: build the plant from the same chain"
            )
        self._mujoco = mujoco
        self._plant = plant
        model = plant.model
        self._model = model
        data = mujoco.MjData(model)
        self._data = data
        self._qadr = np.array(plant.joint_qpos, dtype=np.intp)
        self._dadr = np.array(plant.joint_dof, dtype=np.intp)
        self._act = np.array(plant.actuator, dtype=np.intp)
        self._kv_over_kp = plant.kv / plant.kp
        self._inv_kp = 1.0 / plant.kp
        # The servos outside the chain hold their default targets, with the same bias feed-forward.
        chain = set(plant.actuator)
        held = [a for a in range(model.nu) if a not in chain]
        self._held = np.array(held, dtype=np.intp)
        self._held_dof = np.array(
            [model.jnt_dofadr[model.actuator_trnid[a, 0]] for a in held], dtype=np.intp
        )
        self._held_ctrl = np.array(plant.ctrl0[held], dtype=np.float64)
        self._held_inv_kp = np.array([1.0 / model.actuator_gainprm[a, 0] for a in held])
        data.qpos[:] = plant.qpos0
        data.qpos[self._qadr] = self._q
        data.ctrl[:] = plant.ctrl0
        data.ctrl[self._act] = self._q
        mujoco.mj_forward(model, data)
        self._timestep = float(model.opt.timestep)
        #: Step time not yet simulated (less than one MuJoCo timestep).
        self._owed = 0.0
        self._holding: F64 | None = None
        #: MuJoCo steps taken so far (benchmarks and tests read it).
        self.substeps = 0

    # ------------------------------------------------------------------ the plant

    @property
    def plant(self) -> PlantModel:
        """The MuJoCo model the driver steps."""
        return self._plant

    @property
    def plant_data(self) -> Any:
        """MuJoCo's ``MjData`` of the plant (read it between steps, never write it)."""
        return self._data

    @property
    def sim_position(self) -> F64:
        """The reference: where the kinematic profile has the arm, the servos' target (a copy).

        The arm itself is :attr:`measured_position` (what the state reports).
        """
        return self._q.copy()

    @property
    def measured_position(self) -> F64:
        """The chain's joint positions as MuJoCo has them now (a copy)."""
        return np.array(self._data.qpos[self._qadr], dtype=np.float64)

    @property
    def measured_velocity(self) -> F64:
        """The chain's joint velocities as MuJoCo has them now (a copy)."""
        return np.array(self._data.qvel[self._dadr], dtype=np.float64)

    @property
    def measured_effort(self) -> F64:
        """The chain's servo forces (N m or N) at the last MuJoCo step (a copy)."""
        return np.array(self._data.actuator_force[self._act], dtype=np.float64)

    def _stopped_now(self) -> bool:
        return (
            self._sim_estop != EstopSource.none
            or self._sim_error
            or not self._sim_enabled
            or self._frozen
        )

    def _integrate(self, now: float) -> None:
        """The reference over the last period (SimRobot's), then MuJoCo over the same time."""
        last = self._sim_last_t
        start = self._q.copy()
        if self._stopped_now():
            if self._holding is None:
                lim = self._limits
                self._holding = np.clip(self.measured_position, lim.lower, lim.upper)
            # the reference waits where the arm stopped, so motion resumes from there
            self._q[:] = self._holding
            start = self._holding
        else:
            self._holding = None
        super()._integrate(now)
        if last is None:
            return
        dt = step_duration(now, last, self._update_period)
        if dt > 0.0:
            self._advance(dt, start, self._q.copy(), self._v.copy())

    def _advance(self, dt: float, ref0: F64, ref1: F64, vref: F64) -> None:
        """Step MuJoCo over ``dt``, the servo targets moving from ``ref0`` to ``ref1``."""
        self._owed += dt
        n = int(self._owed / self._timestep + 1e-9)
        self._owed -= n * self._timestep
        mujoco, model, data = self._mujoco, self._model, self._data
        dadr, act = self._dadr, self._act
        velocity_ff = self._kv_over_kp * vref
        delta = ref1 - ref0
        held, held_dof = self._held, self._held_dof
        for k in range(1, n + 1):
            bias = data.qfrc_bias[dadr] - data.qfrc_gravcomp[dadr]
            data.ctrl[act] = ref0 + (k / n) * delta + velocity_ff + bias * self._inv_kp
            if held.size:
                bias = data.qfrc_bias[held_dof] - data.qfrc_gravcomp[held_dof]
                data.ctrl[held] = self._held_ctrl + bias * self._held_inv_kp
            mujoco.mj_step(model, data)
        self.substeps += n

    def _read_feedback(self, now: float) -> None:
        """Step the plant, then report what MuJoCo measured (unless feedback is lost).

        Positions are reported within the joint limits: MuJoCo's limits are soft constraints,
        so a link pressed against its stop (the Panda's fourth joint at home, under gravity)
        sits a few microradians past it, and a client that starts a trajectory from the state
        it reads would have its first waypoint refused as outside the limits. A real
        controller's encoders read against a hard stop; the soft overlap is the simulator's.
        """
        super()._read_feedback(now)
        if self._feedback_lost:
            return
        data = self._data
        lim = self._limits
        self._joint_position[:] = np.clip(data.qpos[self._qadr], lim.lower, lim.upper)
        self._joint_velocity[:] = data.qvel[self._dadr]
        self._joint_effort[:] = data.actuator_force[self._act]
