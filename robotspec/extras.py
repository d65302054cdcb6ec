"""Optional dependencies, fenced one way: the module, or the package's error with the pip command.

Why one way: the optional parts (pinocchio, MuJoCo, the drawing packages, coal for collisions)
were fenced five ways (``try: import``, ``find_spec``, ``importlib.import_module``, each with its
own wording). Every fence now says the same thing the same way -- what needs it, what to install,
the command -- and raises the package's own error (``kind="dependency"``, ``name`` = the pip
package), which the CLI prints as one line, exit code 1, no traceback. A missing extra never
breaks ``import robotspec``: the module is imported only when the feature runs.
"""

from __future__ import annotations

import importlib
import importlib.util
from dataclasses import dataclass
from types import ModuleType

from robotspec.errors import RobotSpecError

__all__ = ["Extra", "require", "require_present"]


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
