"""The semantic robot API (the seed's names): robots and their parts as views over a world."""

from __future__ import annotations

from robotspec.semantic.base import AssignmentError, JointState, SemanticRobotAnnotation
from robotspec.semantic.chains import Arm, Finger, KinematicChain, Neck, Torso
from robotspec.semantic.manipulators import (
    GenericManipulator,
    Hand,
    Manipulator,
    ParallelGripper,
    front_facing_axis_of,
)
from robotspec.semantic.robot import AbstractRobot, CollisionCheckingConfig, EmptyChainWarning
from robotspec.semantic.sensors import Camera, FieldOfView, GenericSensor, Sensor

__all__ = [
    "AbstractRobot",
    "Arm",
    "AssignmentError",
    "Camera",
    "CollisionCheckingConfig",
    "EmptyChainWarning",
    "FieldOfView",
    "Finger",
    "GenericManipulator",
    "GenericSensor",
    "Hand",
    "JointState",
    "KinematicChain",
    "Manipulator",
    "Neck",
    "ParallelGripper",
    "SemanticRobotAnnotation",
    "Sensor",
    "Torso",
    "front_facing_axis_of",
]
