"""Types of the mesh separation core (robotspec/collision/_meshcore.c); sets are opaque capsules."""

from typing import Any

def mesh_set(meshes: Any) -> object: ...
def apart(
    meshes: object, poses: Any, rows: Any, pairs: Any, g1: Any, g2: Any, eps: float
) -> Any: ...
