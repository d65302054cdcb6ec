"""``robotspec init --srdf`` on hostile group structures: deep nesting, many groups, broken ones.

Why: drafting walked subgroups by recursion (1,500 nested groups crashed with RecursionError while
``validate`` read the same file), compared every group with every other (10^5 groups took minutes),
and dropped a group whose chain ran up the tree or named a missing link without a word.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.compiler import check_spec
from robotspec.description.load import load_description
from robotspec.spec.draft.srdf_groups import GroupJoints

JOINT = (
    '<joint name="j{i}" type="revolute"><parent link="{parent}"/><child link="l{i}"/>'
    '<origin xyz="0 0 0.3"/><axis xyz="0 {y} {z}"/>'
    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
)


def _urdf(folder: Path) -> Path:
    """A fixed base and one serial run of three revolute joints: base -> l1 -> l2 -> l3."""
    body = ['<?xml version="1.0"?>\n<robot name="r">\n<link name="base"/>\n']
    for i in (1, 2, 3):
        body.append(f'<link name="l{i}"/>\n')
        parent = "base" if i == 1 else f"l{i - 1}"
        body.append(JOINT.format(i=i, parent=parent, y=i % 2, z=(i + 1) % 2))
    body.append("</robot>\n")
    path = folder / "r.urdf"
    path.write_text("".join(body))
    return path


def _srdf(folder: Path, groups: list[str], name: str = "r.srdf") -> Path:
    path = folder / name
    path.write_text('<?xml version="1.0"?>\n<robot name="r">\n' + "".join(groups) + "</robot>\n")
    return path


def _init(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, srdf: Path
) -> tuple[int, str, str, Path]:
    out = tmp_path / "spec.yaml"
    code = run_app(app, ["init", str(tmp_path / "r.urdf"), "--srdf", str(srdf), "-o", str(out)])
    captured = capsys.readouterr()
    return code, captured.out, captured.err, out


def test_subgroups_nested_1500_deep_are_drafted(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    _urdf(tmp_path)
    depth = 1_500
    # The outermost group comes first, so nothing is known before the walk reaches the bottom.
    groups = [f'<group name="g{i}"><group name="g{i + 1}"/></group>\n' for i in range(depth - 1)]
    groups.append(f'<group name="g{depth - 1}"><chain base_link="base" tip_link="l3"/></group>\n')
    srdf = _srdf(tmp_path, groups)
    code, _, err, out = _init(capsys, tmp_path, srdf)
    assert code == 0, err
    assert "internal error" not in err
    text = out.read_text()
    # Every group holds the same chain: the first is drafted, the others are noted as repeats.
    assert "  g0:  # from the SRDF group 'g0'" in text
    assert "# Note: SRDF group 'g1499' joins or repeats other chains; not drafted." in text
    assert check_spec(out).robot is not None

    desc = load_description(str(tmp_path / "r.urdf"), srdf=str(srdf))
    assert desc.srdf is not None
    sets = GroupJoints.of(desc.world, desc.srdf)
    assert sets.joints["g0"] == frozenset({"j1", "j2", "j3"})
    assert not sets.problems


def test_twenty_thousand_groups_take_linear_time(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # 20,000 groups: comparing every group with every other (4 * 10^8 steps) would not finish
    # within the test run; a linear walk takes about a second.
    _urdf(tmp_path)
    n = 20_000
    tips = ("l1", "l2", "l3")
    groups = [
        f'<group name="g{i}"><chain base_link="base" tip_link="{tips[i % 3]}"/></group>\n'
        for i in range(n)
    ]
    groups += [f'<group name="s{i}"><group name="g{i}"/></group>\n' for i in range(n)]
    srdf = _srdf(tmp_path, groups)
    code, _, err, out = _init(capsys, tmp_path, srdf)
    assert code == 0, err
    text = out.read_text()
    # Every group is read and noted once; none is more than the tree's own arm (a one-joint
    # group is no chain, the others repeat or join it), which is drafted from the tree.
    assert "  arm:  # from the URDF tree" in text
    one_joint = 2 * len(range(0, n, 3))
    assert text.count("moves one joint: not drafted as a chain") == one_joint
    assert text.count("joins or repeats other chains; not drafted") == 2 * n - one_joint


def test_broken_groups_are_noted_not_dropped(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    _urdf(tmp_path)
    srdf = _srdf(
        tmp_path,
        [
            '<group name="reversed"><chain base_link="l3" tip_link="base"/></group>\n',
            '<group name="unknown"><chain base_link="base" tip_link="nope"/></group>\n',
            # What is left of this group (j1 to j3) is still a chain, and drafted.
            '<group name="loose"><joint name="j1"/><joint name="j9"/><link name="l7"/>'
            '<joint name="j2"/><joint name="j3"/><group name="undefined"/></group>\n',
        ],
    )
    code, _, err, out = _init(capsys, tmp_path, srdf)
    assert code == 0, err
    notes = [line for line in out.read_text().splitlines() if line.startswith("# Note: SRDF")]
    assert notes == [
        "# Note: SRDF group 'reversed': its chain 'l3' -> 'base' runs up the tree "
        "(base_link must be above tip_link) (the group is not drafted).",
        "# Note: SRDF group 'unknown': its chain 'base' -> 'nope' names 'nope', "
        "not a link of the URDF (the group is not drafted).",
        "# Note: SRDF group 'loose': no joint 'j9' in the URDF; no link 'l7' in the URDF; "
        "its subgroup 'undefined' is not defined (ignored).",
    ]
    assert "  loose:  # from the SRDF group 'loose'" in out.read_text()
    assert check_spec(out).robot is not None


def test_chain_across_branches_is_noted(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    urdf = _urdf(tmp_path)
    # A second branch off the base: l1 and b1 are siblings.
    urdf.write_text(
        urdf.read_text().replace(
            "</robot>",
            '<link name="b1"/><joint name="jb" type="fixed"><parent link="base"/>'
            '<child link="b1"/></joint>\n</robot>',
        )
    )
    srdf = _srdf(tmp_path, ['<group name="across"><chain base_link="l1" tip_link="b1"/></group>\n'])
    code, _, err, out = _init(capsys, tmp_path, srdf)
    assert code == 0, err
    assert (
        "# Note: SRDF group 'across': its chain 'l1' -> 'b1' spans two branches "
        "('l1' is not above 'b1') (the group is not drafted)." in out.read_text()
    )


def test_virtual_joint_in_a_group_is_not_a_problem(tmp_path: Path) -> None:
    _urdf(tmp_path)
    srdf = _srdf(
        tmp_path,
        [
            '<virtual_joint name="world_joint" type="fixed" parent_frame="world" '
            'child_link="base"/>\n',
            '<group name="all"><joint name="world_joint"/><joint name="j1"/></group>\n',
        ],
    )
    desc = load_description(str(tmp_path / "r.urdf"), srdf=str(srdf))
    assert desc.srdf is not None
    sets = GroupJoints.of(desc.world, desc.srdf)
    assert sets.joints == {"all": frozenset({"j1"})}
    assert sets.problems == {}


def test_deep_nesting_under_the_hostile_runner(tmp_path: Path) -> None:
    # The same 1,500-deep file in a subprocess under the memory and CPU fences (the reported
    # RecursionError was an internal error, exit 3).
    from tests.test_hostile import run_cli

    (tmp_path / "work").mkdir()
    _urdf(tmp_path)
    groups = [f'<group name="g{i}"><group name="g{i + 1}"/></group>\n' for i in range(1_499)]
    groups.append('<group name="g1499"><chain base_link="base" tip_link="l3"/></group>\n')
    srdf = _srdf(tmp_path, groups)
    r = run_cli(tmp_path, "init", str(tmp_path / "r.urdf"), "--srdf", str(srdf))
    assert r.code == 0, r.err
    assert "  g0:  # from the SRDF group 'g0'" in r.out
