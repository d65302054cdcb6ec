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

Why the limited C API: the cores use only CPython's stable ABI (``Py_LIMITED_API`` 3.11) and
numpy's C API, whose headers support it, so one wheel per platform (``cp311-abi3``) serves every
CPython from 3.11 on; a free-threaded CPython, which has no stable ABI, gets a version-specific
build. The numeric kernels live in ``_kincore_kernels.h`` and ``_meshcore_kernels.h``, which
include no Python or numpy header (CI cross-compiles them for Windows); each glue file includes
its kernels into its own translation unit.
"""

from __future__ import annotations

import os
import sys
import sysconfig
from importlib.machinery import EXTENSION_SUFFIXES
from pathlib import Path

import numpy
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

#: Set (to anything but "" or "0") to install without the C accelerators.
NO_EXTENSIONS_ENV = "ROBOTSPEC_NO_EXTENSIONS"
#: The oldest CPython the wheel's stable ABI serves (requires-python in pyproject.toml).
LIMITED_API = "0x030B0000"
#: A free-threaded CPython has no stable ABI: there the cores are built for that version only.
USE_LIMITED_API = not sysconfig.get_config_var("Py_GIL_DISABLED")
#: (module, glue, kernels): the kernels are listed so that editing them rebuilds the module.
CORES = (
    (
        "robotspec.model._kincore",
        "robotspec/model/_kincore.c",
        "robotspec/model/_kincore_kernels.h",
    ),
    (
        "robotspec.collision._meshcore",
        "robotspec/collision/_meshcore.c",
        "robotspec/collision/_meshcore_kernels.h",
    ),
)


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
            return
        if self.inplace or getattr(self, "editable_mode", False):
            for ext in self.extensions:
                self._drop_shadowing(ext)

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

    def _drop_shadowing(self, ext: Extension) -> None:
        """Remove older builds of ``ext`` beside its in-place file (``pip install -e .``).

        Python tries ``.cpython-311-x86_64-linux-gnu.so`` before ``.abi3.so``: a version-specific
        file left by an earlier build would shadow the new stable-ABI one and answer instead.
        """
        package, _, name = ext.name.rpartition(".")
        folder = Path(self.get_finalized_command("build_py").get_package_dir(package))
        built = folder / Path(self.get_ext_filename(ext.name)).name
        if not built.is_file():
            return
        for sfx in EXTENSION_SUFFIXES:
            other = folder / (name + sfx)
            if other != built and other.is_file():
                other.unlink()

    @staticmethod
    def _skipped(what: str, exc: BaseException) -> None:
        sys.stderr.write(
            f"warning: robotspec: could not build {what} ({type(exc).__name__}: {exc}); "
            "installing without it: every query still works, in numpy (slower)\n"
        )


def _extensions() -> list[Extension]:
    if os.environ.get(NO_EXTENSIONS_ENV, "").strip() not in ("", "0"):
        return []
    macros = [("Py_LIMITED_API", LIMITED_API)] if USE_LIMITED_API else []
    return [
        Extension(
            name,
            sources=[glue],
            depends=[kernels],
            include_dirs=[numpy.get_include()],
            define_macros=macros,
            py_limited_api=USE_LIMITED_API,
            optional=True,
        )
        for name, glue, kernels in CORES
    ]


setup(
    ext_modules=_extensions(),
    cmdclass={"build_ext": OptionalBuildExt},
    # The wheel's tag: cp311-abi3 (every CPython from 3.11 on), where the cores use the stable ABI.
    options={"bdist_wheel": {"py_limited_api": "cp311"}} if USE_LIMITED_API else {},
)
