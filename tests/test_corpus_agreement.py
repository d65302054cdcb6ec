"""The agreement study's tool (issue 30): two truths of a robot compared with draft_score's rules.

Small layouts check each rule with counts known by hand; a few real truths of the blind corpus's
tune half, copied and perturbed in ``tmp_path`` (never edited in place), check the command end
to end (skipped, with the command, when the corpus cache is absent); the held-out half is refused
before anything is loaded.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest
import yaml

from tools.corpus import agreement
from tools.corpus.split import half
from tools.corpus.truth_compare import NAMED_VS_NEW, compare
from tools.draft_score import Truth

DATA = Path(__file__).resolve().parent / "data"
#: Tune-half robots of the PyPI part whose truths hold a gripper, a camera and a drive between them.
REAL = ("maniskill/fetch", "robosuite/panda", "robosuite/baxter")


def _joint(name: str, parent: str, child: str, kind: str = "revolute") -> str:
    moving = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0 0.1"/>{"" if kind == "fixed" else moving}</joint>'
    )


#: An arm of two joints ending at a flange and a tool0 frame, a two-finger gripper, a pan-tilt head
#: with a camera frame: (link, joint to it, parent, type).
_TREE = [
    ("base_link", None, None, None),
    ("upper", "shoulder", "base_link", "revolute"),
    ("flange", "elbow", "upper", "revolute"),
    ("tool0", "tool0_fixed", "flange", "fixed"),
    ("finger_a", "fa", "flange", "revolute"),
    ("finger_b", "fb", "flange", "revolute"),
    ("pan", "head_pan", "base_link", "revolute"),
    ("tilt", "head_tilt", "pan", "revolute"),
    ("eye", "eye_fixed", "tilt", "fixed"),
    ("eye_depth", "eye_depth_fixed", "tilt", "fixed"),
]


@pytest.fixture(scope="module")
def world(tmp_path_factory: pytest.TempPathFactory) -> object:
    from robotspec.description.load import load_description

    folder = tmp_path_factory.mktemp("layout")
    parts = [f'<link name="{link}"/>' for link, *_ in _TREE]
    parts += [_joint(j, p, link, k) for link, j, p, k in _TREE if j is not None and p and k]
    urdf = folder / "layout.urdf"
    urdf.write_text('<robot name="layout">' + "".join(parts) + "</robot>")
    return load_description(str(urdf), base_folder=folder).world


#: The first expert's truth of the layout.
TRUTH: dict[str, Any] = {
    "robot": "x/layout",
    "chains": {"arm": {"root": "base_link", "tip": "flange"}},
    "manipulators": {
        "gripper": {
            "type": "parallel_gripper",
            "tool_frame": "tool0",
            "fingers": ["finger_a", "finger_b"],
        }
    },
    "cameras": ["eye"],
    "neck": {"root": "base_link", "tip": "tilt"},
    "drive": {"type": "fixed"},
}


def _truth(data: dict[str, Any]) -> Truth:
    return Truth("layout", str(data["robot"]), data)


def _changed(**change: Any) -> Truth:
    data = copy.deepcopy(TRUTH)
    data.update(change)
    return _truth(data)


def _counts(found: Any) -> dict[str, tuple[int, int]]:
    return dict(found.first.counts)


def test_a_truth_agrees_with_itself_both_ways(world: object) -> None:
    found = compare(_truth(TRUTH), _truth(copy.deepcopy(TRUTH)), world)
    assert found.first.wrong == [] and found.second.wrong == []
    assert _counts(found) == {
        "chains": (1, 1),
        "tool frames": (1, 1),
        "grippers/hands": (1, 1),
        "cameras": (1, 1),
        "torso/neck/drive": (2, 2),  # the neck and the drive
    }
    assert found.stated["torso/neck/drive"] == (2, 2, 2)


def test_a_changed_tip_an_extra_camera_and_another_drive(world: object) -> None:
    gripper = {**TRUTH["manipulators"]["gripper"], "fingers": ["finger_a", "upper"]}
    second = _changed(
        manipulators={"gripper": gripper},
        cameras=["eye", "eye_depth"],
        drive={"type": "differential"},
    )
    found = compare(_truth(TRUTH), second, world)
    # The gripper: the first's is missed and the second's is an extra (two items, none agree);
    # the extra camera is one more item; the drive is one item, wrong.
    assert _counts(found) == {
        "chains": (1, 1),
        "tool frames": (1, 1),
        "grippers/hands": (0, 2),
        "cameras": (1, 2),
        "torso/neck/drive": (1, 2),
    }
    assert found.first.counts == found.second.counts  # one-to-one: the same both ways round
    assert found.stated["grippers/hands"] == (1, 1, 0)
    assert found.stated["cameras"] == (1, 2, 1)
    assert "torso/neck/drive: drive: fixed vs the other's differential" in found.first.wrong


def test_chains_by_kind_and_joints_and_a_neck_without_camera_is_a_chain(world: object) -> None:
    # The same joints to another fixed tip agree; a leg does not agree with an arm.
    assert _counts(
        compare(
            _truth(TRUTH), _changed(chains={"arm": {"root": "base_link", "tip": "tool0"}}), world
        )
    )["chains"] == (1, 1)
    leg = _changed(chains={"arm": {"root": "base_link", "tip": "flange", "kind": "leg"}})
    assert _counts(compare(_truth(TRUTH), leg, world))["chains"] == (0, 2)
    # The second states no camera: its neck is scored as a chain, so it neither agrees with
    # the first's neck nor is it lost (one missed camera, one missed neck, one extra chain).
    found = compare(_truth(TRUTH), _changed(cameras=[]), world)
    assert _counts(found)["chains"] == (1, 2) and _counts(found)["cameras"] == (0, 1)
    assert _counts(found)["torso/neck/drive"] == (1, 2)


def test_tool_frames_named_against_new_disagree_and_are_marked(world: object) -> None:
    gripper = TRUTH["manipulators"]["gripper"]
    on_flange = {**gripper, "tool_frame": {"parent": "flange"}}
    found = compare(_truth(TRUTH), _changed(manipulators={"gripper": on_flange}), world)
    assert _counts(found)["tool frames"] == (0, 2)
    assert found.first.wrong[0] == f"tool frames: gripper: tool0 ({NAMED_VS_NEW})"
    # Both {parent: X} with the same X agree; another X does not, and is not marked.
    both = compare(
        _changed(manipulators={"gripper": on_flange}),
        _changed(manipulators={"gripper": on_flange}),
        world,
    )
    assert _counts(both)["tool frames"] == (1, 1)
    on_upper = {**gripper, "tool_frame": {"parent": "upper"}}
    other = compare(_truth(TRUTH), _changed(manipulators={"gripper": on_upper}), world)
    assert _counts(other)["tool frames"] == (0, 2)
    assert all(NAMED_VS_NEW not in w for w in other.first.wrong)


def test_drive_joints_count_only_when_both_name_them(world: object) -> None:
    planar = {"type": "omni", "joints": ["x", "y", "theta"]}
    named = _changed(drive=planar)
    unnamed = _changed(drive={"type": "omni"})
    assert _counts(compare(named, unnamed, world))["torso/neck/drive"] == (2, 2)
    other = _changed(drive={"type": "omni", "joints": ["y", "x", "theta"]})
    assert _counts(compare(named, other, world))["torso/neck/drive"] == (1, 2)


def _holdout_id() -> str:
    from tools.corpus import extract_github, fetch

    ids = [p.id for p in fetch.load_manifest()] + [g.id for g in extract_github.load_manifest()]
    return next(i for i in ids if half(i) == "holdout")


def test_a_holdout_robot_is_refused_before_anything_is_loaded(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    secret = _holdout_id()
    for side in ("first", "second"):
        (tmp_path / side).mkdir()
        (tmp_path / side / "r.yaml").write_text(yaml.safe_dump({"robot": secret}))

    def never() -> None:
        raise AssertionError("nothing may be loaded for the held-out half")

    monkeypatch.setattr(agreement, "corpus_robots", never)
    folders = ["--first", str(tmp_path / "first"), "--second", str(tmp_path / "second")]
    assert agreement.main(folders) == 2
    assert "refused" in capsys.readouterr().err
    assert agreement.main([*folders, "--drafter"]) == 2
    assert agreement.main(["--only", secret]) == 2


def _real() -> list[Any]:
    """The robots of ``REAL`` whose files are on disk, else a skip naming the command."""
    from tools.corpus import fetch

    robots = []
    for p in fetch.load_manifest():
        if p.id in REAL:
            if not p.urdf_path.is_file():
                pytest.skip(f"needs the corpus cache ({p.folder}): python -m tools.corpus.fetch")
            from tools.corpus.measure import CorpusRobot

            pp = tuple(p.folder / x for x in p.package_paths)
            robots.append(CorpusRobot(p.id, p.half, p.urdf_path, p.srdf_path, pp, p.xacro_args))
    assert [r.half for r in robots] == ["tune"] * len(REAL)
    return robots


def _copy_truths(tmp_path: Path) -> tuple[Path, Path, dict[str, dict[str, Any]]]:
    first, second = tmp_path / "first", tmp_path / "second"
    first.mkdir()
    second.mkdir()
    data = {}
    for rid in REAL:
        name = rid.replace("/", "__") + ".yaml"
        text = (DATA / "blind_truth" / name).read_text(encoding="utf-8")
        (first / name).write_text(text, encoding="utf-8")
        data[rid] = yaml.safe_load(text)
    (second / "unloadable.yaml").write_text("# could not load: a missing mesh package\n")
    return first, second, data


def _totals(out: str, label: str) -> str:
    return next(ln for ln in out.splitlines() if ln.startswith(f"| {label} | {len(REAL)} |"))


def test_real_truths_agree_with_themselves_and_perturbations_count(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    robots = _real()
    monkeypatch.setattr(agreement, "corpus_robots", lambda: (robots, []))
    first, second, data = _copy_truths(tmp_path)
    for rid, t in data.items():
        (second / (rid.replace("/", "__") + ".yaml")).write_text(yaml.safe_dump(t))
    args = ["--first", str(first), "--second", str(second)]
    assert agreement.main(args) == 0
    out = capsys.readouterr()
    assert "unloadable.yaml: no truth (a comment only)" in out.err
    same = _totals(out.out, "first")
    assert _cells(same) == _cells(_totals(out.out, "second"))
    assert all(c.endswith("(100 %)") or c == "-" for c in same.strip("| ").split(" | ")[2:])
    # Perturbed copies: a finger tip changed, one more camera, another drive.
    base = _cells(same)
    grip_robot = next(
        rid
        for rid, t in data.items()
        if any(m.get("fingers") for m in (t.get("manipulators") or {}).values())
    )
    for rid, t in data.items():
        t = copy.deepcopy(t)
        if rid == grip_robot:
            m = next(m for m in t["manipulators"].values() if m.get("fingers"))
            m["fingers"] = ["not_a_tip_of_the_first", *m["fingers"][1:]]
        t["cameras"] = [*(t.get("cameras") or []), f"extra_camera_of_{rid.split('/')[1]}"]
        drive = (t.get("drive") or {"type": "fixed"})["type"]
        t["drive"] = {"type": "omni" if drive != "omni" else "differential"}
        (second / (rid.replace("/", "__") + ".yaml")).write_text(yaml.safe_dump(t))
    assert agreement.main([*args, "--wrong"]) == 0
    out = capsys.readouterr().out
    got = _cells(_totals(out, "first"))
    n = len(REAL)
    assert got["grippers/hands"] == (base["grippers/hands"][0] - 1, base["grippers/hands"][1] + 1)
    assert got["cameras"] == (base["cameras"][0], base["cameras"][1] + n)
    tnd = base["torso/neck/drive"]
    assert got["torso/neck/drive"] == (tnd[0] - n, tnd[1])
    assert got["chains"] == base["chains"] and got["tool frames"] == base["tool frames"]
    assert _cells(_totals(out, "second")) == got
    assert f"- {grip_robot}: grippers/hands: the other's" in out


def _cells(row: str) -> dict[str, tuple[int, int]]:
    cells = row.strip("| ").split(" | ")[2:]
    out = {}
    for c, cell in zip(agreement.AGREEMENT, cells, strict=True):
        got, of = cell.split(" ")[0].split("/") if cell != "-" else ("0", "0")
        out[c] = (int(got), int(of))
    return out


def test_drafter_mode_scores_one_draft_against_each_truth(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # The drafting itself is measure's (tested there); here: both truths, same robots, side by side.
    from tools.draft_score import RobotScore

    robots = _real()
    first, second, data = _copy_truths(tmp_path)
    for rid, t in data.items():
        (second / (rid.replace("/", "__") + ".yaml")).write_text(yaml.safe_dump(t))
    seen: list[tuple[str, int]] = []

    def fake(robot: Any, truth: Truth, tmp: Path) -> tuple[RobotScore, str]:
        seen.append((robot.id, id(truth)))
        s = RobotScore(robot.id)
        s.add("valid", True, "")
        s.add("chains", truth is not None, "a chain")
        return s, ""

    monkeypatch.setattr(agreement, "corpus_robots", lambda: (robots, []))
    monkeypatch.setattr(agreement, "measure_robot", fake)
    assert agreement.main(["--first", str(first), "--second", str(second), "--drafter"]) == 0
    out = capsys.readouterr().out
    assert len(seen) == 2 * len(REAL) and len(set(seen)) == 2 * len(REAL)
    assert f"| first truths | {len(REAL)} | {len(REAL)}/{len(REAL)} (100 %) |" in out
    assert f"| second truths | {len(REAL)} |" in out


def test_measure_scores_against_another_truth_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # ``measure --truth DIR``: only the robots DIR has a truth for; a comment-only file skipped.
    from tools.corpus import measure
    from tools.draft_score import RobotScore

    robots = [measure.CorpusRobot(f"x/r{i}", "tune", Path("a.urdf"), None, (), {}) for i in (1, 2)]
    (tmp_path / "x__r1.yaml").write_text("robot: x/r1\ndrive: {type: omni}\n")
    (tmp_path / "x__r2.yaml").write_text("# could not load: no such package\n")
    scored: list[dict[str, Any]] = []

    def fake(robot: measure.CorpusRobot, truth: Truth, tmp: Path) -> tuple[RobotScore, str]:
        scored.append(truth.data)
        s = RobotScore(robot.id)
        s.add("valid", True, "")
        return s, ""

    monkeypatch.setattr(measure, "corpus_robots", lambda: (robots, []))
    monkeypatch.setattr(measure, "measure_robot", fake)
    assert measure.main(["--truth", str(tmp_path)]) == 0
    out = capsys.readouterr()
    assert scored == [{"robot": "x/r1", "drive": {"type": "omni"}}]
    assert "| x/r1 |" in out.out and "x/r2" not in out.out
    assert "x__r2.yaml: no truth (a comment only)" in out.err
    assert "left out: 1 robots without a truth" in out.err


def test_a_truth_missing_a_key_the_counting_reads_is_skipped_with_its_file(tmp_path: Path) -> None:
    from tools.corpus.truths import load_truth_folder

    (tmp_path / "a.yaml").write_text("robot: x/a\nchains: {arm: {root: base}}\n")
    (tmp_path / "b.yaml").write_text(
        "robot: x/b\nmanipulators: {g: {type: parallel_gripper, tool_frame: t}}\n"
    )
    (tmp_path / "c.yaml").write_text("robot: x/c\n")
    truths, skipped = load_truth_folder(tmp_path)
    assert list(truths) == ["x/c"]
    assert skipped == [
        "a.yaml: chain arm needs root and tip",
        "b.yaml: manipulator g (parallel_gripper) needs fingers",
    ]


def test_cohens_kappa_of_the_drive_types() -> None:
    labels = [("fixed", "fixed"), ("omni", "omni"), ("fixed", "omni"), ("omni", "omni")]
    # Observed 3/4; by chance 1/2 * 1/4 + 1/2 * 3/4 = 1/2; kappa (3/4 - 1/2) / (1 - 1/2).
    line = agreement._kappa_line(labels)
    assert line.endswith("agree on 3 of 4, chance 0.50, Cohen's kappa 0.50.")
    assert "undefined" in agreement._kappa_line([("fixed", "fixed")] * 3)
