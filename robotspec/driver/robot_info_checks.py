"""Cross-field checks of a RobotInfo that pydantic cannot locate well, each at its YAML line.

Why a module of its own: the models (:mod:`robotspec.driver.robot_info_models`) check one field at a
time; what spans fields (array lengths against a chain's joint count, joint numbers against
``joint_info``, names the service will serve) is checked here, after validation, and every
problem found is reported at once, as an error or (where the reference accepts it silently) a
warning.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from robotspec.driver.robot_info_enums import DRIVABLE_JOINT_TYPES, JointType
from robotspec.driver.rr_names import rr_name_problem, rr_name_suggestion
from robotspec.errors import RobotInfoError
from robotspec.files.yamlio import LocatedYaml

if TYPE_CHECKING:
    from robotspec.driver.robot_info_models import KinChainInfo, RobotInfo, Vector3

__all__ = ["MAX_OFFSET_M", "UNIT_TOL", "semantic_checks"]

#: Axis vectors must be unit length to this tolerance (the toolbox asserts the same).
UNIT_TOL = 1e-6
#: Largest magnitude of a link offset or flange position, metres. Why a bound: finite but absurd
#: values (1e200) make the pose and twist arithmetic overflow to infinity in the loop.
MAX_OFFSET_M = 1e3

Loc = tuple[str | int, ...]


@dataclass
class _Findings:
    """The errors and warnings found so far, each located in the document."""

    doc: LocatedYaml
    errors: list[RobotInfoError] = field(default_factory=list)
    warnings: list[RobotInfoError] = field(default_factory=list)

    def add(self, msg: str, loc: Loc, *, warn: bool = False) -> None:
        # Point at the key when the problem is the whole value (a list of the wrong length).
        doc = self.doc
        line, col = doc.key_position(loc) if isinstance(loc[-1], str) else doc.position(loc)
        e = RobotInfoError(
            msg,
            file=doc.file,
            line=line,
            column=col,
            location=loc,
            severity="warning" if warn else "error",
        )
        (self.warnings if warn else self.errors).append(e)


def semantic_checks(
    info: RobotInfo, doc: LocatedYaml
) -> tuple[list[RobotInfoError], list[RobotInfoError]]:
    """Cross-field checks pydantic cannot locate well: (errors, warnings)."""
    found = _Findings(doc)
    _check_device(info, found)
    _check_joints(info, found)
    used: dict[int, int] = {}
    for c, chain in enumerate(info.chains):
        _check_chain(c, chain, len(info.joint_info), used, found)
    return found.errors, found.warnings


def _check_device(info: RobotInfo, found: _Findings) -> None:
    device = info.device_info.device
    name_problem = rr_name_problem(device.name) if device.name else None
    if name_problem and device.uuid is None:
        # Served, the device name becomes the node name and its identifier's lock file.
        found.add(
            f"device_info.device.name '{device.name}' {name_problem}: Robot Raconteur cannot "
            "use it as a device name (letters, digits, '_', '.' and '-', starting with a "
            f"letter); did you mean '{rr_name_suggestion(device.name)}'?",
            ("device_info", "device", "name"),
        )
    if not info.joint_info:
        found.add("joint_info must list at least one joint", ("joint_info",))
    if not info.chains:
        found.add("chains must list at least one kinematic chain", ("chains",))


def _check_joints(info: RobotInfo, found: _Findings) -> None:
    seen_names: dict[str, int] = {}
    for i, j in enumerate(info.joint_info):
        name = j.joint_identifier.name
        loc: Loc = ("joint_info", i, "joint_identifier")
        if not name:
            found.add(f"joint_info[{i}]: joint_identifier needs a name", loc)
        elif name in seen_names:
            found.add(
                f"joint_info[{i}]: joint name '{name}' repeats joint_info[{seen_names[name]}]", loc
            )
        else:
            seen_names[name] = i
        if j.joint_type not in DRIVABLE_JOINT_TYPES:
            found.add(
                f"joint_info[{i}]: joint_type '{j.joint_type.value}' cannot be driven "
                "(only revolute, prismatic or continuous)",
                ("joint_info", i, "joint_type"),
            )
        elif j.joint_type is JointType.continuous:
            found.add(
                f"joint_info[{i}]: joint_type 'continuous' is driven as revolute within its limits "
                "(the reference refuses it)",
                ("joint_info", i, "joint_type"),
                warn=True,
            )


def _check_chain(
    c: int, chain: KinChainInfo, n_joints: int, used: dict[int, int], found: _Findings
) -> None:
    """Chain ``c``: axes, offsets, array lengths, joints (``used``: joint -> its chain)."""
    n = len(chain.joint_numbers)
    where = f"chains[{c}]"
    _check_geometry(c, chain, found)
    if len(chain.H) != n:
        found.add(
            f"{where}.H has {len(chain.H)} axes but the chain has {n} joints (joint_numbers)",
            ("chains", c, "H"),
        )
    if len(chain.P) != n + 1:
        found.add(
            f"{where}.P has {len(chain.P)} vectors but needs {n + 1} (one more than joints)",
            ("chains", c, "P"),
        )
    if chain.link_identifiers and len(chain.link_identifiers) != n + 1:
        found.add(
            f"{where}.link_identifiers has {len(chain.link_identifiers)} names but needs {n + 1}",
            ("chains", c, "link_identifiers"),
        )
    if chain.link_inertias and len(chain.link_inertias) != n + 1:
        found.add(
            f"{where}.link_inertias has {len(chain.link_inertias)} entries but needs {n + 1}",
            ("chains", c, "link_inertias"),
        )
    for k, jn in enumerate(chain.joint_numbers):
        if jn >= n_joints:
            found.add(
                f"{where}.joint_numbers[{k}] names joint {jn}, but joint_info has only "
                f"{n_joints} joints (0..{n_joints - 1})",
                ("chains", c, "joint_numbers", k),
            )
        elif jn in used:
            found.add(
                f"{where}.joint_numbers[{k}]: joint {jn} already belongs to chains[{used[jn]}]",
                ("chains", c, "joint_numbers", k),
            )
        else:
            used[jn] = c
    if chain.flange_pose is None:
        found.add(
            f"{where} has no flange_pose; the identity is used (the reference does the same "
            "silently)",
            ("chains", c),
            warn=True,
        )
    if chain.current_payload is not None and chain.current_tool is None:
        found.add(f"{where}.current_payload needs a current_tool", ("chains", c, "current_payload"))


def _check_geometry(c: int, chain: KinChainInfo, found: _Findings) -> None:
    """Chain ``c``'s axes are unit vectors and its offsets within ``MAX_OFFSET_M``."""
    where = f"chains[{c}]"
    for i, h in enumerate(chain.H):
        norm = math.hypot(h.x, h.y, h.z)  # no OverflowError for 1e200
        if abs(norm - 1.0) > UNIT_TOL:
            found.add(
                f"{where}.H[{i}] must be a unit vector (norm is {norm:.6g})", ("chains", c, "H", i)
            )
    offsets: list[tuple[str, Loc, Vector3]] = [
        (f"P[{i}]", ("chains", c, "P", i), p) for i, p in enumerate(chain.P)
    ]
    if chain.flange_pose is not None:
        loc_f: Loc = ("chains", c, "flange_pose", "position")
        offsets.append(("flange_pose.position", loc_f, chain.flange_pose.position))
    for label, loc_p, p in offsets:
        big = max(abs(p.x), abs(p.y), abs(p.z))
        if big > MAX_OFFSET_M:
            found.add(f"{where}.{label} is {big:g} m from its frame (max {MAX_OFFSET_M:g})", loc_p)
