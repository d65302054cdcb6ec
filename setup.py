"""Build of robotspec's two C extensions (everything else is in pyproject.toml).

Why extensions: single-configuration kinematics and the collision broad phase run in
robotspec/model/_kincore.c, a few thousand floating-point operations per call that Python or
numpy would spend tens of microseconds dispatching; robotspec/collision/_meshcore.c proves mesh
pairs apart box by box, where coal spends hundreds of microseconds on nearly touching meshes
(see README, Benchmarks).
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
        ),
        Extension(
            "robotspec.collision._meshcore",
            sources=["robotspec/collision/_meshcore.c"],
            include_dirs=[numpy.get_include()],
            extra_compile_args=["-O2", "-std=c99"],
        ),
    ]
)
