"""Optional dependencies, fenced one way: the module, or the package's error with the pip command.

Why one way: the optional parts (pinocchio, MuJoCo, the drawing packages, Robot Raconteur, coal
for collisions) were fenced five ways (``try: import``, ``find_spec``, ``importlib.import_module``,
each with its own wording). Every fence now says the same thing the same way -- what needs it,
what to install, the command -- and raises the package's own error (``kind="dependency"``,
``name`` = the pip package), which the CLI prints as one line, exit code 1, no traceback. A
missing extra never breaks ``import robotspec``: the module is imported only when the feature
runs. The extras robotspec declares are named here once (:data:`OPTIONAL`), each with the
module it imports.

Two fences stand apart, on purpose: the semantic digital twin
(:mod:`robotspec.interop.sdt.install`: its message tells a missing SDT from one missing a module
SDT imports undeclared, giskardpy), and the compiled C cores (:mod:`robotspec.accel`: not a
package to install but a build, whose absence is a slower answer, never an error).
"""

from __future__ import annotations

import importlib
import importlib.util
from dataclasses import dataclass
from types import ModuleType

from robotspec.errors import RobotSpecError

__all__ = [
    "MATPLOTLIB",
    "MUJOCO",
    "OPTIONAL",
    "PILLOW",
    "PINOCCHIO",
    "ROBOTRACONTEUR",
    "ROBOTRACONTEUR_COMPANION",
    "VISER",
    "Extra",
    "missing_extras",
    "require",
    "require_all",
    "require_present",
]


@dataclass(frozen=True)
class Extra:
    """An optional dependency: the module imported and how a user installs it.

    ``package`` is the PyPI name (``pin`` for the module ``pinocchio``); ``extra`` the robotspec
    extra that installs it (``None``: the package alone); ``label`` how the message names it
    (default: ``the '<package>' package``).
    """

    module: str
    package: str
    extra: str | None = None
    label: str = ""

    @property
    def command(self) -> str:
        """The pip command a user runs (the robotspec extra where there is one)."""
        if self.extra is None:
            return f"pip install '{self.package}'"
        return f"pip install 'robotspec[{self.extra}]'"

    def missing(self, feature: str, error: type[RobotSpecError] = RobotSpecError) -> RobotSpecError:
        """The error saying ``feature`` needs this extra, and the command that installs it."""
        what = self.label or f"the '{self.package}' package"
        return error(
            f"{feature} needs {what}; install it with `{self.command}`",
            kind="dependency",
            name=self.package,
        )


def require(extra: Extra, feature: str, error: type[RobotSpecError] = RobotSpecError) -> ModuleType:
    """``extra``'s module, imported; ``extra.missing(feature, error)`` when it cannot be."""
    try:
        return importlib.import_module(extra.module)
    except ImportError:
        raise extra.missing(feature, error) from None


def require_present(
    extra: Extra, feature: str, error: type[RobotSpecError] = RobotSpecError
) -> None:
    """Refuse up front, without importing (a slow import, or one for later), when it is absent.

    Why: a command that needs the extra late in its run (after compiling a robot) says what to
    install before doing any work.
    """
    if importlib.util.find_spec(extra.module) is None:
        raise extra.missing(feature, error)


def missing_extras(extras: tuple[Extra, ...]) -> tuple[Extra, ...]:
    """The ``extras`` that cannot be imported, without importing any (empty when all are there)."""
    return tuple(e for e in extras if importlib.util.find_spec(e.module) is None)


def require_all(
    extras: tuple[Extra, ...], feature: str, error: type[RobotSpecError] = RobotSpecError
) -> None:
    """Refuse up front, naming every one of ``extras`` that is absent and one command.

    Why: a feature that needs two packages (Robot Raconteur and its companion) says both at
    once, so a user installs once. The command is the first absent one's (the same extra).
    """
    absent = missing_extras(extras)
    if not absent:
        return
    if len(absent) == 1:
        raise absent[0].missing(feature, error)
    names = " and ".join(f"'{e.package}'" for e in absent)
    raise error(
        f"{feature} needs the {names} packages; install them with `{absent[0].command}`",
        kind="dependency",
        name=absent[0].package,
    )


#: ``robot.to_pinocchio()`` (PyPI names it ``pin``).
PINOCCHIO = Extra("pinocchio", "pin", "pinocchio", label="pinocchio (PyPI package 'pin')")
#: ``robotspec drive --physics mujoco``, ``robotspec annotate mjcf``.
MUJOCO = Extra("mujoco", "mujoco", "mujoco", label="MuJoCo")
#: ``robotspec render``.
PILLOW = Extra("PIL", "Pillow", "view")
#: ``robotspec view``, ``robotspec setup``.
VISER = Extra("viser", "viser", "view")
#: ``robotspec drive --plot``.
MATPLOTLIB = Extra("matplotlib", "matplotlib", "view")
#: ``robotspec drive --serve``: Robot Raconteur and its companion library, one extra.
ROBOTRACONTEUR = Extra("RobotRaconteur", "robotraconteur", "robotraconteur")
ROBOTRACONTEUR_COMPANION = Extra(
    "RobotRaconteurCompanion", "robotraconteurcompanion", "robotraconteur"
)
#: Every optional extra robotspec declares (pyproject.toml), with the module it imports.
OPTIONAL: tuple[Extra, ...] = (
    PINOCCHIO,
    MUJOCO,
    PILLOW,
    VISER,
    MATPLOTLIB,
    ROBOTRACONTEUR,
    ROBOTRACONTEUR_COMPANION,
)
