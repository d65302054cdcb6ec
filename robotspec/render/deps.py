"""Optional dependencies of the drawing commands, checked before any work is done.

Why up front: ``render`` needs Pillow, ``view`` viser and ``--plot`` matplotlib, all in the
``view`` extra; a user without them should get one line saying what to install, not a traceback
after the robot compiled.
"""

from __future__ import annotations

import importlib.util

from robotspec.errors import RobotSpecError

__all__ = ["require"]


def require(module: str, package: str, feature: str) -> None:
    """Raise a RobotSpecError naming the pip package when ``module`` cannot be imported."""
    if importlib.util.find_spec(module) is None:
        raise RobotSpecError(
            f"{feature} needs the '{package}' package; install it with "
            f"`pip install '{package}'` or `pip install 'robotspec[view]'`",
            kind="dependency",
            name=package,
        )
