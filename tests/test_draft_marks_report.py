"""The corpus measure's rule table ends with how many items a draft states without a mark."""

from __future__ import annotations

from tools.corpus.measure import rule_lines
from tools.draft_score import ASKED, MARKED, RobotScore


def test_the_rule_table_counts_the_items_left_without_a_mark() -> None:
    s = RobotScore("r")
    s.rules = {
        MARKED: [10, 2],
        ASKED: [1, 1],
        "camera: a Gazebo sensor": [3, 1],
        "(no rule)": [1, 0],
    }
    lines = rule_lines([s])
    assert lines[-1] == "Items without a mark: 4 of 15 (1 wrong)."
    assert "| camera: a Gazebo sensor | 3 | 1 |" in lines
