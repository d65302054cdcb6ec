"""The decisions a draft holds, before they are written as YAML.

Kept apart from the detectors and the writer so that tests (and the robot zoo) can look at what
``robotspec init`` decided without parsing its text. Every guess carries its reason (``decide``);
the writer turns it into a ``# DECIDE:`` comment.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = [
    "Draft",
    "DraftCamera",
    "DraftChain",
    "DraftDrive",
    "DraftFinger",
    "DraftFrame",
    "DraftManipulator",
    "DraftQuestion",
    "JointState",
]

#: A named joint state: joint name -> position (rad or m).
JointState = dict[str, float]


@dataclass
class DraftFinger:
    """One finger of a parallel gripper, as the spec's ``FingerSpec`` (root to tip)."""

    root: str
    tip: str


@dataclass
class DraftManipulator:
    """A hand or tool on a chain: a parallel gripper when two finger branches were found."""

    name: str
    root: str
    tool_frame: str
    source: str
    decide: list[str] = field(default_factory=list)
    finger: DraftFinger | None = None
    thumb: DraftFinger | None = None
    states: dict[str, JointState] = field(default_factory=dict)
    front_facing: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)
    #: Actuated joints of the hand (for group states); not written.
    joints: frozenset[str] = frozenset()
    #: A hand's fingers besides its thumb, by name (written as ``type: hand``).
    fingers: dict[str, DraftFinger] = field(default_factory=dict)
    #: How ``front_facing`` was derived (a plain comment: it follows the tool frame and tips).
    facing: str | None = None
    #: The rules of ``confidence`` that state its tool frame and fingers (never written).
    stated: tuple[str, ...] = ()

    @property
    def is_gripper(self) -> bool:
        """Whether the draft writes a ``parallel_gripper`` (both fingers known)."""
        return self.finger is not None and self.thumb is not None

    @property
    def is_hand(self) -> bool:
        """Whether the draft writes a ``hand`` (a thumb and named fingers)."""
        return self.finger is None and self.thumb is not None and bool(self.fingers)


@dataclass
class DraftChain:
    """An arm, a leg, a torso or a neck: ``root`` to ``tip`` (or an SRDF ``group``)."""

    name: str
    root: str
    tip: str
    source: str
    role: str = "arm"  # arm | leg | chain | torso | neck
    group: str | None = None  # written as ``group:`` (an SRDF group of one <chain>)
    srdf_group: str | None = None  # the SRDF group it came from, in any form
    decide: list[str] = field(default_factory=list)
    manipulator: str | None = None
    sensors: list[str] = field(default_factory=list)
    states: dict[str, JointState] = field(default_factory=dict)
    side: str | None = None  # written only when the default pose cannot tell the sides
    yaw_body: str | None = None
    pitch_body: str | None = None
    #: Actuated (non-mimic) joints between root and tip; the chain's identity when comparing.
    joints: frozenset[str] = frozenset()
    #: The rule of ``confidence`` that states it, when no question is asked (never written).
    stated: str | None = None


@dataclass
class DraftCamera:
    """A camera on ``body``; ``optical`` frames look along +z (REP 103), others along +x."""

    name: str
    body: str
    optical: bool
    decide: list[str] = field(default_factory=list)
    #: A camera model of ``templates/cameras.yaml``; when set, no angles are written.
    preset: str | None = None
    #: Chosen angles (horizontal, vertical, rad); None writes the placeholder, marked DECIDE.
    field_of_view: tuple[float, float] | None = None
    #: A body frame (not optical) that looks along its z axis (written ``[0, 0, 1]``).
    looks_along_z: bool = False
    #: The viewing axis the files state in ``body``'s frame (a Gazebo sensor's), when it is
    #: neither +x nor +z; written as ``forward_facing_axis``.
    axis: tuple[float, float, float] | None = None
    #: What states the camera (a Gazebo sensor), written as ``# from ...``; None for a guess.
    source: str | None = None
    #: Heights (m) the camera is claimed to reach, and whether it is the default camera: never
    #: drafted, kept when a spec is read back for editing (``robotspec setup``).
    minimal_height: float | None = None
    maximal_height: float | None = None
    default: bool = False
    #: The rule of ``confidence`` that states it, when no question is asked (never written).
    stated: str | None = None


@dataclass
class DraftFrame:
    """A frame the URDF lacks, proposed under ``description.frames`` (a gripper's tool frame)."""

    name: str
    parent: str
    xyz: tuple[float, float, float]
    reason: str


@dataclass
class DraftDrive:
    """How the base moves, and why the draft thinks so."""

    type: str
    joint: str | None = None
    parent_frame: str | None = None
    source: str = ""
    decide: str | None = None
    #: The URDF's own base joints (x, y, theta) made the drive (``drive.joints``), if any.
    joints: tuple[str, str, str] | None = None
    #: The rule of ``confidence`` that states it, when no question is asked (never written).
    stated: str | None = None


@dataclass(frozen=True)
class DraftQuestion:
    """A ``DECIDE`` question about something no drafted part covers (``unassigned``).

    ``section``: the spec section it is written in (``chains``, ``manipulators``, ``sensors``);
    ``joints`` and ``links``: what it names, read by the corpus measure (never written).
    """

    section: str
    text: str
    joints: frozenset[str] = frozenset()
    links: frozenset[str] = frozenset()


@dataclass
class Draft:
    """Everything ``render_draft`` writes; see the detectors for how each part is found."""

    name: str
    urdf: str
    srdf: str | None
    root: str
    drive: DraftDrive | None
    chains: list[DraftChain]
    manipulators: list[DraftManipulator]
    cameras: list[DraftCamera]
    torso: DraftChain | None = None
    neck: DraftChain | None = None
    frames: list[DraftFrame] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    package_paths: list[str] = field(default_factory=list)
    #: The xacro arguments the robot was drafted with (``description.xacro_args``).
    xacro_args: dict[str, str] = field(default_factory=dict)
    states: dict[str, JointState] = field(default_factory=dict)
    #: The manipulator of a hand or gripper drafted alone (no arm carries it), if one was.
    lone_hand: str | None = None
    #: The direction the robot faces in its root frame, when the draft thinks it is not +x.
    forward: tuple[float, float, float] | None = None
    #: Why ``forward`` was drafted (a guess: written as a DECIDE mark); "" once a person decided.
    forward_decide: str | None = None
    #: Warnings a person accepted in ``robotspec setup``: (at, says, because), written as new
    #: ``accept_warnings`` entries by the assistant (``setup/accept.py``), not by the drafter.
    accepted: list[tuple[str, str, str]] = field(default_factory=list)
    #: Questions about what no drafted part covers, written as comments in their sections.
    questions: list[DraftQuestion] = field(default_factory=list)

    @property
    def arms(self) -> list[DraftChain]:
        """The chains that are arms."""
        return [c for c in self.chains if c.role == "arm"]
