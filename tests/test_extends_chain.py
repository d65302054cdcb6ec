"""A spec's ``extends`` chain: followed in a loop, capped, a cycle located (issue 31).

A chain 1,100 files deep was ``internal error: RecursionError`` (exit 3); it is a located error
at the ``extends`` line past ``ROBOTSPEC_MAX_EXTENDS_DEPTH``, and with the cap raised it loads.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.errors import SpecError
from robotspec.spec.load import load_spec

URDF = '<robot name="r"><link name="base"/></robot>\n'


def chain(folder: Path, files: int) -> Path:
    """``s0.yaml`` extends ``s1.yaml`` ... extends ``s{files-1}.yaml``, the only full spec."""
    (folder / "r.urdf").write_text(URDF)
    for n in range(files):
        head = (
            f"extends: s{n + 1}.yaml\n"
            if n < files - 1
            else "robotspec: 1\nroot: base\ndescription: {urdf: r.urdf}\n"
        )
        (folder / f"s{n}.yaml").write_text(head + f"name: s{n}\n")
    return folder / "s0.yaml"


def test_a_chain_past_the_cap_is_an_error_at_the_extends_that_goes_too_far(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    first = chain(tmp_path, 1_100)
    code = run_app(app, ["validate", str(first)])
    out = capsys.readouterr()
    assert code == 1
    assert (out.out + out.err).splitlines()[0] == (
        f"{tmp_path / 's100.yaml'}:1:10: error: 'extends' chain longer than 100 files "
        "(set ROBOTSPEC_MAX_EXTENDS_DEPTH to raise it)"
    )


def test_the_cap_counts_the_files_beyond_the_spec(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROBOTSPEC_MAX_EXTENDS_DEPTH", "3")
    assert load_spec(chain(tmp_path, 4)).spec.name == "s0"
    with pytest.raises(SpecError, match=r"s3.yaml:1:10: error: 'extends' chain longer than 3"):
        load_spec(chain(tmp_path, 5))


def test_a_raised_cap_loads_a_chain_deeper_than_python_s_stack(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROBOTSPEC_MAX_EXTENDS_DEPTH", "2000")
    loaded = load_spec(chain(tmp_path, 1_100))
    assert loaded.spec.name == "s0"
    assert loaded.spec.root == "base"
    assert len(loaded.documents) == 1_100
    assert loaded.position(("root",)) == (str(tmp_path / "s1099.yaml"), 2, 7)


def test_a_cycle_is_located_at_the_extends_that_closes_it(tmp_path: Path) -> None:
    (tmp_path / "a.yaml").write_text("name: a\nextends: b.yaml\n")
    (tmp_path / "b.yaml").write_text("extends: a.yaml\nname: b\n")
    with pytest.raises(SpecError) as info:
        load_spec(tmp_path / "a.yaml")
    assert str(info.value) == (
        f"{tmp_path / 'b.yaml'}:1:10: error: 'extends' forms a cycle: a.yaml -> b.yaml -> a.yaml"
    )
    (tmp_path / "c.yaml").write_text("extends: c.yaml\n")
    with pytest.raises(SpecError, match=r"c.yaml:1:10: error: 'extends' forms a cycle: c.yaml"):
        load_spec(tmp_path / "c.yaml")
