"""robotspec: robot semantics as data.

A robot's URDF/xacro and SRDF are loaded into one world model; a short YAML spec names its
semantic parts (arms, grippers, cameras, torso, neck) and compiles into an ``AbstractRobot``.

The public API is re-exported here lazily (PEP 562): ``import robotspec`` stays as light as the
CLI needs (no numpy, no lxml), and each name imports its module on first use::

    import robotspec

    pr2 = robotspec.load_robot("pr2")  # a robotspec.robots.PR2
    result = robotspec.check_spec("my_robot.yaml")  # warnings; every error raised at once
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

from robotspec.errors import RobotSpecError, RobotSpecErrors

if TYPE_CHECKING:
    from robotspec.compiler import (
        CompileResult,
        check_spec,
        compile_robot,
        compile_spec_for_world,
    )
    from robotspec.description.load import Description, load_description
    from robotspec.errors import NotFoundError
    from robotspec.model.world import World
    from robotspec.robots import HSRB, PR2, UR5, B1UR5Allegro, DualPanda, Panda, Tiago
    from robotspec.robots import load as load_robot
    from robotspec.semantic import (
        AbstractRobot,
        Arm,
        Camera,
        FieldOfView,
        Finger,
        Hand,
        KinematicChain,
        Manipulator,
        Neck,
        ParallelGripper,
        Sensor,
        Torso,
    )
    from robotspec.spec.load import LoadedSpec, load_spec
    from robotspec.spec.models import RobotSpec

__version__ = "0.1.0"

#: Public name -> (module, attribute in that module).
_EXPORTS: dict[str, tuple[str, str]] = {
    **{
        n: ("robotspec.compiler", n)
        for n in ("CompileResult", "check_spec", "compile_robot", "compile_spec_for_world")
    },
    "Description": ("robotspec.description.load", "Description"),
    "load_description": ("robotspec.description.load", "load_description"),
    "NotFoundError": ("robotspec.errors", "NotFoundError"),
    "World": ("robotspec.model.world", "World"),
    **{
        n: ("robotspec.robots", n)
        for n in ("HSRB", "PR2", "UR5", "B1UR5Allegro", "DualPanda", "Panda", "Tiago")
    },
    "load_robot": ("robotspec.robots", "load"),
    **{
        n: ("robotspec.semantic", n)
        for n in (
            "AbstractRobot",
            "Arm",
            "Camera",
            "FieldOfView",
            "Finger",
            "Hand",
            "KinematicChain",
            "Manipulator",
            "Neck",
            "ParallelGripper",
            "Sensor",
            "Torso",
        )
    },
    "LoadedSpec": ("robotspec.spec.load", "LoadedSpec"),
    "load_spec": ("robotspec.spec.load", "load_spec"),
    "RobotSpec": ("robotspec.spec.models", "RobotSpec"),
}

__all__ = [
    "AbstractRobot",
    "Arm",
    "B1UR5Allegro",
    "Camera",
    "CompileResult",
    "Description",
    "DualPanda",
    "FieldOfView",
    "Finger",
    "HSRB",
    "Hand",
    "KinematicChain",
    "LoadedSpec",
    "Manipulator",
    "Neck",
    "NotFoundError",
    "PR2",
    "Panda",
    "ParallelGripper",
    "RobotSpec",
    "RobotSpecError",
    "RobotSpecErrors",
    "Sensor",
    "Tiago",
    "Torso",
    "UR5",
    "World",
    "__version__",
    "check_spec",
    "compile_robot",
    "compile_spec_for_world",
    "load_description",
    "load_robot",
    "load_spec",
]


def __getattr__(name: str) -> Any:
    target = _EXPORTS.get(name)
    if target is None:
        raise AttributeError(f"module 'robotspec' has no attribute {name!r}")
    value = getattr(import_module(target[0]), target[1])
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return __all__
