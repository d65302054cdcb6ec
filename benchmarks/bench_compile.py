"""Compiling the PR2 spec end to end, against pinocchio building the same model, in one run.

robotspec: spec YAML -> URDF world + SRDF + every semantic part, checks and collision pairs
(``compile_robot("pr2")``). pinocchio: ``buildModelFromUrdf`` + ``buildGeomFromUrdf``
(COLLISION, with package dirs) + ``addAllCollisionPairs`` + ``removeCollisionPairs`` (the SRDF).
Neither side caches anything between runs. Target: robotspec no slower than pinocchio.

Second line: the composed ``b1_ur5_allegro`` (three parts welded, semantics merged) against
pinocchio loading the same robot already joined (``robotspec export bundle``'s URDF and SRDF):
the cost of composing on every load.

Run: ``python benchmarks/bench_compile.py [--repeat N] [--profile]`` (needs the dev extra:
example-robot-data, pin). Prints medians and the ratio pinocchio / robotspec (above 1 means
robotspec is faster); ``--profile`` adds robotspec's top costs (cProfile, cumulative).
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
from pathlib import Path

from rows import Row, add_json_flag, erd_share, median_times, print_rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--profile", action="store_true", help="cProfile robotspec's compile")
    add_json_flag(parser)
    args = parser.parse_args()
    say = (lambda *a, **k: None) if args.json else print

    import pinocchio as pin

    from robotspec.compiler import compile_robot

    share = erd_share()
    pr2 = share / "robots" / "pr2_description"
    urdf, srdf = pr2 / "urdf" / "pr2.urdf", pr2 / "srdf" / "pr2.srdf"
    package_dirs = [str(share / "robots"), str(share.parent)]

    def ours() -> object:
        return compile_robot("pr2")

    def pinocchio() -> object:
        model = pin.buildModelFromUrdf(str(urdf))
        geom = pin.buildGeomFromUrdf(
            model, str(urdf), pin.GeometryType.COLLISION, package_dirs=package_dirs
        )
        geom.addAllCollisionPairs()
        pin.removeCollisionPairs(model, geom, str(srdf))
        return model, geom

    robot = ours()
    model, geom = pinocchio()  # type: ignore[misc]
    say(
        f"robotspec: {len(robot.bodies)} bodies, {len(robot.kinematic_chains)} chains, "  # type: ignore[attr-defined]
        f"{len(robot.disabled_collision_pairs)} disabled pairs (with geometry)"  # type: ignore[attr-defined]
    )
    say(
        f"pinocchio: {model.njoints} joints, {geom.ngeoms} collision geometries, "
        f"{len(geom.collisionPairs)} collision pairs after the SRDF"
    )
    t_ours, t_pin = median_times([ours, pinocchio], args.repeat)
    rows = [
        Row(
            "compile PR2 spec (URDF + SRDF + spec)",
            t_ours,
            "pinocchio model+geom+SRDF pairs",
            t_pin,
        )
    ]

    import tempfile

    from robotspec.compiler import check_spec
    from robotspec.export.urdf import bundle

    folder = Path(tempfile.mkdtemp(prefix="bench-compose-"))
    out = bundle(check_spec("b1_ur5_allegro"), name="b1")
    (folder / "b1.urdf").write_text(out.urdf)
    (folder / "b1.srdf").write_text(out.srdf)

    def composed() -> object:
        return compile_robot("b1_ur5_allegro")

    def pin_joined() -> object:
        path = str(folder / "b1.urdf")
        model = pin.buildModelFromUrdf(path)
        geom = pin.buildGeomFromUrdf(
            model, path, pin.GeometryType.COLLISION, package_dirs=package_dirs
        )
        geom.addAllCollisionPairs()
        pin.removeCollisionPairs(model, geom, str(folder / "b1.srdf"))
        return model, geom

    t_comp, t_pin_joined = median_times([composed, pin_joined], args.repeat)
    rows.append(
        Row(
            "compile composed b1_ur5_allegro (3 parts)",
            t_comp,
            "pinocchio, the exported joined files",
            t_pin_joined,
        )
    )
    print_rows(rows, args.json)
    say(f"(medians of {args.repeat}, calls interleaved; ratio = pinocchio / robotspec)")

    if args.profile:
        prof = cProfile.Profile()
        prof.enable()
        for _ in range(5):
            ours()
        prof.disable()
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("cumulative").print_stats(25)
        print(out.getvalue())
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("tottime").print_stats(15)
        print(out.getvalue())


if __name__ == "__main__":
    main()
