"""The driver on MuJoCo physics against the kinematic simulation, and the export it runs on.

Run: ``python benchmarks/bench_physics.py [--robot panda|pr2] [--rounds 3] [--seconds 8]``
(needs the ``mujoco`` extra and example-robot-data).

Measured in one process, one run:

* export: ``mjcf_export`` of the compiled robot (meshes converted to binary STL in memory), then
  MuJoCo compiling the plant model from the text and the mesh bytes
  (``robotspec.export.physics_model.plant_model``), the work ``drive --physics mujoco`` does
  before its first step; the robot's compile is not counted (the kinematic driver needs it too);
* real-time factor: the same workload, jogs out toward mid-range and back (``wait=True``) until
  ``--seconds`` of simulated time, at 100 Hz on a ``SimClock`` (as fast as the CPU goes), on
  ``SimRobot`` and on ``MujocoSimRobot``, taking turns each round; the factor is simulated
  seconds per wall second (median of the rounds);
* the physics run's figures: MuJoCo steps per driver period, the jog's end error (measured, the
  driver's arrival rule is 1e-4 rad) and the largest joint torque (the servos' forces).

The Panda runs with gravity on; the PR2's right arm with gravity compensated (its URDF's 30 N m
shoulder effort cannot hold the arm; the real one has a spring counterbalance).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np
from rows import Row, add_json_flag, print_rows

ROBOTS = {"panda": ("arm", False), "pr2": ("right_arm", True)}


def workload(robot: object, seconds: float) -> tuple[float, float, float]:
    """Jog out and back until ``seconds`` of clock time; (simulated s, end error, max |torque|)."""
    from robotspec.driver.sim import SimRobot

    assert isinstance(robot, SimRobot)
    robot.step()
    robot.step()
    lim = robot.limits
    home = robot.sim_position
    out = home + 0.3 * (0.5 * (lim.lower + lim.upper) - home)
    speed = 0.5 * lim.velocity
    robot.command_mode = "jog"
    worst_error = 0.0
    torque = 0.0
    target = out
    while robot._stopwatch_ellapsed_s() < seconds:
        robot.jog_freespace(target, speed, wait=True)
        st = robot.robot_state
        worst_error = max(worst_error, float(np.max(np.abs(st.joint_position - target))))
        torque = max(torque, float(np.max(np.abs(st.joint_effort))))
        target = home if target is out else out
    return robot._stopwatch_ellapsed_s(), worst_error, torque


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", choices=sorted(ROBOTS), default="panda")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=8.0)
    add_json_flag(parser)
    args = parser.parse_args()
    try:
        import mujoco
    except ImportError:
        sys.exit("needs MuJoCo: pip install 'robotspec[mujoco]'")
    from robotspec.compiler import compile_robot, resolve_spec
    from robotspec.driver.clock import SimClock
    from robotspec.driver.mujoco_plant import MujocoSimRobot
    from robotspec.driver.sim import SimRobot
    from robotspec.export.mjcf import mjcf_export
    from robotspec.export.physics_model import plant_model
    from robotspec.export.robotinfo import export_robot_chain
    from robotspec.export.urdf import joined_urdf
    from robotspec.spec.load import load_spec

    chain, compensated = ROBOTS[args.robot]
    path = resolve_spec(args.robot)
    robot = compile_robot(path)
    info = export_robot_chain(robot, chain).info
    names = [j.joint_identifier.name for j in info.joint_info]
    t0 = time.perf_counter()
    tree = joined_urdf(load_spec(path))
    export = mjcf_export(robot, tree, name="robot")
    t1 = time.perf_counter()
    plant = plant_model(robot, export, names, gravity_compensation=compensated)
    t2 = time.perf_counter()

    kin_rtf, mj_rtf, kin_wall, mj_wall = [], [], [], []
    figures = (0.0, 0.0, 0.0)
    substeps = 0.0
    for _ in range(args.rounds):
        kin = SimRobot(info, clock=SimClock())
        t = time.perf_counter()
        sim_s, _, _ = workload(kin, args.seconds)
        wall = time.perf_counter() - t
        kin_wall.append(wall)
        kin_rtf.append(sim_s / wall)
        phys = MujocoSimRobot(info, plant, clock=SimClock())
        t = time.perf_counter()
        sim_s, err, torque = workload(phys, args.seconds)
        wall = time.perf_counter() - t
        mj_wall.append(wall)
        mj_rtf.append(sim_s / wall)
        figures = (sim_s, err, torque)
        substeps = phys.substeps / max(1, phys.robot_state.seqno)
    load = os.getloadavg()[0]
    gravity = "gravity compensated" if compensated else "gravity on"
    rows = [
        Row(f"MJCF export of {args.robot} (meshes in memory)", t1 - t0, "target", None),
        Row("MuJoCo compiles the plant model", t2 - t1, "target", None),
        Row(
            f"{figures[0]:.1f} s of jogs, MuJoCo plant ({gravity})",
            statistics.median(mj_wall),
            "the kinematic simulation",
            statistics.median(kin_wall),
        ),
    ]
    print_rows(rows, args.json)
    if not args.json:
        print(
            f"real-time factor: MuJoCo plant {statistics.median(mj_rtf):.0f}x, kinematic "
            f"{statistics.median(kin_rtf):.0f}x (median of {args.rounds}; rounds "
            f"{', '.join(f'{x:.0f}' for x in mj_rtf)} / {', '.join(f'{x:.0f}' for x in kin_rtf)})"
        )
        print(
            f"MuJoCo {mujoco.__version__}: {substeps:.1f} steps per 10 ms period, "
            f"{plant.model.nbody} bodies, {plant.model.nv} DOF; jog end error at most "
            f"{figures[1]:.2g} rad; largest joint torque {figures[2]:.3g}; load average {load:.1f}"
        )


if __name__ == "__main__":
    main()
