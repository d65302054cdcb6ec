"""Self-collision checking with coal: geometry, allowed-collision rules, queries, matrices.

``SelfCollisionChecker.from_robot(robot)`` checks a compiled robot under its own rules (adjacent
bodies, its SRDF, the spec's disabled bodies and buffer distance); ``generate_for_robot(robot)``
computes the disabled pairs MoveIt's Setup Assistant would write. Needs the ``coal`` and
``trimesh`` packages (imported on first use).
"""

from robotspec.collision.checker import PairDistance, SelfCollisionChecker
from robotspec.collision.matrix import (
    CollisionMatrix,
    MatrixEntry,
    compare_pairs,
    generate_collision_matrix,
    generate_for_robot,
)
from robotspec.collision.rules import CollisionRules, adjacent_pairs, pair_key
from robotspec.collision.sampling import (
    default_configuration,
    random_configurations,
    sampling_bounds,
)
from robotspec.collision.shapes import (
    CollisionGeometry,
    GeometryModel,
    MeshLibrary,
    build_geometry_model,
)
from robotspec.semantic.states import state_configuration  # where states live, re-exported

__all__ = [
    "CollisionGeometry",
    "CollisionMatrix",
    "CollisionRules",
    "GeometryModel",
    "MatrixEntry",
    "MeshLibrary",
    "PairDistance",
    "SelfCollisionChecker",
    "adjacent_pairs",
    "build_geometry_model",
    "compare_pairs",
    "default_configuration",
    "generate_collision_matrix",
    "generate_for_robot",
    "pair_key",
    "random_configurations",
    "sampling_bounds",
    "state_configuration",
]
