"""Robots assembled from parts: an arm, a hand and a base welded together in one spec.

``compose`` joins the parts' URDF trees, SRDFs and specs into one description the compiler
builds like any other; ``robotspec export urdf`` writes the joined tree for other tools.
"""

from __future__ import annotations

from robotspec.compose.assembly import Composition, compose
from robotspec.compose.naming import PartNames
from robotspec.compose.parts import description_tree
from robotspec.compose.weld import ComposedPart

__all__ = ["ComposedPart", "Composition", "PartNames", "compose", "description_tree"]
