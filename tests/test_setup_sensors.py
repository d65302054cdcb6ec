"""A sensor's chain in the setup assistant: the Kinova's wrist camera carried by its arm."""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.compiler import check_spec
from robotspec.setup import SetupSession
from robotspec.setup.edits_sensors import NO_CARRIER
from robotspec.setup.session import SetupError
from tests.conftest import erd_robots


def _kinova(tmp_path: Path) -> SetupSession:
    kinova = erd_robots() / "kinova_description"
    if not kinova.is_dir():
        pytest.skip("example-robot-data without kinova_description")
    return SetupSession.open(
        str(kinova / "robots" / "kinova.urdf"),
        srdf=str(kinova / "srdf" / "kinova.srdf"),
        output=tmp_path / "kinova.yaml",
    )


def test_a_wrist_camera_on_the_arm_saves_without_the_no_chain_warning(tmp_path: Path) -> None:
    s = _kinova(tmp_path)
    for q in s.snapshot.questions:
        s.answer(q.id)
    v = s.add_camera("wrist_camera", "j2s6s200_link_6")
    assert [p.message for p in v.at("sensors.wrist_camera")] == [
        "sensors.wrist_camera: sensor 'wrist_camera' is on no chain "
        "(no chain and no neck carries it)"
    ]
    assert s.sensor_carrier("sensors.wrist_camera") == NO_CARRIER
    assert s.carriers() == (NO_CARRIER, "chains.end_effector")
    s.answer("sensors.wrist_camera.field_of_view", "preset: realsense_d435")
    v = s.set_sensor_carrier("sensors.wrist_camera", "chains.end_effector")
    assert v.valid and not v.at("sensors.wrist_camera")
    assert "    sensors: [wrist_camera]\n" in s.snapshot.text
    assert s.sensor_carrier("sensors.wrist_camera") == "chains.end_effector"
    saved = s.save()
    # What remains is the robot's own SRDF's (a group_state without a group), no spec's.
    warnings = [d.message for d in check_spec(saved).warnings]
    assert warnings == ["group_state 'arm_up' has no group attribute"], warnings
    # Off the chain again: the line goes, the warning comes back.
    v = s.set_sensor_carrier("sensors.wrist_camera", NO_CARRIER)
    assert "sensors: [wrist_camera]" not in s.snapshot.text and v.at("sensors.wrist_camera")
    with pytest.raises(SetupError, match="torso carries no sensors"):
        s.set_sensor_carrier("sensors.wrist_camera", "torso")
    with pytest.raises(SetupError, match="no chain 'nope'"):
        s.set_sensor_carrier("sensors.wrist_camera", "chains.nope")
