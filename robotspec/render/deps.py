"""Optional dependencies of the drawing commands, checked before any work is done.

Why up front: ``render`` needs Pillow, ``view`` viser and ``--plot`` matplotlib, all in the
``view`` extra; a user without them should get one line saying what to install, not a traceback
after the robot compiled.
"""

from __future__ import annotations

from robotspec.extras import Extra, require_present

__all__ = ["require"]


def require(module: str, package: str, feature: str) -> None:
    """Raise a RobotSpecError naming the ``view`` extra when ``module`` cannot be imported."""
    require_present(Extra(module, package, "view"), feature)
