"""A simulated Robot Raconteur-style robot driver.

The subpackage follows the contract of ``robotraconteur_abstract_robot.AbstractRobot`` (the seed
document; upstream ``abstract_robot.py`` of robotraconteur-abstract-robot 0.2.2), with the
reference's defects fixed (listed in ``docs/driver.md``).
Modules, one job each:

* :mod:`~robotspec.driver.robot_info` -- the RobotInfo YAML as validated, located models (the
  models in :mod:`~robotspec.driver.robot_info_models`, the cross-field checks in
  :mod:`~robotspec.driver.robot_info_checks`);
* :mod:`~robotspec.driver.state` -- command modes, state flags and frozen state snapshots;
* :mod:`~robotspec.driver.commands` -- validation of client commands and the send-path guard;
* :mod:`~robotspec.driver.profiles` -- online motion profiles: jogs and stream limiting, with
  acceleration limits and braking before joint limits, on the real step duration;
* :mod:`~robotspec.driver.cartesian` -- joint rates for a twist (damped least squares) and
  whether the tool can follow it;
* :mod:`~robotspec.driver.trajectory` -- joint trajectory checks and interpolation;
* :mod:`~robotspec.driver.chain_kinematics` -- forward kinematics and Jacobians of H/P chains;
* :mod:`~robotspec.driver.clock` -- real and simulated clocks;
* :mod:`~robotspec.driver.loop_state` -- every field of the loop, set up from the RobotInfo;
* :mod:`~robotspec.driver.modes` -- the state machine (communication and robot-state checks);
* :mod:`~robotspec.driver.fill` -- the command of each step (jogs, trajectories, streams, guard);
* :mod:`~robotspec.driver.cartesian_jog` -- Cartesian jogs in the loop, and when they stop;
* :mod:`~robotspec.driver.state_fill` -- flags, TCP poses and the published snapshot;
* :mod:`~robotspec.driver.loop` -- the loop, its timing and the timestep pipeline;
* :mod:`~robotspec.driver.robot_driver` -- the driver base class: the seed's client API (command
  modes, status, enable, homing), with :mod:`~robotspec.driver.robot_driver_motion` (jogs,
  trajectories, streams) and :mod:`~robotspec.driver.robot_driver_tools` (tools, payloads);
* :mod:`~robotspec.driver.sim` -- the simulated robot with injectable faults;
* :mod:`~robotspec.driver.mujoco_plant` -- the simulated robot on MuJoCo physics (the
  ``mujoco`` extra), :mod:`~robotspec.driver.mujoco_model` the model it steps;
* :mod:`~robotspec.driver.script` -- YAML scenarios of client calls with expected outcomes.

Nothing here is imported by ``robotspec`` itself, so the CLI starts fast.
"""

from __future__ import annotations
