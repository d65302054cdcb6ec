"""Build of robotspec's one C extension (everything else is in pyproject.toml).

Why an extension: single-configuration kinematics and the collision broad phase run in
robotspec/model/_kincore.c, a few thousand floating-point operations per call that Python or
numpy would spend tens of microseconds dispatching (see README, Benchmarks).
"""

from __future__ import annotations

import numpy
from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "robotspec.model._kincore",
            sources=["robotspec/model/_kincore.c"],
            include_dirs=[numpy.get_include()],
            extra_compile_args=["-O2", "-std=c99"],
        )
    ]
)
