"""Robots whose collision geometry is missing or has no volume: said plainly, never a crash.

Real files have zero-radius spheres (ARMAR-4 has six) and robots without any ``<collision>``;
before, the first stopped every collision command at the first such link, one per run, and the
second "passed" with 0 pairs.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app

JOINT = (
    '<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/>'
    '<origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>'
    '<limit lower="-2" upper="2" velocity="1" effort="1"/></joint>\n'
)


def robot(folder: Path, collisions: list[str]) -> Path:
    links = [f"l{i}" for i in range(len(collisions))]
    body = "".join(
        f'<link name="{n}">'
        + (f"<collision><geometry>{c}</geometry></collision>" if c else "")
        + "</link>\n"
        for n, c in zip(links, collisions, strict=True)
    )
    body += "".join(
        JOINT.format(n=f"j{i}", p=links[i - 1], c=links[i]) for i in range(1, len(links))
    )
    (folder / "r.urdf").write_text(f'<robot name="r">\n{body}</robot>\n')
    spec = folder / "r.yaml"
    spec.write_text("robotspec: 1\nname: R\ndescription: {urdf: r.urdf}\nroot: l0\n")
    return spec


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out + out.err


COMMANDS = [
    (["collisions", "check"], "check collisions"),
    (["collisions", "generate", "-n", "20"], "generate the matrix for"),
    (["collisions", "audit", "-n", "20"], "audit"),
]


@pytest.mark.parametrize(("argv", "said"), COMMANDS, ids=["check", "generate", "audit"])
def test_no_collision_geometry_is_said_plainly(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], said: str
) -> None:
    spec = robot(tmp_path, ["", '<sphere radius="0"/>', ""])
    code, text = cli(capsys, *argv, str(spec))
    assert code == 1
    assert text == (
        f"{tmp_path / 'r.urdf'}: error: robot 'R' has no collision geometry (no <collision> "
        f"element with a volume in r.urdf): nothing to {said}\n"
    )


def test_one_body_with_geometry_has_no_pair(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = robot(tmp_path, ['<box size="0.1 0.1 0.1"/>', "", ""])
    code, text = cli(capsys, "collisions", "check", str(spec))
    assert code == 1
    assert "collision geometry on one body only ('l0' in r.urdf): no pair to check" in text


def test_zero_sized_elements_are_left_out_with_one_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ball = '<sphere radius="0.05"/>'
    spec = robot(
        tmp_path,
        [ball, '<sphere radius="0"/>', ball, '<cylinder radius="0.1" length="0"/>', ball, ball],
    )
    for argv in (["collisions", "check", "--distances"], ["collisions", "generate", "-n", "50"]):
        code, text = cli(capsys, *argv, str(spec))
        assert code == 0, text
        warnings = [line for line in text.splitlines() if "of zero size" in line]
        assert len(warnings) <= 1, text
    code, text = cli(capsys, "collisions", "check", "--ignore-srdf", str(spec))
    assert code == 0, text
    assert (
        f"{tmp_path / 'r.urdf'}:3: warning: 2 collision elements of zero size left out (no "
        "volume to collide with): 'l1' (sphere, line 3), 'l3' (cylinder, line 5)"
    ) in text


def test_a_negative_size_is_still_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ball = '<sphere radius="0.05"/>'
    spec = robot(tmp_path, [ball, ball, '<sphere radius="-0.1"/>'])
    code, text = cli(capsys, "collisions", "check", str(spec))
    assert code == 1, text
    assert "non-positive or non-finite dimension" in text or "radius" in text
