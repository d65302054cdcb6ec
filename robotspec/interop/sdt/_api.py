"""The SDT names the bridge uses, imported in one place (importing this module imports SDT).

Why one module: SDT is an optional extra of 3.6 GB that takes seconds to import; the rest of
the bridge reaches it only through :func:`robotspec.interop.sdt.sdt_api`, so ``import
robotspec`` never imports it and a missing install is one clear error.
"""

from __future__ import annotations

from semantic_digital_twin.collision_checking.collision_matrix import CollisionCheck
from semantic_digital_twin.collision_checking.collision_rules import (
    AvoidExternalCollisions,
    AvoidSelfCollisions,
    SelfCollisionMatrixRule,
)
from semantic_digital_twin.datastructures import definitions
from semantic_digital_twin.datastructures.field_of_view import FieldOfView
from semantic_digital_twin.datastructures.joint_state import JointState
from semantic_digital_twin.datastructures.prefixed_name import PrefixedName
from semantic_digital_twin.exceptions import DuplicateRobotAssignmentsError
from semantic_digital_twin.robots import robot_part_mixins as mixins
from semantic_digital_twin.robots import robot_parts as parts
from semantic_digital_twin.spatial_types import (
    HomogeneousTransformationMatrix,
    Quaternion,
    Vector3,
)
from semantic_digital_twin.spatial_types.derivatives import DerivativeMap
from semantic_digital_twin.world import World
from semantic_digital_twin.world_description import geometry
from semantic_digital_twin.world_description.connections import (
    Connection6DoF,
    DifferentialDrive,
    FixedConnection,
    OmniDrive,
    PrismaticConnection,
    RevoluteConnection,
)
from semantic_digital_twin.world_description.degree_of_freedom import (
    DegreeOfFreedom,
    DegreeOfFreedomLimits,
)
from semantic_digital_twin.world_description.shape_collection import ShapeCollection
from semantic_digital_twin.world_description.world_entity import Body

__all__ = [
    "AvoidExternalCollisions",
    "AvoidSelfCollisions",
    "Body",
    "CollisionCheck",
    "Connection6DoF",
    "DegreeOfFreedom",
    "DegreeOfFreedomLimits",
    "DerivativeMap",
    "DifferentialDrive",
    "DuplicateRobotAssignmentsError",
    "FieldOfView",
    "FixedConnection",
    "HomogeneousTransformationMatrix",
    "JointState",
    "OmniDrive",
    "PrefixedName",
    "PrismaticConnection",
    "Quaternion",
    "RevoluteConnection",
    "SelfCollisionMatrixRule",
    "ShapeCollection",
    "Vector3",
    "World",
    "definitions",
    "geometry",
    "mixins",
    "parts",
]
