"""World loading and forward kinematics on the PR2, against yourdfpy and pinocchio, one run.

Run: ``python benchmarks/bench_world.py`` (needs the dev extra: example-robot-data, pin).
Prints times and ratios (peer time / robotspec time: above 1 means robotspec is faster).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np
from rows import Row, add_json_flag, erd_share, print_rows


def best_of(fn: Callable[[], object], repeat: int, number: int = 1) -> float:
    """Median over ``repeat`` runs of the per-call time of ``number`` calls (seconds)."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t) / number)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--samples", type=int, default=10_000)
    add_json_flag(parser)
    args = parser.parse_args()

    import pinocchio as pin
    import yourdfpy

    from robotspec.description.urdf import load_urdf
    from robotspec.model.kinematics import Kinematics

    share = erd_share()
    urdf = share / "robots/pr2_description/urdf/pr2.urdf"
    rows: list[tuple[str, float, str, float]] = []

    # --- loading
    t_ours = best_of(lambda: load_urdf(urdf), 7)
    t_ours_keep = best_of(lambda: load_urdf(urdf, meshes="keep"), 7)
    t_ydp = best_of(lambda: yourdfpy.URDF.load(str(urdf), load_meshes=False), 7)
    t_ydp_bare = best_of(
        lambda: yourdfpy.URDF.load(str(urdf), load_meshes=False, build_scene_graph=False), 7
    )
    t_pin = best_of(lambda: pin.buildModelFromUrdf(str(urdf)), 7)
    rows += [
        ("load world (meshes resolved)", t_ours, "yourdfpy URDF.load(load_meshes=False)", t_ydp),
        ("load world (meshes resolved)", t_ours, "yourdfpy, no scene graph", t_ydp_bare),
        ("load world (meshes resolved)", t_ours, "pinocchio buildModelFromUrdf", t_pin),
        (
            "load world (mesh URIs kept)",
            t_ours_keep,
            "yourdfpy URDF.load(load_meshes=False)",
            t_ydp,
        ),
    ]

    world = load_urdf(urdf)
    kin = Kinematics(world)
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    frame_ids = [model.getFrameId(b.name) for b in world.bodies]
    rng = np.random.default_rng(0)
    n_dof = len(world.degrees_of_freedom)
    q = rng.uniform(-1, 1, n_dof)
    qp = pin.neutral(model)

    def pin_fk() -> None:
        pin.forwardKinematics(model, data, qp)
        pin.updateFramePlacements(model, data)

    def pin_fk_read() -> np.ndarray:
        pin_fk()
        return np.array([data.oMf[i].homogeneous for i in frame_ids])

    # --- one configuration, all bodies
    t_fk = best_of(lambda: kin.forward(q), 7, 200)
    rows += [
        (
            "FK all bodies, 1 config",
            t_fk,
            "pinocchio FK+frames (poses left in data)",
            best_of(pin_fk, 7, 200),
        ),
        (
            "FK all bodies, 1 config",
            t_fk,
            "pinocchio FK+frames, poses read out",
            best_of(pin_fk_read, 7, 200),
        ),
    ]
    # --- one 7-joint chain
    chain = kin.chain("torso_lift_link", "r_wrist_roll_link")
    t_chain = best_of(lambda: chain.fk(q), 7, 500)
    rows.append(("FK of the 7-joint arm chain", t_chain, "(target: under 50 us)", 50e-6))
    t_jac = best_of(lambda: chain.jacobian(q), 7, 500)
    wrist = model.getFrameId("r_wrist_roll_link")
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    rows.append(
        (
            "Jacobian of the 7-joint arm chain",
            t_jac,
            "pinocchio computeFrameJacobian (wrist, world-aligned)",
            best_of(lambda: pin.computeFrameJacobian(model, data, qp, wrist, lwa), 7, 500),
        )
    )

    # --- batch
    qs = rng.uniform(-1, 1, (args.samples, n_dof))
    t_batch = best_of(lambda: kin.forward_batch(qs), 5)

    def pin_loop() -> None:
        for _ in range(args.samples):
            pin_fk()

    def pin_loop_read() -> None:
        out = np.empty((args.samples, len(frame_ids), 4, 4))
        for k in range(args.samples):
            pin_fk()
            for j, i in enumerate(frame_ids):
                out[k, j] = data.oMf[i].homogeneous

    rows += [
        (
            f"batched FK, {args.samples} configs",
            t_batch,
            "pinocchio loop (poses left in data)",
            best_of(pin_loop, 3),
        ),
        (
            f"batched FK, {args.samples} configs",
            t_batch,
            "pinocchio loop, poses read out",
            best_of(pin_loop_read, 1),
        ),
    ]

    if not args.json:
        print(f"PR2 (example-robot-data): {len(world.bodies)} bodies, {n_dof} DOF\n")
    print_rows([Row(*r) for r in rows], args.json)


if __name__ == "__main__":
    main()
