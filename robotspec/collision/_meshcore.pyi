"""Types of the mesh separation core (robotspec/collision/_meshcore.c); sets are opaque capsules."""

from typing import Any

#: The interface version compiled into the core (meshcore.INTERFACE must equal it).
INTERFACE: int

def mesh_set(meshes: Any) -> object: ...
def apart(
    meshes: object, poses: Any, rows: Any, pairs: Any, g1: Any, g2: Any, eps: float
) -> Any: ...
def walk(
    meshes: object,
    poses: Any,
    rows: Any,
    pairs: Any,
    g1: Any,
    g2: Any,
    owner: Any,
    found: Any,
    eps: float,
    mode: int,
) -> tuple[Any, Any, Any]: ...
def apart_one(meshes: object, poses: Any, row: int, i: int, j: int, eps: float) -> int: ...
def on_surface(meshes: object, poses: Any, row: int, g: int, point: Any, tol: float) -> bool: ...
