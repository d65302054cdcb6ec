"""The state of one compilation, and the name lookups every check uses."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from robotspec.description.srdf import Srdf
from robotspec.diagnostics import Diagnostics, Loc
from robotspec.model.world import Body, Connection, World
from robotspec.semantic import JointState
from robotspec.spec.load import LoadedSpec
from robotspec.spec.models import RobotSpec

__all__ = ["AXIS_TOL", "Build", "moved_by", "subtree_joints"]

AXIS_TOL = 1e-3


@dataclass
class Build:
    """The state of one compilation: spec, world, diagnostics and what was resolved."""

    loaded: LoadedSpec
    world: World
    diag: Diagnostics
    srdf: Srdf | None
    presets: Mapping[str, Mapping[str, object]]
    robot_root: Body | None = None
    states: dict[str, JointState] = field(default_factory=dict)

    @property
    def spec(self) -> RobotSpec:
        """The validated spec."""
        return self.loaded.spec

    @property
    def where(self) -> str:
        """How error messages name the robot's description file."""
        src = self.world.source or self.world.name
        return src.rsplit("/", 1)[-1]

    # ------------------------------------------------------------------ name resolution
    def body(self, loc: Loc, name: str | None) -> Body | None:
        """The body called ``name``, or None after recording a located 'not found' error."""
        if name is None:
            return None
        if self.world.has_body(name):
            return self.world.get_body_by_name(name)
        self.diag.not_found(loc, "link", name, self.world.body_names, self.where)
        return None

    def chain_ok(
        self, loc: Loc, what: str, root: Body | None, tip: Body | None, *, allow_empty: bool = False
    ) -> bool:
        """Check that ``root`` is a proper ancestor of ``tip``; name the fix when it is not."""
        if root is None or tip is None:
            return False
        if root.index == tip.index:
            if allow_empty:
                return True
            self.diag.error(
                loc,
                f"{what} is empty: root and tip are both '{root.name}'; a chain needs at least "
                "one joint",
                name=root.name,
            )
            return False
        if self.world.is_ancestor(root, tip):
            return True
        common = self.world.common_ancestor(root, tip)
        if self.world.is_ancestor(tip, root):
            detail = f"'{tip.name}' is above '{root.name}'; swap root and tip"
        else:
            detail = (
                f"they are siblings on different branches; their common ancestor is "
                f"'{common.name}' (did you mean root '{common.name}'?)"
            )
        self.diag.error(
            loc,
            f"{what}: root '{root.name}' is not an ancestor of tip '{tip.name}': {detail}",
            name=root.name,
            suggestions=(common.name,),
        )
        return False

    def add_states(self, prefix: str, states: Mapping[str, JointState]) -> None:
        """Record a part's checked states under ``prefix.name`` (robot-level: no prefix)."""
        self.states.update({f"{prefix}.{k}" if prefix else k: v for k, v in states.items()})

    def joint(self, loc: Loc, name: str) -> Connection | None:
        """The connection called ``name`` or a located 'not found' error."""
        if self.world.has_connection(name):
            return self.world.get_connection_by_name(name)
        self.diag.not_found(loc, "joint", name, self.world.connection_names, self.where)
        return None


def moved_by(world: World, connections: list[Connection]) -> set[str]:
    """Names of joints whose motion moves these connections (themselves and mimic leaders)."""
    names = {c.name for c in connections if not c.is_fixed}
    for c in connections:
        if c.mimic is not None:
            names.add(c.mimic.leader)
    return names


def subtree_joints(world: World, root: Body) -> list[Connection]:
    """The connections below ``root``: the joints that belong to the robot."""
    inside = {b.index for b in world.subtree(root)}
    return [c for c in world.connections if c.parent in inside]


# ---------------------------------------------------------------------------- checks
