"""Pictures of a compiled robot: an offscreen PNG, a live browser view, and drive plots.

Why a package of its own: drawing needs Pillow (and viser or matplotlib for the view and the
plots), which the rest of robotspec must not import; everything here is imported lazily by the
commands that draw.
"""

from __future__ import annotations

from robotspec.render.picture import Picture, RenderOptions, render_scene
from robotspec.render.raster import VIEWS, ViewCamera, parse_size
from robotspec.render.scene import LegendEntry, RobotScene, build_scene, default_q

__all__ = [
    "VIEWS",
    "LegendEntry",
    "Picture",
    "RenderOptions",
    "RobotScene",
    "ViewCamera",
    "build_scene",
    "default_q",
    "parse_size",
    "render_scene",
]
