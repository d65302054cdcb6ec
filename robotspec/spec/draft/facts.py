"""What a robot's URDF states beyond its tree, gathered once for the drafter.

Why a record of its own: the world keeps links and joints only; the ``<gazebo>`` sensors and the
control blocks (transmissions, ``ros2_control``, drive plugins) are in the same file and say
which frame a camera is and which joints are driven. The drafter reads them before it guesses
from names (issue 30). An empty record (no such blocks, or a world built without its file) makes
every detector fall back to its guesses.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from robotspec.description.actuation import Actuation, read_actuation
from robotspec.description.gazebo import GazeboCamera, gazebo_cameras, sensor_links

if TYPE_CHECKING:
    from lxml import etree

__all__ = ["FileFacts", "read_facts"]


@dataclass(frozen=True)
class FileFacts:
    """The URDF's Gazebo cameras, the links its Gazebo sensors are on, and its actuation."""

    cameras: tuple[GazeboCamera, ...] = ()
    #: Link -> type of the first Gazebo sensor on it (``ray``, ``imu``, ``camera``...).
    sensor_links: Mapping[str, str] = field(default_factory=dict)
    actuation: Actuation = field(default_factory=Actuation)


def read_facts(root: etree._Element | None) -> FileFacts:
    """The facts of a URDF element tree (``None``: none known)."""
    if root is None:
        return FileFacts()
    return FileFacts(gazebo_cameras(root), sensor_links(root), read_actuation(root))
