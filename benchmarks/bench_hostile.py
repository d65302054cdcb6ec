"""Loading a generated 60,000-link URDF (a branching tree with box geometry), against yourdfpy.

Run: ``python benchmarks/bench_hostile.py [--links N] [--bare]`` (needs the dev extra: yourdfpy).
A plain 6 MB URDF of this size once hung robotspec (the world's child lists were built in
quadratic time). One run: robotspec's ``load_urdf`` (bounded read, one checked walk, world
build) and yourdfpy's ``URDF.load`` (no meshes, no scene graph) on the same file, interleaved;
prints both times and the ratio (peer time / robotspec time: above 1 means robotspec is faster).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from rows import Row, add_json_flag, print_rows


def generated_urdf(n: int, *, bare: bool = False) -> str:
    """A tree of ``n`` links: each link hangs below link ``(i - 1) // 3`` by a revolute joint.

    ``bare``: links without geometry or mass (13 MB for 60,000 links, most of it joints).
    """
    parts = ['<robot name="big">']
    for i in range(n):
        if bare:
            parts.append(f'<link name="l{i}"/>')
            continue
        parts.append(
            f'<link name="l{i}"><visual><origin xyz="0 0 0.05" rpy="0 0 0"/><geometry>'
            '<box size="0.1 0.1 0.1"/></geometry></visual>'
            '<inertial><mass value="0.1"/></inertial></link>'
        )
    for i in range(1, n):
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{(i - 1) // 3}"/>'
            f'<child link="l{i}"/><origin xyz="0 0 0.1" rpy="0 0 0.1"/><axis xyz="0 0 1"/>'
            '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        )
    parts.append("</robot>\n")
    return "\n".join(parts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--links", type=int, default=60_000)
    parser.add_argument("--bare", action="store_true", help="links without geometry (13 MB)")
    add_json_flag(parser)
    args = parser.parse_args()

    import yourdfpy

    from robotspec.description.urdf import load_urdf

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "big.urdf"
        path.write_text(generated_urdf(args.links, bare=args.bare))
        size = path.stat().st_size
        t = time.perf_counter()
        world = load_urdf(path, meshes="keep")
        t_ours = time.perf_counter() - t
        t = time.perf_counter()
        peer = yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=False)
        t_ydp = time.perf_counter() - t
    assert len(world.bodies) == len(peer.robot.links) == args.links
    what = f"load_urdf, {args.links} links ({size / 1e6:.1f} MB)"
    rows = [Row(what, t_ours, "yourdfpy URDF.load, no meshes, no scene graph", t_ydp)]
    print_rows(rows, args.json)


if __name__ == "__main__":
    main()
