"""Types of the C core (robotspec/model/_kincore.c); tables are opaque capsules."""

from typing import Any

#: The interface version compiled into the core (kincore.INTERFACE must equal it).
INTERFACE: int

def tree(
    parent: Any,
    child: Any,
    kind: Any,
    origin: Any,
    axis: Any,
    dof: Any,
    mul: Any,
    off: Any,
    n_slots: int,
    n_out: int,
    n_dof: int,
) -> object: ...
def fk(tree: object, q: object) -> Any: ...
def fk_batch(tree: object, q: object, out: Any = None, stream: bool = False) -> Any: ...
def tree_size(tree: object) -> tuple[int, int]: ...
def chain(
    pre: Any,
    post: Any,
    kind: Any,
    axis: Any,
    dof: Any,
    mul: Any,
    off: Any,
    col: Any,
    n_cols: int,
    n_dof: int,
) -> object: ...
def chain_fk(chain: object, q: object) -> Any: ...
def chain_fk_batch(chain: object, q: object) -> Any: ...
def chain_jacobian(chain: object, q: object) -> Any: ...
def geoms(
    body: Any, body_to_geom: Any, center: Any, half: Any, g1: Any, g2: Any, n_body: int
) -> object: ...
def broad(geoms: object, body_poses: Any, margin: float, mask: Any) -> tuple[Any, Any, Any]: ...
