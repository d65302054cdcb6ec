"""The Robot Raconteur ``RobotInfo`` YAML, as strict, located Pydantic models.

This module reads a file (:func:`read_robot_info`) and serves every name of the models
(:mod:`~robotspec.driver.robot_info_models`) and of their enums; the cross-field checks are
:mod:`~robotspec.driver.robot_info_checks`.

Why strict: the reference parser (Robot Raconteur Companion ``InfoParser``) silently ignores unknown
keys, so a misspelt ``acceleraton`` leaves the acceleration at 0 and fails much later with a bare
assertion. Here every model forbids extra keys, enums are checked by name, array lengths are checked
against the chain's joint count, and every problem is a :class:`~robotspec.errors.RobotInfoError`
with the file and line of the offending YAML node (through
:func:`robotspec.files.yamlio.load_yaml`).

The field names are the robdef field names (stdver 0.10), so any file the reference accepts and that
has no typos loads here too. Loading never writes anywhere: unlike the reference ``InfoFileLoader``
no device UUID is assigned or persisted, and no lock file is taken.

Things the reference accepts that are only *warnings* here (so all real files still load): a chain
without ``flange_pose`` (identity is used, as the reference does silently) and ``continuous`` joints
(driven as revolute).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pydantic import ValidationError

from robotspec.driver.robot_info_checks import MAX_OFFSET_M, UNIT_TOL, semantic_checks
from robotspec.driver.robot_info_enums import (
    CAPABILITY_BITS,
    JointEffortUnits,
    JointPositionUnits,
    JointType,
    RobotCapability,
    RobotTypeCode,
    ToolCapability,
    ToolTypeCode,
)
from robotspec.driver.robot_info_models import (
    MAX_LIMIT,
    QUAT_TOL,
    DeviceClass,
    DeviceInfo,
    Identifier,
    JointInfo,
    JointLimits,
    KinChainInfo,
    NamedPose,
    PayloadInfo,
    Pose,
    Quaternion,
    RobotInfo,
    SpatialInertia,
    SpatialVector,
    ToolInfo,
    Transform,
    Vector3,
)
from robotspec.errors import RobotInfoError, RobotSpecErrors
from robotspec.files.validation import validation_errors
from robotspec.files.yamlio import LocatedYaml, load_yaml, load_yaml_text

__all__ = [
    "CAPABILITY_BITS",
    "MAX_LIMIT",
    "MAX_OFFSET_M",
    "QUAT_TOL",
    "UNIT_TOL",
    "DeviceClass",
    "DeviceInfo",
    "Identifier",
    "JointEffortUnits",
    "JointInfo",
    "JointLimits",
    "JointPositionUnits",
    "JointType",
    "KinChainInfo",
    "LoadedRobotInfo",
    "NamedPose",
    "PayloadInfo",
    "Pose",
    "Quaternion",
    "RobotCapability",
    "RobotInfo",
    "RobotTypeCode",
    "SpatialInertia",
    "SpatialVector",
    "ToolCapability",
    "ToolInfo",
    "ToolTypeCode",
    "Transform",
    "Vector3",
    "load_robot_info",
    "read_robot_info",
    "read_robot_info_text",
]


@dataclass(frozen=True)
class LoadedRobotInfo:
    """A validated RobotInfo, the file it came from and the warnings found while loading."""

    info: RobotInfo
    file: str
    warnings: tuple[RobotInfoError, ...] = ()


def _read(doc: LocatedYaml) -> LoadedRobotInfo:
    if not isinstance(doc.data, dict):
        raise RobotInfoError("a RobotInfo file must be a YAML mapping", file=doc.file, line=1)
    try:
        info = RobotInfo.model_validate(doc.data)
    except ValidationError as exc:
        raise validation_errors(exc, doc, RobotInfo, RobotInfoError) from None
    errors, warnings = semantic_checks(info, doc)
    if errors:
        if len(errors) == 1:
            raise errors[0]
        raise RobotSpecErrors(errors, summary=f"{doc.file}: {len(errors)} problems")
    return LoadedRobotInfo(info=info, file=doc.file, warnings=tuple(warnings))


def read_robot_info(path: str | Path) -> LoadedRobotInfo:
    """Load and validate a RobotInfo YAML file, keeping the warnings.

    Raises:
        RobotInfoError: one located problem.
        RobotSpecErrors: several, all reported at once.
    """
    doc = load_yaml(path)
    return _read(doc)


def read_robot_info_text(text: str, file: str = "<string>") -> LoadedRobotInfo:
    """Like :func:`read_robot_info`, from text (tests, generated files)."""
    return _read(load_yaml_text(text, file=file))


def load_robot_info(path: str | Path) -> RobotInfo:
    """Load and validate a RobotInfo YAML file; warnings are dropped (see ``read_robot_info``)."""
    return read_robot_info(path).info
