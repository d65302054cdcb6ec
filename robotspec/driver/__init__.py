"""A simulated Robot Raconteur-style robot driver.

The subpackage follows the contract of ``robotraconteur_abstract_robot.AbstractRobot`` (the seed
document) and the behaviour recorded in the reference note, with the reference's defects fixed (see
:mod:`robotspec.driver.robot_driver` and ``docs/driver.md``). Modules, one job each:

* :mod:`~robotspec.driver.robot_info` -- the RobotInfo YAML as validated, located models;
* :mod:`~robotspec.driver.state` -- command modes, state flags and frozen state snapshots;
* :mod:`~robotspec.driver.commands` -- validation of client commands and the send-path guard;
* :mod:`~robotspec.driver.profiles` -- online jog profiles (time-optimal, limit-aware);
* :mod:`~robotspec.driver.trajectory` -- joint trajectory checks and interpolation;
* :mod:`~robotspec.driver.chain_kinematics` -- forward kinematics and Jacobians of H/P chains;
* :mod:`~robotspec.driver.clock` -- real and simulated clocks;
* :mod:`~robotspec.driver.loop` -- the timestep pipeline and state machine;
* :mod:`~robotspec.driver.robot_driver` -- the driver base class: the seed's client API;
* :mod:`~robotspec.driver.sim` -- the simulated robot with injectable faults;
* :mod:`~robotspec.driver.script` -- YAML scenarios of client calls with expected outcomes.

Nothing here is imported by ``robotspec`` itself, so the CLI starts fast.
"""

from __future__ import annotations
