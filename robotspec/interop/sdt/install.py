"""What is really missing when SDT cannot be imported, and the command that fixes it.

Why a module of its own: "pip install 'robotspec[sdt]'" is the right answer only when SDT
itself is absent. SDT 26.7 from PyPI also imports a package PyPI does not have (giskardpy, for
one helper, ``giskardpy.utils.utils.create_path``, while it loads its ``World``): there the
extra is installed already and the same advice sends the user in a circle. This module reads
the ``ImportError`` and names the module that is missing, with the command that brings it.
"""

from __future__ import annotations

import importlib.metadata
import importlib.util

from robotspec.errors import RobotSpecError

__all__ = ["GISKARDPY_INSTALL", "import_error"]

#: giskardpy lives in the CRAM monorepo beside SDT, not on PyPI. SDT needs one helper of it;
#: ``--no-deps`` leaves out what giskardpy's own motion control needs (PyQt5, piqp, ...).
GISKARDPY_INSTALL = (
    "pip install --no-deps 'giskardpy @ git+https://github.com/cram2/"
    "cognitive_robot_abstract_machine#subdirectory=giskardpy'"
)


def _installed(distribution: str) -> str | None:
    try:
        return importlib.metadata.version(distribution)
    except importlib.metadata.PackageNotFoundError:
        return None


def import_error(exc: ImportError, *, tested: str) -> RobotSpecError:
    """The error for ``exc``, raised while importing SDT; ``tested``: the SDT minor version.

    Three cases, each with its own command: SDT itself absent (the ``sdt`` extra); a module
    SDT imports without declaring it (giskardpy: from its source; another: named as such);
    an SDT of another version whose names or modules the bridge does not find (the pinned
    version; an installed SDT without one of its modules is not "not installed").
    """
    missing = (exc.name or "") if isinstance(exc, ModuleNotFoundError) else ""
    top = missing.partition(".")[0]
    version = _installed("semantic-digital-twin")
    if version is None or missing == "semantic_digital_twin":
        message = (
            f"the semantic digital twin is not installed ({exc}): pip install 'robotspec[sdt]' "
            f"(semantic-digital-twin {tested}.*; see docs/sdt.md, 'Installing SDT')"
        )
    elif top == "giskardpy":
        message = (
            f"semantic-digital-twin {version} is installed, but it imports giskardpy "
            "(giskardpy.utils.utils.create_path, while it loads its World), which is not "
            f"installed and not on PyPI: {GISKARDPY_INSTALL} (see docs/sdt.md, 'Installing SDT')"
        )
    elif top == "semantic_digital_twin":  # installed, without a module the bridge imports
        message = (
            f"semantic-digital-twin {version} is installed but has no module '{missing}' "
            f"({exc}); robotspec's bridge is written for {tested}.*: pip install "
            f"'semantic-digital-twin=={tested}.*'"
        )
    elif top and importlib.util.find_spec(top) is None:
        message = (
            f"semantic-digital-twin {version} is installed, but it imports '{missing}', which "
            f"is not installed ({exc}); the sdt extra brings what SDT {tested} is known to "
            "need (pip install 'robotspec[sdt]'); see docs/sdt.md for what SDT leaves out"
        )
    elif not version.startswith(f"{tested}."):
        message = (
            f"semantic-digital-twin {version} cannot be imported ({type(exc).__name__}: {exc}); "
            f"robotspec's bridge is written for {tested}.*: pip install "
            f"'semantic-digital-twin=={tested}.*'"
        )
    else:
        message = (
            f"semantic-digital-twin {version} is installed but cannot be imported "
            f"({type(exc).__name__}: {exc}); see docs/sdt.md for what SDT {tested} leaves out"
        )
    return RobotSpecError(message, kind="dependency", name=top or "semantic_digital_twin")
