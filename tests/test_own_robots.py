"""Bringing a robot robotspec does not ship: real files as users have them (issue 15).

Talos's ``package:///`` meshes, a robot whose mesh package is absent, Baxter with and without its
prefixed SRDF, an SRDF that disables a link against itself, left and right arms.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.compiler import check_spec, compile_robot
from robotspec.description.srdf_names import map_prefixed_names
from robotspec.description.srdf_reader import parse_srdf_bytes
from robotspec.errors import KinematicsError
from robotspec.files.packages import PackageResolver
from robotspec.model.geometry import Mesh
from robotspec.semantic import AbstractRobot, Arm, Neck
from robotspec.semantic.base import AssignmentError

from .conftest import DATA, erd_robots

OWN = DATA / "own_robots"
ABSENT_URDF = OWN / "absent_meshes.urdf"
FIX = (
    "to fix, add the folder that holds it with -P FOLDER, to ROS_PACKAGE_PATH, "
    "or to description.package_paths in the spec"
)


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """Run ``robotspec ARGV`` in-process; returns (exit code, stdout, stderr)."""
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def searched(description: Path) -> str:
    """The search folders the compiler's resolver reports for ``description``."""
    return ", ".join(str(f) for f in PackageResolver.create(description).search_folders)


def write_stl(path: Path) -> None:
    """A one-triangle ASCII STL (enough for the mesh readers)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\n"
        "vertex 0 0.1 0\nendloop\nendfacet\nendsolid t\n"
    )


# --- meshes -------------------------------------------------------------------------------------


def absent_mesh_warnings() -> list[str]:
    folders = searched(ABSENT_URDF)
    return [
        f"{ABSENT_URDF}:8: warning: package 'absent_mesh_pkg' not found; searched: {folders}; "
        f"4 meshes of 2 bodies (upper_arm, forearm) have no geometry; {FIX}",
        f"{ABSENT_URDF}:16: warning: package 'absent_root_pkg' not found (a package:/// path "
        f"starts at a package root); searched: {folders}; body 'hand' has no mesh geometry; "
        f"{FIX}",
    ]


def test_absent_mesh_package_is_one_warning_per_package(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, out, err = run(capsys, "validate", str(OWN / "absent_meshes.yaml"))
    assert (code, err) == (0, "")
    assert out.splitlines() == [*absent_mesh_warnings(), "1 of 1 spec valid; 0 errors, 2 warnings"]
    code, out, _ = run(capsys, "validate", "--strict", str(OWN / "absent_meshes.yaml"))
    assert code == 1
    assert out.splitlines() == [
        *(w.replace(": warning: ", ": error: ") for w in absent_mesh_warnings()),
        "0 of 1 spec valid; 2 errors, 0 warnings",
    ]


def test_absent_meshes_keep_kinematics_and_semantics(capsys: pytest.CaptureFixture[str]) -> None:
    robot = compile_robot(OWN / "absent_meshes.yaml")
    meshes: dict[str, list[str | None]] = {}
    for b in robot.world.bodies:
        for shape in (*b.visuals, *b.collisions):
            if isinstance(shape.geometry, Mesh):
                meshes.setdefault(b.name, []).append(shape.geometry.path)
    assert meshes == {"upper_arm": [None, None], "forearm": [None, None], "hand": [None]}
    code, out, _ = run(capsys, "inspect", "chains", str(OWN / "absent_meshes.yaml"))
    assert code == 0 and out.splitlines()[1].split()[:4] == ["arm", "arm", "base_link", "hand"]


def test_package_path_makes_the_meshes_found(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    for name in ("upper_arm", "upper_arm_collision", "forearm", "forearm_collision"):
        write_stl(tmp_path / "absent_mesh_pkg" / "meshes" / f"{name}.stl")
    write_stl(tmp_path / "absent_root_pkg" / "meshes" / "hand.stl")
    code, out, _ = run(capsys, "validate", "-P", str(tmp_path), str(OWN / "absent_meshes.yaml"))
    assert (code, out) == (0, "1 of 1 spec valid; 0 errors, 0 warnings\n")
    robot = compile_robot(OWN / "absent_meshes.yaml", package_paths=[tmp_path])
    hand = robot.world.get_body_by_name("hand").visuals[0].geometry
    assert isinstance(hand, Mesh) and hand.path == str(
        (tmp_path / "absent_root_pkg" / "meshes" / "hand.stl").resolve()
    )


GEOMETRY_LOST = (
    "2 bodies lose their geometry, mesh files not found (upper_arm, forearm; meshes of "
    "'absent_mesh_pkg')"
)


def test_collisions_name_the_bodies_without_geometry_and_go_on_when_allowed(
    capsys: pytest.CaptureFixture[str],
) -> None:
    spec = str(OWN / "absent_meshes.yaml")
    code, out, err = run(capsys, "collisions", "check", spec)
    assert (code, out) == (1, "")
    assert err == (
        f"error: {GEOMETRY_LOST}; pass --skip-missing-meshes to check collisions without them, "
        "or make the package findable: -P FOLDER, ROS_PACKAGE_PATH, or "
        "description.package_paths in the spec\n"
    )
    code, out, err = run(capsys, "collisions", "check", "--skip-missing-meshes", spec)
    assert code == 0 and out.startswith("collision-free")
    assert err == f"warning: {GEOMETRY_LOST}; check collisions goes on without them\n"


def test_render_names_the_bodies_without_geometry(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    pytest.importorskip("PIL")
    spec = str(OWN / "absent_meshes.yaml")
    png = tmp_path / "r.png"
    code, _, err = run(capsys, "render", spec, "-o", str(png), "--size", "64x48")
    lost = (
        "3 bodies lose their geometry, mesh files not found (upper_arm, forearm, hand; meshes "
        "of 'absent_mesh_pkg', 'absent_root_pkg')"
    )
    assert code == 1 and not png.exists()
    assert err.startswith(f"error: {lost}; pass --skip-missing-meshes to render without them")
    code, out, err = run(
        capsys, "render", spec, "-o", str(png), "--size", "64x48", "--skip-missing-meshes"
    )
    assert code == 0 and png.is_file()
    assert err == f"warning: {lost}; render goes on without them\n"


def test_talos_package_root_meshes_all_resolve(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    robots = erd_robots()
    spec = tmp_path / "talos.yaml"
    spec.write_text(
        "robotspec: 1\nname: Talos\ndescription:\n"
        "  urdf: package://example-robot-data/robots/talos_data/robots/talos_full_v2.urdf\n"
        "  srdf: package://example-robot-data/robots/talos_data/srdf/talos.srdf\n"
        "root: base_link\n"
        "chains:\n  left_arm: {root: torso_2_link, tip: arm_left_7_link, manipulator: left}\n"
        "manipulators:\n  left: {type: generic, root: gripper_left_base_link, "
        "tool_frame: gripper_left_base_link}\n"
    )
    result = check_spec(spec)
    assert result.robot is not None
    meshes = [
        s.geometry
        for b in result.robot.world.bodies
        for s in (*b.visuals, *b.collisions)
        if isinstance(s.geometry, Mesh)
    ]
    assert sum(m.uri.startswith("package:///example-robot-data/") for m in meshes) == 93
    assert all(m.path is not None and Path(m.path).is_file() for m in meshes)
    assert not [w for w in result.warnings if "package" in w.message]
    code, out, _ = run(capsys, "validate", str(spec))
    srdf = robots / "talos_data" / "srdf" / "talos.srdf"
    # The one warning left is Talos's own: its SRDF names pinocchio's free-flyer joint.
    assert code == 0
    assert out.splitlines()[-1] == "1 of 1 spec valid; 0 errors, 1 warning"
    assert out.splitlines()[0].startswith(f"{srdf}:104: warning: joint 'root_joint' not found")


# --- SRDF names -------------------------------------------------------------------------------


BAXTER_PREFIX_WARNING = (
    "warning: group 'whole_body': 19 joint names carry the prefix 'baxter/' that the URDF's "
    "names lack; read as the URDF's names ('baxter/head_pan' as 'head_pan', 'baxter/left_s0' "
    "as 'left_s0', 'baxter/left_s1' as 'left_s1' and 16 more)"
)


def test_baxter_prefixed_srdf_is_one_warning_per_group(capsys: pytest.CaptureFixture[str]) -> None:
    srdf = erd_robots() / "baxter_description" / "srdf" / "baxter_manipulation.srdf"
    code, out, _ = run(capsys, "validate", str(OWN / "baxter_srdf.yaml"))
    assert code == 0
    assert out.splitlines() == [
        f"{srdf}:17: {BAXTER_PREFIX_WARNING}",
        "1 of 1 spec valid; 0 errors, 1 warning",
    ]
    robot = compile_robot(OWN / "baxter_srdf.yaml")
    assert robot.srdf is not None and robot.srdf.groups[0].joints[0] == "head_pan"
    # The imported state sets the leaders; MoveIt's mimic entries agree and are dropped.
    state = dict(robot.joint_states["whole_body.neutral"].joints)
    assert len(state) == 17 and "l_gripper_r_finger_joint" not in state
    code, out, _ = run(capsys, "inspect", "tree", str(OWN / "baxter_srdf.yaml"))
    assert code == 0


def test_summary_counts_warnings_when_there_are_errors(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    erd_robots()
    bad = tmp_path / "bad.yaml"
    text = (OWN / "baxter_srdf.yaml").read_text().replace("tip: left_hand_link", "tip: left_hnd")
    bad.write_text(text)
    code, out, _ = run(capsys, "validate", str(bad))
    lines = out.splitlines()
    assert code == 1
    assert lines[0].startswith(f"{bad}:15:41: error: link 'left_hnd' not found in baxter.urdf")
    assert lines[1].endswith(BAXTER_PREFIX_WARNING)
    assert lines[2:] == ["0 of 1 spec valid; 1 error, 1 warning"]
    labels = [re.search(r": (error|warning): ", line) for line in lines[:2]]
    assert [m.group(1) for m in labels if m] == ["error", "warning"]


def test_baxter_without_srdf_has_two_arms_and_a_neck() -> None:
    erd_robots()
    robot = compile_robot(OWN / "baxter.yaml")
    assert (robot.left_arm.name, robot.right_arm.name) == ("left_arm", "right_arm")
    assert robot.neck is not None and [s.name for s in robot.neck.sensors] == ["head_camera"]
    assert robot.srdf is None


def test_ambiguous_prefixes_are_one_located_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    (tmp_path / "robot.urdf").write_text(ABSENT_URDF.read_text())
    (tmp_path / "robot.srdf").write_text(
        '<robot name="a">\n  <group name="arm">\n    <joint name="left/shoulder"/>\n'
        '    <joint name="right/shoulder"/>\n  </group>\n'
        '  <group name="other">\n    <joint name="r1/elbow"/>\n  </group>\n</robot>\n'
    )
    spec = tmp_path / "spec.yaml"
    spec.write_text(
        (OWN / "self_pair.yaml")
        .read_text()
        .replace("absent_meshes.urdf", "robot.urdf")
        .replace("self_pair.srdf", "robot.srdf")
    )
    code, out, _ = run(capsys, "validate", str(spec))
    srdf = tmp_path / "robot.srdf"
    lines = [line for line in out.splitlines() if "robot.srdf" in line]
    assert code == 1
    assert lines == [  # errors first, then warnings, each in file order
        f"{srdf}:4: error: joints 'left/shoulder' and 'right/shoulder' of group 'arm' would "
        "both be the URDF's joint 'shoulder' once their prefixes are cut; keep one of them, "
        "written 'shoulder', in robot.srdf",
        f"{srdf}:2: warning: group 'arm': 1 joint names carry the prefix 'left/' that the "
        "URDF's names lack; read as the URDF's names ('left/shoulder' as 'shoulder')",
        f"{srdf}:6: warning: group 'other': 1 joint names carry the prefix 'r1/' that the "
        "URDF's names lack; read as the URDF's names ('r1/elbow' as 'elbow')",
    ]
    # (the other two warnings are the copied URDF's absent mesh packages)
    assert out.splitlines()[-1] == "0 of 1 spec valid; 1 error, 4 warnings"


def test_a_name_that_could_lose_two_prefixes_is_refused() -> None:
    srdf = parse_srdf_bytes(
        b'<robot name="r">\n<group name="g">\n<link name="a/b/c"/>\n</group>\n</robot>\n',
        "r.srdf",
    )
    mapping = map_prefixed_names(srdf, ["b/c", "c"], [])
    assert mapping.srdf.groups[0].links == ("a/b/c",)  # left as written
    assert [(e.line, e.message) for e in mapping.errors] == [
        (
            3,
            "link 'a/b/c' of group 'g' could be the URDF's link 'b/c' or 'c' once a prefix is "
            "cut; write the URDF's name in r.srdf",
        )
    ]
    assert mapping.warnings == () and mapping.ambiguous == {(3, "a/b/c")}
    # Names the URDF has are never touched, even when they hold a '/'.
    assert map_prefixed_names(srdf, ["a/b/c", "c"], []).srdf is srdf


# --- self pairs -------------------------------------------------------------------------------


def test_self_pair_is_a_warning_everywhere(capsys: pytest.CaptureFixture[str]) -> None:
    spec = str(OWN / "self_pair.yaml")
    code, out, _ = run(capsys, "validate", spec)
    assert code == 0
    assert f"{OWN / 'self_pair.srdf'}:6: warning: <disable_collisions> disables link 'hand' " in out
    assert "against itself; a link is never checked against itself, so the entry is ignored " in (
        out
    )
    assert out.splitlines()[-1] == "1 of 1 spec valid; 0 errors, 3 warnings"
    code, out, err = run(capsys, "export", "srdf", spec)
    assert code == 0 and "internal error" not in err
    assert re.findall(r"<disable_collisions [^>]*>", out) == [
        '<disable_collisions link1="base_link" link2="upper_arm" reason="Adjacent"/>',
        '<disable_collisions link1="upper_arm" link2="forearm" reason="Adjacent"/>',
    ]
    robot = compile_robot(spec)
    assert all(len(p) == 2 for p in robot.disabled_collision_pairs)


# --- joints -----------------------------------------------------------------------------------


@pytest.mark.parametrize(("cap", "marked"), [(None, False), ("5.0", False), ("1.0", True)])
def test_inspect_joints_marks_only_tightened_velocities(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, cap: str | None, marked: bool
) -> None:
    spec = tmp_path / "arm.yaml"
    (tmp_path / "absent_meshes.urdf").write_text(ABSENT_URDF.read_text())
    text = (OWN / "absent_meshes.yaml").read_text()
    if cap is not None:
        text += f"velocity_limits: {{default: {cap}}}\n"
    spec.write_text(text)
    code, out, _ = run(capsys, "inspect", "joints", str(spec))
    velocity = "1*" if marked else "2"
    assert code == 0
    assert [line.split()[-1] for line in out.splitlines()[1:]] == [velocity, velocity]
    code, out, _ = run(capsys, "inspect", "joints", "--json", str(spec))
    assert out.count('"tightened": true') == (2 if marked else 0)


# --- left and right arms ----------------------------------------------------------------------


@pytest.mark.parametrize("name", ["pr2", "dual_panda"])
def test_shipped_two_arm_robots_offer_left_and_right(name: str) -> None:
    erd_robots()
    robot = compile_robot(name)
    assert (robot.left_arm.name, robot.right_arm.name) == ("left_arm", "right_arm")


def test_tiago_has_one_arm() -> None:
    erd_robots()
    robot = compile_robot("tiago")
    with pytest.raises(KinematicsError) as info:
        _ = robot.left_arm
    assert info.value.message == (
        "left_arm and right_arm need exactly two arms (chains with a manipulator); "
        "this robot has 1: 'arm'"
    )


def swapped_baxter(tmp_path: Path, extra: str = "") -> Path:
    """Baxter with its chain names swapped: 'right_arm' holds the left arm's links."""
    text = (OWN / "baxter.yaml").read_text()
    text = text.replace("  left_arm: {", "  TMP: {").replace("  right_arm: {", "  left_arm: {")
    text = text.replace("  TMP: {", "  right_arm: {")
    spec = tmp_path / "swapped.yaml"
    spec.write_text(
        text.replace("manipulator: left_gripper}", f"manipulator: left_gripper{extra}}}")
    )
    return spec


def test_left_and_right_are_chosen_by_position_not_by_name(tmp_path: Path) -> None:
    erd_robots()
    robot = compile_robot(swapped_baxter(tmp_path))
    assert robot.left_arm.root.name == "left_arm_mount"
    assert robot.left_arm.name == "right_arm"  # the chain's name is the author's
    assert robot.right_arm.root.name == "right_arm_mount"


def test_declared_side_wins_and_a_contradiction_is_warned(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    erd_robots()
    spec = swapped_baxter(tmp_path, ", side: right")
    robot = compile_robot(spec)
    assert robot.right_arm.root.name == "left_arm_mount"  # the spec says so
    code, out, _ = run(capsys, "validate", str(spec))
    assert code == 0
    assert out.splitlines() == [
        f"{spec}:14:91: warning: chains.right_arm.side: chain 'right_arm' is declared side: "
        "right, but in the default pose it lies left of 'left_arm' seen from 'base'",
        "1 of 1 spec valid; 0 errors, 1 warning",
    ]


def test_side_on_a_chain_without_manipulator_and_twice_the_same_side(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    erd_robots()
    text = (OWN / "baxter.yaml").read_text()
    text = text.replace("manipulator: left_gripper}", "manipulator: left_gripper, side: left}")
    text = text.replace("manipulator: right_gripper}", "manipulator: right_gripper, side: left}")
    spec = tmp_path / "twice.yaml"
    spec.write_text(text)
    code, out, _ = run(capsys, "validate", str(spec))
    assert code == 1
    assert out.splitlines()[0] == (
        f"{spec}:15:94: error: chains.right_arm.side: chains 'left_arm' and 'right_arm' are "
        "both declared side: left"
    )


def test_add_arm_and_add_neck_follow_the_seed() -> None:
    erd_robots()
    robot = compile_robot(OWN / "baxter.yaml")
    w = robot.world
    bare = AbstractRobot(name="b", root=robot.root, world=w)
    chain = Arm(name="a", root=robot.left_arm.root, world=w, tip=robot.left_arm.tip)
    with pytest.raises(AssignmentError) as info:
        bare.add_arm(chain)
    assert info.value.message == ("arm 'a' carries no manipulator; add it with add_kinematic_chain")
    assert isinstance(info.value, ValueError)  # the seed raises ValueError
    neck = Neck(name="n", root=w.get_body_by_name("torso"), world=w, tip=w.get_body_by_name("head"))
    with pytest.raises(AssignmentError, match="neck 'n' carries no sensor"):
        bare.add_neck(neck)
    assert bare.neck is None and bare.arms == []
    assert robot.arms == [robot.left_arm, robot.right_arm]
    assert all(isinstance(a, Arm) for a in robot.arms)


def test_a_spec_neck_without_sensors_is_an_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    erd_robots()
    spec = tmp_path / "neck.yaml"
    spec.write_text((OWN / "baxter.yaml").read_text().replace("  sensors: [head_camera]\n", ""))
    code, out, _ = run(capsys, "validate", str(spec))
    assert code == 1
    assert out.splitlines()[0] == f"{spec}:9:3: error: neck: a neck must carry at least one sensor"


def test_imported_srdf_states_skip_joints_the_urdf_lacks(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    (tmp_path / "robot.urdf").write_text(ABSENT_URDF.read_text())
    (tmp_path / "robot.srdf").write_text(
        '<robot name="a">\n  <group name="arm"><chain base_link="base_link" tip_link="hand"/>'
        '</group>\n  <group_state name="home" group="arm">\n'
        '    <joint name="shoulder" value="0.5"/>\n    <joint name="ghost_joint" value="1"/>\n'
        "  </group_state>\n</robot>\n"
    )
    spec = tmp_path / "spec.yaml"
    spec.write_text(
        (OWN / "self_pair.yaml")
        .read_text()
        .replace("absent_meshes.urdf", "robot.urdf")
        .replace("self_pair.srdf", "robot.srdf")
        + "import_srdf_group_states: true\n"
    )
    code, out, _ = run(capsys, "validate", str(spec))
    assert code == 0
    assert (
        f"{tmp_path / 'robot.srdf'}:5: warning: joint 'ghost_joint' not found in robot.urdf" in out
    )
    robot = compile_robot(spec)
    assert robot.joint_states["arm.home"].joints == (("shoulder", 0.5),)


TWO_ARM_SPEC = """\
robotspec: 1
name: {name}
description:
  urdf: package://example-robot-data/robots/{urdf}
root: base_footprint
chains:
  arm_a: {{root: torso_lift_link, tip: arm_right_7_link, manipulator: hand_a}}
  arm_b: {{root: torso_lift_link, tip: arm_left_7_link, manipulator: hand_b}}
manipulators:
  hand_a: {{type: generic, root: {right}, tool_frame: {right}}}
  hand_b: {{type: generic, root: {left}, tool_frame: {left}}}
"""


@pytest.mark.parametrize(
    ("name", "urdf", "hand"),
    [
        ("TiagoDual", "tiago_description/robots/tiago_dual.urdf", "hand_{}_palm_link"),
        ("TiagoPro", "tiago_pro_description/robots/tiago_pro.urdf", "gripper_{}_base_link"),
    ],
)
def test_dual_arm_tiagos_have_left_and_right_by_position(
    tmp_path: Path, name: str, urdf: str, hand: str
) -> None:
    erd_robots()
    spec = tmp_path / "two_arms.yaml"
    spec.write_text(
        TWO_ARM_SPEC.format(
            name=name, urdf=urdf, right=hand.format("right"), left=hand.format("left")
        )
    )
    robot = compile_robot(spec)
    # Neutral chain names: the sides come from where the arms are, seen from the base.
    assert (robot.left_arm.name, robot.right_arm.name) == ("arm_b", "arm_a")


def test_meshes_missing_from_a_found_package_are_one_warning(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    pkg = tmp_path / "absent_mesh_pkg"
    pkg.mkdir()
    (pkg / "package.xml").write_text("<package><name>absent_mesh_pkg</name></package>")
    write_stl(tmp_path / "absent_root_pkg" / "meshes" / "hand.stl")
    code, out, _ = run(capsys, "validate", "-P", str(tmp_path), str(OWN / "absent_meshes.yaml"))
    real = pkg.resolve()
    assert code == 0
    assert out.splitlines() == [
        f"{ABSENT_URDF}:8: warning: 4 meshes of 'absent_mesh_pkg' not found (first: mesh "
        f"'package://absent_mesh_pkg/meshes/upper_arm.stl' resolves to "
        f"'{real}/meshes/upper_arm.stl', which does not exist); 4 meshes of 2 bodies "
        "(upper_arm, forearm) have no geometry",
        "1 of 1 spec valid; 0 errors, 1 warning",
    ]
