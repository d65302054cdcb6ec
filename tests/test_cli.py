"""The command line as a user runs it: exact output, exit codes (0 ok, 1 invalid, 2 usage)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.compiler import check_spec
from robotspec.shipped import shipped_schema_path
from robotspec.spec.load import json_schema_text

from .conftest import erd_robots, shared_path


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """Run ``robotspec ARGV`` in-process; returns (exit code, stdout, stderr)."""
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


PR2_CHAINS = """\
chain                 kind    root                     tip                          joints  dof  manipulator    sensors
torso                 torso   base_link                torso_lift_link              1       1    -              -
neck                  neck    torso_lift_link          head_tilt_link               2       2    -              kinect
left_arm              arm     torso_lift_link          l_wrist_roll_link            9       7    left_gripper   -
right_arm             arm     torso_lift_link          r_wrist_roll_link            9       7    right_gripper  -
left_gripper_thumb    finger  l_gripper_l_finger_link  l_gripper_l_finger_tip_link  1       1    -              -
left_gripper_finger   finger  l_gripper_r_finger_link  l_gripper_r_finger_tip_link  1       1    -              -
right_gripper_thumb   finger  r_gripper_l_finger_link  r_gripper_l_finger_tip_link  1       1    -              -
right_gripper_finger  finger  r_gripper_r_finger_link  r_gripper_r_finger_tip_link  1       1    -              -
"""  # noqa: E501


def test_help_lists_every_command(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "--help")
    assert code == 0
    for command in ("validate", "inspect", "list", "schema", "init", "drive", "demo"):
        assert f" {command} " in out


def test_cli_import_is_light() -> None:
    # `robotspec --help` must start fast: the app module imports no numeric or XML stack.
    code = (
        "import sys, importlib; importlib.import_module('robotspec.cli.app'); "
        "print(sorted({m.split('.')[0] for m in sys.modules} & "
        "{'numpy', 'lxml', 'pydantic', 'yaml', 'yourdfpy', 'coal', 'trimesh'}))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_validate_pr2(capsys: pytest.CaptureFixture[str]) -> None:
    erd_robots()
    code, out, err = run(capsys, "validate", "pr2")
    assert (code, out, err) == (0, "1 of 1 spec valid; 0 errors, 0 warnings\n", "")


def test_inspect_chains_pr2_exact(capsys: pytest.CaptureFixture[str]) -> None:
    erd_robots()
    code, out, _ = run(capsys, "inspect", "chains", "pr2")
    assert code == 0
    assert out == PR2_CHAINS


def test_inspect_json_outputs_parse(capsys: pytest.CaptureFixture[str]) -> None:
    erd_robots()
    for what in ("chains", "manipulators", "sensors", "joints", "groups", "collisions", "tree"):
        code, out, _ = run(capsys, "inspect", what, "pr2", "--json")
        assert code == 0, what
        json.loads(out)
    _, out, _ = run(capsys, "inspect", "manipulators", "pr2", "--json")
    grippers = {m["name"]: m for m in json.loads(out)}
    assert grippers["right_gripper"]["tool_frame"] == "r_gripper_tool_frame"
    assert grippers["right_gripper"]["type"] == "parallel_gripper"
    _, out, _ = run(capsys, "inspect", "joints", "pr2", "--json")
    joints = {j["name"]: j for j in json.loads(out)}
    # The spec tightens the right shoulder like the reference (0.15 rad/s), marked as tightened.
    assert joints["r_shoulder_pan_joint"]["velocity"] == pytest.approx(0.15)
    assert joints["r_shoulder_pan_joint"]["tightened"] is True


def test_validate_reports_every_problem_with_position(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    erd_robots()
    spec = tmp_path / "bad.yaml"
    spec.write_text(
        "robotspec: 1\n"
        "name: Broken\n"
        "extends: pr2\n"
        "chains:\n"
        "  right_arm:\n"
        "    root: torso_lift_link\n"
        "    tip: r_wrist_roll_lnk\n"
        "    manipulator: right_gripper\n"
        "torso:\n"
        "  root: base_link\n"
        "  tip: torso_lift_lnk\n"
    )
    code, out, err = run(capsys, "validate", str(spec))
    assert code == 1, err
    lines = out.splitlines()
    assert lines == [
        f"{spec}:7:10: error: link 'r_wrist_roll_lnk' not found in pr2.urdf; did you mean "
        "'r_wrist_roll_link', 'l_wrist_roll_link' or 'r_wrist_flex_link'?",
        f"{spec}:11:8: error: link 'torso_lift_lnk' not found in pr2.urdf; did you mean "
        "'torso_lift_link', 'r_shoulder_lift_link' or 'l_shoulder_lift_link'?",
        "0 of 1 spec valid; 2 errors, 0 warnings",
    ]
    code, out, _ = run(capsys, "validate", str(spec), "--format", "json")
    assert code == 1
    (result,) = json.loads(out)
    assert [p["name"] for p in result["problems"]] == ["r_wrist_roll_lnk", "torso_lift_lnk"]
    assert result["problems"][0]["suggestions"][0] == "r_wrist_roll_link"
    assert (result["problems"][0]["line"], result["problems"][0]["column"]) == (7, 10)


def test_usage_errors_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(capsys, "validate")[0] == 2
    assert run(capsys, "validate", "pr2", "--no-such-option")[0] == 2
    assert run(capsys, "no-such-command")[0] == 2
    assert run(capsys, "inspect", "nothing", "pr2")[0] == 2


def test_unknown_robot_and_missing_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, out, _ = run(capsys, "validate", "pr3")
    assert code == 1
    assert "'pr3' not found in the shipped robots; did you mean 'pr2'?" in out
    (tmp_path / "robot.yaml").write_text("robotspec: 1\n")
    code, _, err = run(capsys, "inspect", "chains", str(tmp_path / "robt.yaml"))
    assert code == 1
    assert err == f"{tmp_path / 'robt.yaml'}: error: file not found; did you mean 'robot.yaml'?\n"


def test_yaml_tags_are_refused_without_traceback(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    spec = tmp_path / "evil.yaml"
    spec.write_text("robotspec: 1\nname: !!python/object/apply:os.system ['echo pwned']\n")
    code, out, err = run(capsys, "validate", str(spec))
    assert code == 1
    assert "Traceback" not in out + err
    assert "pwned" not in out + err.replace("echo pwned", "")
    assert f"{spec}:2:7: error:" in out


def test_strict_turns_warnings_into_errors(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    erd_robots()
    spec = tmp_path / "warn.yaml"
    spec.write_text(
        "robotspec: 1\nname: W\nextends: pr2\nchains:\n"
        "  spare:\n    root: torso_lift_link\n    tip: l_elbow_flex_link\n"
    )
    code, out, _ = run(capsys, "validate", str(spec))
    assert code == 0
    warning = (
        f"{spec}:6:5: warning: chains.spare: chain 'spare' has neither a manipulator nor a "
        "sensor (not an arm? say 'kind: leg' or 'kind: chain')"
    )
    assert out.splitlines() == [warning, "1 of 1 spec valid; 0 errors, 1 warning"]
    code, out, _ = run(capsys, "validate", "--strict", str(spec))
    assert code == 1
    assert out.splitlines()[0] == warning.replace("warning:", "error:")


def test_list_and_schema(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, out, _ = run(capsys, "list")
    assert code == 0
    names = [line.split()[0] for line in out.splitlines()[1:]]
    assert names == ["b1_ur5_allegro", "dual_panda", "hsrb", "panda", "pr2", "tiago", "ur5"]
    code, out, _ = run(capsys, "schema")
    assert code == 0
    assert out == json_schema_text() == shipped_schema_path().read_text()
    assert run(capsys, "schema", "-o", str(tmp_path / "s.json"))[0] == 0
    assert json.loads((tmp_path / "s.json").read_text())["title"] == "robotspec robot spec"


# ------------------------------------------------------------------------------------- init


def _init(
    capsys: pytest.CaptureFixture[str], out: Path, *argv: str, allow: tuple[Path, ...] = ()
) -> dict[str, object]:
    code, _, err = run(capsys, "init", *argv, "-o", str(out))
    assert code == 0, err
    text = out.read_text()
    # A portable schema reference: the file beside the spec, never this machine's path.
    assert text.startswith("# yaml-language-server: $schema=robotspec.schema.json\n")
    check_spec(out, package_paths=allow)  # the draft validates as written
    data = yaml.safe_load(text)
    assert isinstance(data, dict)
    return data


def test_init_pr2_from_srdf(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    robots = erd_robots()
    out = tmp_path / "pr2.yaml"
    data = _init(
        capsys,
        out,
        str(robots / "pr2_description/urdf/pr2.urdf"),
        "--srdf",
        str(robots / "pr2_description/srdf/pr2.srdf"),
    )
    assert data["description"] == {
        "urdf": "package://pr2_description/urdf/pr2.urdf",
        "srdf": "package://pr2_description/srdf/pr2.srdf",
    }
    assert data["root"] == "base_footprint"
    assert data["drive"] == {
        "type": "omni",
        "joint": "world_joint",
        "parent_frame": "odom_combined",
    }
    chains = data["chains"]
    assert isinstance(chains, dict)
    assert chains["right_arm"]["group"] == "right_arm"
    assert chains["right_arm"]["manipulator"] == "right_eef"
    assert chains["right_arm"]["sensors"] == ["r_forearm_cam"]
    # The SRDF's group states become the arm's named states.
    assert set(chains["right_arm"]["states"]) == {"tuck_right_arm"}
    assert set(chains) == {"left_arm", "right_arm"}  # the head is the neck, 'torso' the torso
    right = data["manipulators"]["right_eef"]  # type: ignore[index]
    assert right["type"] == "parallel_gripper"
    assert right["tool_frame"] == "r_gripper_tool_frame"
    assert right["root"] == "r_gripper_palm_link"
    assert data["torso"]["root"] == "base_link"  # type: ignore[index]
    assert data["neck"]["tip"] == "head_tilt_link"  # type: ignore[index]
    assert "wide_stereo" in data["neck"]["sensors"]  # type: ignore[index]
    assert "wide_stereo" in data["sensors"]  # type: ignore[operator]
    # A second run refuses to overwrite.
    code, _, err = run(
        capsys, "init", str(robots / "pr2_description/urdf/pr2.urdf"), "-o", str(out)
    )
    assert code == 1
    assert err == f"{out}: error: the file exists; pass --force to overwrite it\n"


def test_init_without_srdf_guesses_chains_and_tool(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # UR5e: nobody wrote a spec for it; the arm and tool0 come from the tree alone.
    urdf = shared_path("robots", "ur5e", "ur5e.urdf")
    # The URDF lies outside the spec's project: the user allows its folder, as init says.
    data = _init(capsys, tmp_path / "ur5e.yaml", str(urdf), allow=(urdf.parent,))
    assert data["chains"] == {  # the arm ends at its flange, past wrist_3_link (issue 30)
        "arm": {"root": "base_link", "tip": "flange", "manipulator": "tool"}
    }
    assert data["manipulators"]["tool"]["tool_frame"] == "tool0"  # type: ignore[index]
    assert data["drive"] == {"type": "fixed"}


def test_init_fanuc_writes_package_paths(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # FANUC (MoveIt resources): packages found beside the URDF must be findable from the spec.
    fanuc = shared_path("robots", "fanuc")
    data = _init(
        capsys,
        tmp_path / "fanuc.yaml",
        str(fanuc / "moveit_resources_fanuc_description/urdf/fanuc.urdf"),
        "--srdf",
        str(fanuc / "moveit_resources_fanuc_moveit_config/config/fanuc.srdf"),
        allow=(fanuc,),  # outside the spec's folder: the user allows it, as with -P
    )
    desc = data["description"]
    assert isinstance(desc, dict)
    assert desc["urdf"] == "package://moveit_resources_fanuc_description/urdf/fanuc.urdf"
    assert len(desc["package_paths"]) == 1
    assert (tmp_path / desc["package_paths"][0]).resolve() == fanuc.resolve()
    chains = data["chains"]
    assert isinstance(chains, dict) and list(chains) == ["manipulator"]
    assert chains["manipulator"]["group"] == "manipulator"


def test_init_talos_humanoid(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    robots = erd_robots()
    data = _init(
        capsys,
        tmp_path / "talos.yaml",
        str(robots / "talos_data/robots/talos_reduced.urdf"),
        "--srdf",
        str(robots / "talos_data/srdf/talos.srdf"),
    )
    chains = data["chains"]
    assert isinstance(chains, dict)
    # The SRDF's groups (joints plus a chain): arms and legs, in the SRDF's names.
    assert sorted(chains) == ["l_arm", "l_leg", "r_arm", "r_leg"]
    assert chains["l_leg"]["kind"] == "leg"  # a leg, as the spec says (no tool warning)
    assert data["torso"]["root"] == "base_link"  # type: ignore[index]
    assert data["torso"]["states"] == {  # type: ignore[index]
        "half_sitting": {"torso_1_joint": 0, "torso_2_joint": 0.006761}
    }
    assert data["neck"]["root"] == "torso_2_link"  # type: ignore[index]


def test_shell_completion_of_commands_and_specs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "mine.yaml").write_text("robotspec: 1\n")
    env = {"_ROBOTSPEC_COMPLETE": "complete_bash", "COMP_CWORD": "1"}

    def complete(words: str, cword: int) -> list[str]:
        out = subprocess.run(
            [sys.executable, "-m", "robotspec"],
            env={**env, "COMP_WORDS": words, "COMP_CWORD": str(cword), "PATH": ""},
            cwd=tmp_path,
            capture_output=True,
            text=True,
        )
        return out.stdout.split()

    assert complete("robotspec ins", 1) == ["inspect"]
    assert complete("robotspec inspect chains p", 3) == ["panda", "pr2"]
    assert complete("robotspec validate robots/", 2) == ["robots/mine.yaml"]


@pytest.mark.parametrize(
    ("robot", "chain"), [("pr2", "right_arm"), ("panda", "arm"), ("ur5", None)]
)
def test_demo_scenario_passes_for_shipped_robots(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, robot: str, chain: str | None
) -> None:
    # The README's demo drives the last arm through a generated scenario; run the same
    # scenario on virtual time (Panda's home sits on a joint limit: exact ends matter).
    erd_robots()
    from robotspec.cli.demo_cmd import demo_scenario
    from robotspec.compiler import compile_robot
    from robotspec.export.robotinfo import export_spec_chain

    name = chain or compile_robot(robot).arms[-1].name
    script = tmp_path / "demo.yaml"
    script.write_text(demo_scenario(export_spec_chain(robot, name).info))
    code, out, err = run(
        capsys, "drive", "--spec", robot, "--chain", name, "--script", str(script), "--virtual-time"
    )
    assert code == 0, out + err
    assert out.splitlines()[-1] == "scenario: 8 of 8 steps as expected"


def test_other_commands_print_the_warnings_attached_to_an_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    erd_robots()
    spec = tmp_path / "both.yaml"
    spec.write_text(
        "robotspec: 1\nname: W\nextends: pr2\nchains:\n"
        "  spare:\n    root: torso_lift_link\n    tip: l_elbow_flex_link\n"
        "  broken:\n    root: torso_lift_link\n    tip: l_elbow_flex_lnk\n"
    )
    code, out, err = run(capsys, "inspect", "chains", str(spec))
    assert code == 1 and out == ""
    lines = err.splitlines()
    assert f"{spec}:10:10: error:" in lines[0] and "'l_elbow_flex_lnk'" in lines[0]
    assert (
        f"{spec}:6:5: warning: chains.spare: chain 'spare' has neither a manipulator nor a "
        "sensor (not an arm? say 'kind: leg' or 'kind: chain')" in lines[1:]
    )
