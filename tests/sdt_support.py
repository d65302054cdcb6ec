"""What the SDT bridge tests share: SDT imported (or the test skipped), SDT's own robots.

SDT 26.7.0 from PyPI cannot run its own hand-written robots as shipped; this module is the one
place the tests make up for it, each stand-in with its reason:

- giskardpy is not on PyPI, and SDT imports ``giskardpy.utils.utils.create_path`` while it
  loads its robot classes: ``tests/sdt_stand_ins/giskardpy`` has that one helper. It is put on
  ``sys.path`` only when no real giskardpy is installed (real SDT users have it).
- SDT's wheel lacks its ``resources/`` folder, so the hand-written classes' collision rules
  (which read ``resources/collision_configs/<robot>.srdf``) cannot be set up:
  :func:`hand_written` skips exactly that step (``_setup_collision_rules``); the parts,
  hardware interfaces, states and velocity limits compared here are all built.
- The same missing folder holds ``resources/obj/cylinder.obj``, the mesh SDT's Bullet collision
  sync loads for *every* cylinder of a world (HSRB has some; PR2 has none), so any world with
  a cylinder fails to build: :func:`stand_in_cylinder` points SDT's ``create_cylinder_shape`` at
  a unit cylinder (diameter 1, height 1) made by trimesh.
- SDT's package resolver takes a ROS_PACKAGE_PATH entry only if the entry ends with the
  package's name: :func:`package_path` lists every package folder itself.
- SDT's URDF parser refuses a revolute joint without ``<axis>`` (HSRB has three), which URDF
  defines as ``1 0 0``: :func:`sdt_world_from_urdf` writes that default in before SDT parses.

robotspec's bridge needs none of these: it builds the SDT world from robotspec's own model.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import pytest

STAND_INS = Path(__file__).resolve().parent / "sdt_stand_ins"
REASON = (
    "semantic-digital-twin is not installed; the SDT bridge tests run in the SDT environment "
    "(pip install -e '.[dev,sdt]', see docs/sdt.md)"
)


def require_sdt() -> None:
    """Skip unless SDT is installed; make its undeclared giskardpy import work."""
    if importlib.util.find_spec("semantic_digital_twin") is None:
        if os.environ.get("ROBOTSPEC_REQUIRE_SDT"):  # CI's SDT environment: never a skip
            pytest.fail(f"ROBOTSPEC_REQUIRE_SDT is set but {REASON}")
        pytest.skip(REASON)
    if importlib.util.find_spec("giskardpy") is None and str(STAND_INS) not in sys.path:
        sys.path.append(str(STAND_INS))


@pytest.fixture(scope="session")
def sdt(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """SDT importable with its stand-ins; generated classes' recipes kept in a temporary folder."""
    require_sdt()
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ROBOTSPEC_SDT_CLASSES", str(tmp_path_factory.mktemp("sdt-classes")))
        stand_in_cylinder(tmp_path_factory.mktemp("sdt-cylinder"), mp)
        yield


def stand_in_cylinder(folder: Path, mp: pytest.MonkeyPatch) -> None:
    """SDT's cylinder shape from a unit cylinder written to ``folder`` (see the docstring)."""
    import trimesh
    from semantic_digital_twin.collision_checking import pybullet_collision_detector as pcd

    mesh = folder / "cylinder.obj"
    if not mesh.is_file():
        trimesh.creation.cylinder(radius=0.5, height=1.0, sections=32).export(mesh)
    bullet = pcd.bullet

    def create_cylinder_shape(diameter: float, height: float) -> Any:
        scaling = bullet.Vector3(diameter, diameter, height) * 0.996  # as SDT's own
        return bullet.load_convex_shape(str(mesh), single_shape=True, scaling=scaling)

    mp.setattr(pcd, "create_cylinder_shape", create_cylinder_shape)


def package_path(folders: Iterable[Path]) -> str:
    """A ROS_PACKAGE_PATH SDT can use: each package folder itself (see the module docstring)."""
    out: list[str] = []
    for folder in folders:
        out.extend(str(p) for p in sorted(folder.iterdir()) if (p / "package.xml").is_file())
        if (folder / "package.xml").is_file() or folder.name == "example-robot-data":
            out.append(str(folder))
    return os.pathsep.join(out)


def urdf_with_default_axes(text: str) -> str:
    """The URDF with URDF's default ``<axis xyz="1 0 0"/>`` written where a joint has none."""
    from lxml import etree

    root = etree.fromstring(text.encode())
    for joint in root.iter("joint"):
        moving = joint.get("type") in ("revolute", "continuous", "prismatic")
        if moving and joint.find("axis") is None:
            etree.SubElement(joint, "axis", xyz="1 0 0")
    return etree.tostring(root, encoding="unicode")


def sdt_world_from_urdf(
    urdf: Path, *, odom: str, frames: Iterable[tuple[str, str, tuple[float, float, float]]] = ()
) -> Any:
    """SDT's own world of ``urdf`` (its parser), with extra frames and an omni drive."""
    from semantic_digital_twin.adapters.urdf import URDFParser
    from semantic_digital_twin.datastructures.prefixed_name import PrefixedName
    from semantic_digital_twin.spatial_types import HomogeneousTransformationMatrix
    from semantic_digital_twin.world_description.connections import FixedConnection, OmniDrive
    from semantic_digital_twin.world_description.world_entity import Body

    world = URDFParser(urdf=urdf_with_default_axes(urdf.read_text(encoding="utf-8"))).parse()
    with world.modify_world():
        for name, parent, xyz in frames:
            frame = Body(name=PrefixedName(name, world.name))
            world.add_kinematic_structure_entity(frame)
            world.add_connection(
                FixedConnection(
                    parent=world.get_body_by_name(parent),
                    child=frame,
                    parent_T_connection_expression=HomogeneousTransformationMatrix.from_xyz_rpy(
                        *xyz
                    ),
                )
            )
        base = world.root
        localization = Body(name=PrefixedName(odom))
        world.add_kinematic_structure_entity(localization)
        world.add_connection(
            OmniDrive.create_with_dofs(parent=localization, child=base, world=world)
        )
    return world


def hand_written(cls: Any, world: Any, monkeypatch: pytest.MonkeyPatch) -> Any:
    """SDT's hand-written robot class on ``world``, without its collision rules (see above)."""
    monkeypatch.setattr(cls, "_setup_collision_rules", lambda self: None)
    return cls.from_world(world)
