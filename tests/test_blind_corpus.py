"""The blind corpus's manifests and truths are consistent (issue 30); nothing here drafts.

Every manifest of ``tests/data/blind_corpus/`` lists robots whose ``half`` is the salted hash's
answer (``tools.corpus.split.half``), never a choice, and each robot has a truth file in
``tests/data/blind_truth/`` in the format of ``tests/data/draft_truth`` (only known keys).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from tools.corpus.split import half

DATA = Path(__file__).resolve().parent / "data"
MANIFESTS = sorted((DATA / "blind_corpus").glob("*.yaml"))
TRUTHS = DATA / "blind_truth"

TOP = {"robot", "forward", "chains", "manipulators", "cameras", "torso", "neck", "drive"}
CHAIN = {"root", "tip", "kind"}
MANIPULATOR = {"type", "tool_frame", "thumb", "fingers"}
PART = {"root", "tip"}
DRIVE = {"type", "joints"}


def _entries(path: Path) -> list[dict[str, Any]]:
    data = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    robots = data.get("robots") or []
    assert isinstance(robots, list)
    return robots


def _all() -> list[tuple[str, dict[str, Any]]]:
    return [(p.name, e) for p in MANIFESTS for e in _entries(p)]


def test_the_pypi_manifest_is_there() -> None:
    assert DATA / "blind_corpus" / "pypi.yaml" in MANIFESTS
    assert len(_entries(DATA / "blind_corpus" / "pypi.yaml")) >= 25


def test_ids_are_unique_across_manifests() -> None:
    ids = [e["id"] for _, e in _all()]
    assert len(ids) == len(set(ids)), sorted(i for i in ids if ids.count(i) > 1)


@pytest.mark.parametrize(
    ("manifest", "entry"), _all(), ids=lambda v: v if isinstance(v, str) else v["id"]
)
def test_half_is_the_salted_hash(manifest: str, entry: dict[str, Any]) -> None:
    assert entry["half"] == half(entry["id"]), f"{manifest}: {entry['id']}"


@pytest.mark.parametrize(
    ("manifest", "entry"), _all(), ids=lambda v: v if isinstance(v, str) else v["id"]
)
def test_every_robot_has_a_truth_of_known_keys(manifest: str, entry: dict[str, Any]) -> None:
    path = TRUTHS / (entry["id"].replace("/", "__") + ".yaml")
    assert path.is_file(), f"{manifest}: {entry['id']} has no truth {path.name}"
    text = path.read_text(encoding="utf-8")
    assert text.startswith("#"), f"{path.name}: the truth starts with a comment saying what it is"
    t = yaml.safe_load(text)
    assert t["robot"] == entry["id"]
    assert set(t) <= TOP, set(t) - TOP
    for name, c in (t.get("chains") or {}).items():
        assert set(c) <= CHAIN and {"root", "tip"} <= set(c), name
        assert c.get("kind", "arm") in ("arm", "leg", "chain"), name
    for name, m in (t.get("manipulators") or {}).items():
        assert set(m) <= MANIPULATOR and {"type", "tool_frame"} <= set(m), name
        assert m["type"] in ("parallel_gripper", "hand", "generic"), name
        tool = m["tool_frame"]
        assert isinstance(tool, str) or (isinstance(tool, dict) and set(tool) == {"parent"}), name
        if m["type"] == "parallel_gripper":
            assert len(m["fingers"]) == 2 and "thumb" not in m, name
        if m["type"] == "hand":
            assert isinstance(m["thumb"], str) and len(m["fingers"]) >= 1, name
    assert all(isinstance(c, str) for c in t.get("cameras") or [])
    for key in ("torso", "neck"):
        assert t.get(key) is None or set(t[key]) == PART, key
    drive = t.get("drive") or {"type": "fixed"}
    assert set(drive) <= DRIVE and drive["type"] in ("omni", "differential", "fixed", "floating")
    if "joints" in drive:
        assert len(drive["joints"]) == 3
    if "forward" in t:
        assert len(t["forward"]) == 3


def test_every_truth_is_listed() -> None:
    listed = {e["id"].replace("/", "__") for _, e in _all()}
    orphans = sorted(p.stem for p in TRUTHS.glob("*.yaml") if p.stem not in listed)
    assert not orphans, f"truths without a manifest entry: {orphans}"


def test_the_holdout_is_measured_as_totals_only(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # The protocol in code: nothing per robot of the holdout half is printed.
    from tools.corpus import measure
    from tools.draft_score import RobotScore

    robots = [
        measure.CorpusRobot(f"x/secret_{h}", h, Path("a.urdf"), None, (), {})
        for h in ("tune", "holdout")
    ]

    def fake(robot: measure.CorpusRobot, truth: object, tmp: Path) -> tuple[RobotScore, str]:
        s = RobotScore(robot.id)
        s.add("valid", False, "the draft does not validate", marked=False)
        s.add("chains", False, "arm not drafted", marked=False)
        return s, "init: a problem"

    monkeypatch.setattr(measure, "corpus_robots", lambda: (robots, []))
    monkeypatch.setattr(measure, "measure_robot", fake)

    class Truths(dict[str, object]):
        def __missing__(self, key: str) -> object:
            return None

    monkeypatch.setattr(measure, "_truths", lambda: Truths())
    assert measure.main(["--half", "holdout"]) == 0
    out = capsys.readouterr().out
    assert "secret" not in out and "not drafted" not in out and "problem" not in out
    assert "| holdout | 1 | 0/1 (0 %) | 0/1 (0 %) |" in out
    assert measure.main(["--half", "tune"]) == 0
    assert "x/secret_tune" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        measure.main(["--half", "holdout", "--only", "x/secret_holdout"])
    # A group of five ids (e.g. the robots one round added) is measured as totals only too.
    group = ["x/secret_holdout", "a/1", "a/2", "a/3", "a/4"]
    assert measure.main(["--half", "holdout", "--only", *group]) == 0
    out = capsys.readouterr().out
    assert "secret" not in out and "| holdout | 1 | 0/1 (0 %) |" in out


def test_shares_stay_inside_the_third_partys_tree(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A manifest's share paths are copied out of a repository nobody here wrote: a file link
    # planted there, or a path leaving the tree, is refused; a link inside a folder stays a link.
    from tools.corpus import extract_github as eg

    monkeypatch.setattr(eg, "cache_root", lambda: tmp_path)
    secret = tmp_path / "secret.txt"
    secret.write_text("not the robot's")

    def robot(share: dict[str, tuple[str, ...]]) -> eg.GithubRobot:
        return eg.GithubRobot("gh/x", "o/r", "c", "a.urdf", None, {}, (), "tune", "", share)

    tree = robot({}).folder
    (tree / "pkg" / "urdf").mkdir(parents=True)
    (tree / "pkg" / "urdf" / "a.xacro").write_text("<robot/>")
    (tree / "pkg" / "urdf" / "inner").symlink_to(secret)
    (tree / "planted").symlink_to(secret)
    eg.install_shares(robot({"pkg": ("pkg/urdf",)}))
    copied = tree / "_share" / "pkg" / "urdf"
    assert (copied / "a.xacro").read_text() == "<robot/>"
    assert (copied / "inner").is_symlink()
    for bad in ("planted", "../secret.txt"):
        with pytest.raises(ValueError, match="link or leaves the tree"):
            eg.install_shares(robot({"other": (bad,)}))
    assert not (tree / "_share" / "other").exists()
