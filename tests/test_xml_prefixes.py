"""URDFs with XML prefixes they never declare (Drake writes ``drake:`` so) are read, with a warning.

urdfdom and pinocchio read such files; robotspec refused the whole file. The prefixes are now
declared for the parse (a namespace of robotspec's own), the extension elements stay what they
are to URDF (unknown, unused), and ``validate`` says once per file which prefixes were undeclared.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.errors import DescriptionError
from robotspec.files.xmlsafe import UNDECLARED_NAMESPACE, parse_xml_bytes, undeclared_prefixes

DRAKE_ARM = """<?xml version="1.0"?>
<!-- written by a tool that forgot xmlns:drake -->
<robot name="arm">
  <link name="base">
    <drake:proximity_properties><drake:mu_static value="0.5"/></drake:proximity_properties>
  </link>
  <link name="tip"/>
  <joint name="j1" type="revolute" drake:ignore="1">
    <parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <sdf:extra/>
</robot>
"""


def test_undeclared_prefixes_are_declared_for_the_parse() -> None:
    root = parse_xml_bytes(DRAKE_ARM.encode(), "arm.urdf")
    assert undeclared_prefixes(root) == ["drake", "sdf"]
    joint = root.find("joint")
    assert joint is not None
    assert joint.get(f"{{{UNDECLARED_NAMESPACE}drake}}ignore") == "1"
    assert [el.tag for el in root if isinstance(el.tag, str)][
        -1
    ] == f"{{{UNDECLARED_NAMESPACE}sdf}}extra"


def test_a_declared_file_is_untouched() -> None:
    root = parse_xml_bytes(
        b'<robot name="r" xmlns:drake="http://drake.mit.edu"><link name="a"/></robot>', "r"
    )
    assert undeclared_prefixes(root) == []
    assert root.nsmap == {"drake": "http://drake.mit.edu"}


@pytest.mark.parametrize(
    ("text", "where"),
    [
        # another fault beside the prefix: that fault, at its own column
        (b'<robot><a x:y="1"><b></robot>', "r.urdf:1:29: error: malformed XML: Opening and ending"),
        (b"<robot>\n<x:a>\n<b></robot>", "r.urdf:3:11: error: malformed XML: Opening and ending"),
    ],
)
def test_other_faults_keep_their_place(text: bytes, where: str) -> None:
    with pytest.raises(DescriptionError) as info:
        parse_xml_bytes(text, "r.urdf")
    assert str(info.value).startswith(where)


def test_validate_reads_the_file_and_warns_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "arm.urdf").write_text(DRAKE_ARM)
    (tmp_path / "arm.yaml").write_text(
        "robotspec: 1\nname: Arm\ndescription: {urdf: arm.urdf}\nroot: base\n"
        "chains:\n  arm: {root: base, tip: tip}\n"
    )
    code = run_app(app, ["validate", str(tmp_path / "arm.yaml")])
    out, err = capsys.readouterr()
    text = out + err
    assert code == 0, text
    assert text.count("used without a declaration") == 1
    assert "arm.urdf:3: warning: XML prefixes 'drake:', 'sdf:' used" in text, text
