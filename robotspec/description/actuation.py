"""Which joints a URDF says are driven and how: transmissions, ros2_control, drive plugins.

Why read them: a transmission or a ``ros2_control`` joint is the file saying "a motor turns this
joint", with the interface it is commanded through. That is evidence ``robotspec init`` otherwise
guesses from names and shapes: a continuous joint commanded in velocity at the end of a branch is
a wheel whatever it is called; a joint a gripper transmission lists as passive, or a
``ros2_control`` joint with no command interface, moves with another one; a Gazebo drive plugin
(``diff_drive``, ``skid_steer_drive``, ``planar_move``, gz-sim's ``DiffDrive`` and
``MecanumDrive``) states the kind of base and its wheels.

Formats read: ROS 1 transmissions (``<joint><hardwareInterface>`` and the older
``type="pr2_mechanism_model/..."`` attribute form, with PR2's ``gap_joint``/``passive_joint`` and
wrist ``flexJoint``/``rollJoint``), ROS 2 ``<ros2_control>`` joints (``command_interface``,
``state_interface``, a ``mimic`` attribute or parameter). The tree is the safely parsed URDF
(``robotspec.files.xmlsafe``); work is one pass over the root's direct children. Nothing is
raised: this is evidence for a draft, not input the robot needs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from lxml import etree

__all__ = ["Actuation", "DrivePlugin", "read_actuation"]

#: The interfaces a joint is commanded through, by the words their names use.
_INTERFACES = ("position", "velocity", "effort")
#: Gazebo drive plugins (by a word of their file or class name) and the drive kind they state.
_DRIVE_PLUGINS = (
    ("skid_steer", "differential"),
    ("skidsteer", "differential"),
    ("diff_drive", "differential"),
    ("diffdrive", "differential"),
    ("tracked_vehicle", "differential"),
    # Car-like steering moves no sideways either: robotspec's nearest kind (the draft asks).
    ("ackerman", "differential"),
    ("mecanum", "omni"),
    ("planar_move", "omni"),
    ("omni", "omni"),
)
#: Elements of a drive plugin that name a wheel joint (classic ROS 1, ROS 2, gz-sim).
_WHEEL_TAGS = frozenset(
    {"leftJoint", "rightJoint", "left_joint", "right_joint"}
    | {"leftFrontJoint", "rightFrontJoint", "leftRearJoint", "rightRearJoint"}
    | {"front_left_joint", "front_right_joint", "back_left_joint", "back_right_joint"}
    | {"rear_left_joint", "rear_right_joint"}
)
#: PR2 mechanism-model elements naming an actuated joint, and a passive one.
_PR2_ACTUATED = frozenset({"joint", "gap_joint", "flexJoint", "rollJoint"})
_PR2_PASSIVE = frozenset({"passive_joint"})
#: Most joints recorded from one file.
_MAX_JOINTS = 100_000


@dataclass(frozen=True)
class DrivePlugin:
    """A Gazebo plugin that moves the base: its file (or class) name, kind and wheel joints."""

    plugin: str
    kind: str  # "differential" | "omni"
    wheels: tuple[str, ...]


@dataclass(frozen=True)
class Actuation:
    """What a URDF's control blocks say about its joints.

    ``joints``: every joint a transmission or ``ros2_control`` block drives, with the interfaces
    it is commanded through (empty when the block names none, as PR2's old transmissions).
    ``passive``: joints the blocks name as following others (not driven). ``drives``: Gazebo
    drive plugins, in file order.
    """

    joints: Mapping[str, frozenset[str]] = field(default_factory=dict)
    passive: frozenset[str] = frozenset()
    drives: tuple[DrivePlugin, ...] = ()

    @property
    def stated(self) -> bool:
        """Whether the file has any control block at all (else nothing here is evidence)."""
        return bool(self.joints or self.passive or self.drives)

    def velocity_only(self, joint: str) -> bool:
        """Whether ``joint`` is commanded in velocity and in nothing else (a wheel's interface)."""
        return self.joints.get(joint, frozenset()) == frozenset({"velocity"})


def _tag(el: object) -> str | None:
    tag = getattr(el, "tag", None)
    return tag if isinstance(tag, str) else None


def _interface(text: str | None) -> str | None:
    """``hardware_interface/VelocityJointInterface`` or ``velocity`` -> ``velocity``."""
    if not text:
        return None
    low = text.strip().lower()
    return next((i for i in _INTERFACES if i in low), None)


class _Collector:
    """Joints and interfaces gathered from the blocks, bounded."""

    def __init__(self) -> None:
        self.joints: dict[str, set[str]] = {}
        self.passive: set[str] = set()

    def drive(self, name: str | None, interfaces: set[str]) -> None:
        if name and len(self.joints) < _MAX_JOINTS:
            self.joints.setdefault(name.strip(), set()).update(interfaces)

    def follow(self, name: str | None) -> None:
        if name and len(self.passive) < _MAX_JOINTS:
            self.passive.add(name.strip())


def _transmission(tr: etree._Element, out: _Collector) -> None:
    for el in tr:
        tag = _tag(el)
        if tag is None:
            continue
        if tag in _PR2_PASSIVE:
            out.follow(el.get("name"))
        elif tag in _PR2_ACTUATED:
            found = {
                i
                for k in el
                if _tag(k) == "hardwareInterface"
                if (i := _interface(k.text)) is not None
            }
            out.drive(el.get("name"), found)


def _ros2_control(rc: etree._Element, out: _Collector) -> None:
    for joint in rc:
        if _tag(joint) != "joint":
            continue
        name = joint.get("name")
        commands = {
            i
            for k in joint
            if _tag(k) == "command_interface"
            if (i := _interface(k.get("name"))) is not None
        }
        mimic = (joint.get("mimic") or "").strip().lower() == "true" or any(
            _tag(k) == "param" and k.get("name") == "mimic" for k in joint
        )
        if mimic or not any(_tag(k) == "command_interface" for k in joint):
            out.follow(name)
        else:
            out.drive(name, commands)


def _drive_plugin(plugin: etree._Element) -> DrivePlugin | None:
    label = f"{plugin.get('filename') or ''} {plugin.get('name') or ''}".lower()
    squashed = label.replace("-", "_").replace("::", "_")
    kind = next((k for word, k in _DRIVE_PLUGINS if word in squashed), None)
    if kind is None:
        return None
    wheels = tuple(
        (k.text or "").strip() for k in plugin if _tag(k) in _WHEEL_TAGS and (k.text or "").strip()
    )
    return DrivePlugin((plugin.get("filename") or plugin.get("name") or "").strip(), kind, wheels)


def read_actuation(root: etree._Element) -> Actuation:
    """The control facts of a URDF element tree (see the module docstring)."""
    out = _Collector()
    drives: list[DrivePlugin] = []
    for el in root:
        tag = _tag(el)
        if tag == "transmission":
            _transmission(el, out)
        elif tag == "ros2_control":
            _ros2_control(el, out)
        elif tag == "gazebo":
            for plugin in el:
                if _tag(plugin) == "plugin" and (d := _drive_plugin(plugin)) is not None:
                    drives.append(d)
    passive = frozenset(out.passive - out.joints.keys())
    return Actuation(
        joints={j: frozenset(i) for j, i in out.joints.items()},
        passive=passive,
        drives=tuple(drives),
    )
