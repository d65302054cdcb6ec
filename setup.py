"""Build of robotspec's two optional C accelerators (everything else is in pyproject.toml).

Why extensions: single-configuration kinematics and the collision broad phase run in
robotspec/model/_kincore.c, a few thousand floating-point operations per call that Python or
numpy would spend tens of microseconds dispatching; robotspec/collision/_meshcore.c proves mesh
pairs apart box by box, where coal spends hundreds of microseconds on nearly touching meshes
(see README, Benchmarks).

Why optional: both are accelerators. Every answer also comes from the pure-Python fallbacks
(robotspec/model/_kincore_py.py, robotspec/collision/_meshcore_py.py), so an install without a
C compiler, or whose compiler refuses the files, warns and still succeeds.
``ROBOTSPEC_NO_EXTENSIONS=1`` skips building them at all (to test the pure-Python install).
"""

from __future__ import annotations

import os
import sys

import numpy
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

#: Set (to anything but "" or "0") to install without the C accelerators.
NO_EXTENSIONS_ENV = "ROBOTSPEC_NO_EXTENSIONS"


class OptionalBuildExt(build_ext):
    """Builds the accelerators when it can; warns and goes on when it cannot.

    setuptools' ``optional=True`` covers a compiler that fails on a file, not a missing compiler
    (MSVC not installed fails in ``run`` before any extension is tried), hence this class. Each
    compiler also gets its own flags: ``-std=c99`` means nothing to MSVC.
    """

    def run(self) -> None:
        """Build every extension; any failure (say, no compiler at all) only warns."""
        try:
            super().run()
        except Exception as exc:  # noqa: BLE001 - any build failure leaves the fallbacks
            self._skipped("the C accelerators", exc)

    def build_extension(self, ext: Extension) -> None:
        """Build one extension with its compiler's flags; a failure only warns."""
        if self.compiler is not None and self.compiler.compiler_type == "msvc":
            ext.extra_compile_args = ["/O2"]
        else:
            ext.extra_compile_args = ["-O2", "-std=c99"]
        try:
            super().build_extension(ext)
        except Exception as exc:  # noqa: BLE001 - compiler missing, refusing, or crashing
            self._skipped(ext.name, exc)

    @staticmethod
    def _skipped(what: str, exc: BaseException) -> None:
        sys.stderr.write(
            f"warning: robotspec: could not build {what} ({type(exc).__name__}: {exc}); "
            "installing without it: every query still works, in numpy (slower)\n"
        )


def _extensions() -> list[Extension]:
    if os.environ.get(NO_EXTENSIONS_ENV, "").strip() not in ("", "0"):
        return []
    return [
        Extension(
            name,
            sources=[source],
            include_dirs=[numpy.get_include()],
            optional=True,
        )
        for name, source in (
            ("robotspec.model._kincore", "robotspec/model/_kincore.c"),
            ("robotspec.collision._meshcore", "robotspec/collision/_meshcore.c"),
        )
    ]


setup(ext_modules=_extensions(), cmdclass={"build_ext": OptionalBuildExt})
