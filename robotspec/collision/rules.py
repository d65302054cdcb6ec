"""Which body pairs are checked: adjacency, the SRDF's collision elements and the spec's choices.

Adjacency follows MoveIt's Setup Assistant (``computeConnectionGraph``): bodies are nodes, every
joint (fixed or moving) is an edge, and each body without collision geometry is removed after
joining all of its neighbours to each other. So two bodies are adjacent when one joint connects
them, or when they are connected only through bodies without geometry (PR2's
``l_forearm_roll_link`` joins ``l_upper_arm_link`` and ``l_forearm_link``; two geometry children
of a geometry-less frame are adjacent to each other). Matching MoveIt here is what makes a
generated matrix comparable with SRDFs the Setup Assistant wrote.

Precedence for a pair (first match decides): a body disabled by the spec; an SRDF
``disable_collisions`` entry (MoveIt: disabled pairs win over enabled ones); an SRDF
``enable_collisions`` entry (re-enables an adjacent pair or one of a ``disable_default_collisions``
body); adjacency; ``disable_default_collisions``. Everything else is checked.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from robotspec.errors import CollisionError, closest_names
from robotspec.model.world import World

if TYPE_CHECKING:
    from robotspec.collision.robot_view import CollisionRobot
    from robotspec.description.srdf import Srdf

__all__ = [
    "ADJACENT",
    "CollisionRules",
    "adjacent_pairs",
    "pair_key",
]

#: MoveIt's reason words.
ADJACENT = "Adjacent"
DEFAULT = "Default"
ALWAYS = "Always"
NEVER = "Never"
#: Reasons robotspec adds for rules that are not pair entries.
BODY_DISABLED = "body disabled"
DEFAULT_DISABLED = "disable_default_collisions"


def pair_key(a: str, b: str) -> tuple[str, str]:
    """The canonical (sorted) spelling of an unordered pair."""
    return (a, b) if a <= b else (b, a)


def adjacent_pairs(world: World, with_geometry: Collection[str]) -> frozenset[tuple[str, str]]:
    """Pairs of geometry bodies that MoveIt's Setup Assistant calls adjacent (see module doc)."""
    graph: dict[str, set[str]] = {b.name: set() for b in world.bodies}
    for c in world.connections:
        p, ch = world.bodies[c.parent].name, world.bodies[c.child].name
        graph[p].add(ch)
        graph[ch].add(p)
    keep = set(with_geometry)
    # Contract geometry-less bodies in world order (deterministic), joining their neighbours.
    for b in world.bodies:
        if b.name in keep:
            continue
        neighbours = sorted(graph.pop(b.name))
        for n in neighbours:
            graph[n].discard(b.name)
        for i, x in enumerate(neighbours):
            for y in neighbours[i + 1 :]:
                graph[x].add(y)
                graph[y].add(x)
    return frozenset(pair_key(a, n) for a, ns in graph.items() for n in ns if a != n)


@dataclass(frozen=True)
class CollisionRules:
    """The allowed-collision rules of one robot over its bodies with geometry.

    ``disabled`` maps sorted pairs to their SRDF reason (``None`` when the SRDF gave none);
    ``default_disabled`` are ``disable_default_collisions`` links, ``enabled`` the pairs that
    re-enable them; ``disabled_bodies`` come from the spec and are never checked.
    ``buffer_distance`` (m) is the spec's ``collision.buffer_distance``: the distance below
    which :meth:`SelfCollisionChecker.buffer_violations` reports a pair.
    """

    bodies: tuple[str, ...]
    adjacent: frozenset[tuple[str, str]] = frozenset()
    disabled: Mapping[tuple[str, str], str | None] = field(default_factory=dict)
    enabled: frozenset[tuple[str, str]] = frozenset()
    default_disabled: frozenset[str] = frozenset()
    disabled_bodies: frozenset[str] = frozenset()
    buffer_distance: float = 0.0

    def __post_init__(self) -> None:
        if not self.buffer_distance >= 0.0:
            raise CollisionError(
                f"buffer distance must be >= 0, got {self.buffer_distance}", kind="config"
            )

    # ------------------------------------------------------------------ construction
    @classmethod
    def for_world(
        cls,
        world: World,
        bodies: Iterable[str] | None = None,
        *,
        srdf: Srdf | None = None,
        disabled_bodies: Iterable[str] = (),
        buffer_distance: float = 0.0,
        adjacency: bool = True,
    ) -> CollisionRules:
        """Rules for ``bodies`` (default: every body with collision geometry) of ``world``.

        SRDF entries naming bodies outside ``bodies`` are ignored, as MoveIt and the reference do
        (an SRDF often outlives its URDF).
        """
        names = (
            tuple(b.name for b in world.bodies if b.has_collision)
            if bodies is None
            else tuple(dict.fromkeys(bodies))
        )
        known = set(names)
        for b in names:
            if not world.has_body(b):
                raise CollisionError(
                    f"link '{b}' not found in world '{world.name}'",
                    kind="link",
                    name=b,
                    suggestions=closest_names(b, world.body_names),
                )
        off = frozenset(disabled_bodies)
        adjacent = adjacent_pairs(world, known) if adjacency else frozenset()
        disabled: dict[tuple[str, str], str | None] = {}
        enabled: set[tuple[str, str]] = set()
        default_off: set[str] = set()
        if srdf is not None:
            for d in srdf.disabled_collisions:
                if d.link1 in known and d.link2 in known and d.link1 != d.link2:
                    disabled.setdefault(pair_key(d.link1, d.link2), d.reason)
            for e in srdf.enabled_collisions:
                if e.link1 in known and e.link2 in known and e.link1 != e.link2:
                    enabled.add(pair_key(e.link1, e.link2))
            default_off = {x.link for x in srdf.disable_default_collisions if x.link in known}
        return cls(
            bodies=names,
            adjacent=frozenset(p for p in adjacent if p[0] in known and p[1] in known),
            disabled=disabled,
            enabled=frozenset(enabled),
            default_disabled=frozenset(default_off),
            disabled_bodies=off,
            buffer_distance=float(buffer_distance),
        )

    @classmethod
    def from_robot(cls, robot: CollisionRobot, *, adjacency: bool = True) -> CollisionRules:
        """The rules a compiled robot carries: SRDF, disabled bodies, buffer distance.

        The SRDF counts when the spec applies it; the buffer distance is the robot's
        ``default_collision_config.buffer_zone_distance``.

        ``robot.disabled_collision_bodies`` holds both the spec's bodies and the SRDF's
        ``disable_default_collisions`` links (the reference's ``load_srdf``); the latter are
        separated again so that ``enable_collisions`` can re-enable their pairs.
        """
        bodies = [b.name for b in robot.bodies_with_collisions]
        srdf = robot.srdf
        uses_srdf = srdf is not None and (
            bool(robot.disabled_collision_pairs) or not srdf.disabled_collisions
        )
        default_off = (
            {x.link for x in srdf.disable_default_collisions} if srdf and uses_srdf else set()
        )
        spec_off = {b for b in robot.disabled_collision_bodies if b not in default_off}
        rules = cls.for_world(
            robot.world,
            bodies,
            srdf=srdf if uses_srdf else None,
            disabled_bodies=spec_off,
            buffer_distance=robot.default_collision_config.buffer_zone_distance,
            adjacency=adjacency,
        )
        # Pairs the robot carries beyond its SRDF (added in code) count too.
        extra = {
            pair_key(*sorted(p)): None
            for p in robot.disabled_collision_pairs
            if len(p) == 2 and pair_key(*sorted(p)) not in rules.disabled
        }
        if extra:
            merged = dict(rules.disabled)
            merged.update(extra)
            rules = cls(
                bodies=rules.bodies,
                adjacent=rules.adjacent,
                disabled=merged,
                enabled=rules.enabled,
                default_disabled=rules.default_disabled,
                disabled_bodies=rules.disabled_bodies,
                buffer_distance=rules.buffer_distance,
            )
        return rules

    # ----------------------------------------------------------------------- queries
    def why_disabled(self, a: str, b: str) -> str | None:
        """Why the pair is not checked (a reason word), or ``None`` if it is checked."""
        if a == b:
            return "same body"
        if a in self.disabled_bodies or b in self.disabled_bodies:
            return BODY_DISABLED
        key = pair_key(a, b)
        if key in self.disabled:
            return self.disabled[key] or "SRDF"
        if key in self.enabled:
            return None
        if key in self.adjacent:
            return ADJACENT
        if a in self.default_disabled or b in self.default_disabled:
            return DEFAULT_DISABLED
        return None

    def is_checked(self, a: str, b: str) -> bool:
        """Whether the pair is checked for collision."""
        return self.why_disabled(a, b) is None

    def active_pairs(self) -> tuple[tuple[str, str], ...]:
        """Every checked pair, each as (earlier body, later body) in ``bodies`` order."""
        names = self.bodies
        return tuple(
            (a, b)
            for i, a in enumerate(names)
            for b in names[i + 1 :]
            if self.why_disabled(a, b) is None
        )
