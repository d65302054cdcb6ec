"""robotspec: robot semantics as data.

A robot's URDF/xacro and SRDF are loaded into one world model; a short YAML spec names its
semantic parts (arms, grippers, cameras, torso, neck) and compiles into an ``AbstractRobot``.
"""

from __future__ import annotations

from robotspec.errors import RobotSpecError, RobotSpecErrors

__all__ = ["RobotSpecError", "RobotSpecErrors", "__version__"]

__version__ = "0.1.0"
