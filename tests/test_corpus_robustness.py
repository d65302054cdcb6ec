"""The robustness tool's own pieces (issue 30): which robots a round keeps blind, neutral ids."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from tools.corpus.robustness import blind_ids, rename_map

MANIFEST = """\
robots:
  - id: gh/old_arm
    half: tune
  # round 9a: new legged robots
  - id: gh/new_dog
    half: tune
  - id: gh/new_hexapod
    half: holdout
  # round 9b (another helper)
  - id: gh/new_gripper
    half: tune
"""


def test_blind_ids_skip_only_the_rounds_named(tmp_path: Path) -> None:
    m = tmp_path / "github.yaml"
    m.write_text(MANIFEST, encoding="utf-8")
    assert blind_ids([m], []) == frozenset()
    assert blind_ids([m], ["9a"]) == {"gh/new_dog", "gh/new_hexapod"}
    assert blind_ids([m], ["9A", "9b"]) == {"gh/new_dog", "gh/new_hexapod", "gh/new_gripper"}
    assert blind_ids([m], ["8a"]) == frozenset()


def test_rename_map_gives_neutral_ids_in_document_order() -> None:
    root = etree.fromstring(
        b"<robot name='r'><link name='base'/><link name='tool0'/>"
        b"<joint name='flange' type='fixed'><parent link='base'/><child link='tool0'/></joint>"
        b"</robot>"
    )
    ren = rename_map(root)
    assert ren.links == {"base": "n0", "tool0": "n1"}
    assert ren.joints == {"flange": "q0"}
