"""The world model: bodies, connections and degrees of freedom of one kinematic tree.

The world is the single source of truth that every semantic object is a view over. It knows no
file format (``urdf.py`` builds one). Its structure is immutable: bodies and connections are frozen
records in topological order (a parent before its children), names are indexed, and derived
structures (parents, depths, chains) are computed once. Adding a frame or a base connection makes a
new world. The one piece of state a world carries is its table of degree-of-freedom limits, since
robots tighten velocity limits after compilation (the seed's
``tighten_dof_velocity_limits_of_1dof_connections``), and those limits only ever tighten.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace
from typing import TypeVar

import numpy as np

from robotspec.arrays import real_number
from robotspec.errors import (
    DescriptionError,
    DuplicateNameError,
    KinematicsError,
    NotFoundError,
    raise_collected,
)
from robotspec.model.entities import Body, Connection, ConnectionType, DegreeOfFreedom, Mimic
from robotspec.model.geometry import Matrix, frozen_array

_T = TypeVar("_T")
_R = TypeVar("_R", Body, Connection)

__all__ = [
    "Body",
    "Connection",
    "ConnectionType",
    "DegreeOfFreedom",
    "Mimic",
    "World",
]


class World:
    """A kinematic tree of bodies and connections, with its degrees of freedom.

    Build one with ``World(name, bodies, connections, dofs)``; records must already carry their
    final indices (the URDF loader does this). Construction checks the tree: unique names, every
    connection's bodies exist, one root, no cycle, each body has at most one parent.
    """

    def __init__(
        self,
        name: str,
        bodies: Sequence[Body],
        connections: Sequence[Connection],
        dofs: Sequence[DegreeOfFreedom],
        *,
        source: str | None = None,
    ) -> None:
        self.name = name
        self.source = source
        #: Velocity limits as loaded, of the DOFs whose limit was tightened since (by name).
        self.loaded_velocity_limits: dict[str, float] = {}
        _check_indices(bodies, connections, dofs, source)
        parent_conn, root = _parents_and_root(bodies, connections, source)
        order = _topological_order(bodies, connections, parent_conn, root, source)
        # Re-index into topological order so every array below is parent-before-child.
        # Records already in place are kept as they are (a copy per record is most of the
        # build time of a large, already ordered description).
        remap = {old: new for new, old in enumerate(order)}
        self._bodies: tuple[Body, ...] = tuple(
            bodies[old] if old == new else _moved(bodies[old], index=new)
            for new, old in enumerate(order)
        )
        conn_order = [parent_conn[old] for old in order if parent_conn[old] != -1]

        def placed(new: int, old: int) -> Connection:
            c = connections[old]
            parent, child = remap[c.parent], remap[c.child]
            if (c.index, c.parent, c.child) == (new, parent, child):
                return c
            return _moved(c, index=new, parent=parent, child=child)

        self._connections: tuple[Connection, ...] = tuple(
            placed(new, old) for new, old in enumerate(conn_order)
        )
        self._dofs: tuple[DegreeOfFreedom, ...] = tuple(dofs)
        self._body_index = {b.name: b.index for b in self._bodies}
        self._connection_index = {c.name: c.index for c in self._connections}
        self._dof_index = {d.name: d.index for d in self._dofs}
        self._parent_connection = np.full(len(self._bodies), -1, dtype=np.int64)
        for c in self._connections:
            self._parent_connection[c.child] = c.index
        self._parent_connection.setflags(write=False)
        depth = [0] * len(self._bodies)
        for c in self._connections:
            depth[c.child] = depth[c.parent] + 1
        self._depth = tuple(depth)
        self._annotations: list[object] = []
        # One pass over the connections (linear in the tree's size; 60,000 links are routine
        # for generated descriptions, and a scan per body was quadratic).
        children: list[list[int]] = [[] for _ in self._bodies]
        for c in self._connections:
            children[c.parent].append(c.child)
        self._children: tuple[tuple[int, ...], ...] = tuple(map(tuple, children))

    # ----------------------------------------------------------------- records and lookups
    @property
    def bodies(self) -> tuple[Body, ...]:
        """All bodies, root first, each after its parent."""
        return self._bodies

    @property
    def kinematic_structure_entities(self) -> tuple[Body, ...]:
        """The seed's name for :attr:`bodies` (robotspec has no regions)."""
        return self._bodies

    @property
    def connections(self) -> tuple[Connection, ...]:
        """All connections, in the order of their child bodies."""
        return self._connections

    @property
    def degrees_of_freedom(self) -> tuple[DegreeOfFreedom, ...]:
        """The configuration's coordinates, with their current limits."""
        return self._dofs

    @property
    def root(self) -> Body:
        """The body without a parent."""
        return self._bodies[0]

    @property
    def body_names(self) -> tuple[str, ...]:
        """Names of all bodies, in index order."""
        return tuple(b.name for b in self._bodies)

    @property
    def connection_names(self) -> tuple[str, ...]:
        """Names of all connections, in index order."""
        return tuple(c.name for c in self._connections)

    @property
    def dof_names(self) -> tuple[str, ...]:
        """Names of all degrees of freedom, in configuration order."""
        return tuple(d.name for d in self._dofs)

    def _where(self) -> str:
        return self.source.rsplit("/", 1)[-1] if self.source else f"world '{self.name}'"

    def get_body_by_name(self, name: str) -> Body:
        """The body called ``name``; NotFoundError with the closest names otherwise."""
        idx = self._body_index.get(name)
        if idx is None:
            raise NotFoundError("link", name, self._body_index, where=self._where())
        return self._bodies[idx]

    get_kinematic_structure_entity_by_name = get_body_by_name

    def get_connection_by_name(self, name: str) -> Connection:
        """The connection called ``name``; NotFoundError with the closest names otherwise."""
        idx = self._connection_index.get(name)
        if idx is None:
            raise NotFoundError("joint", name, self._connection_index, where=self._where())
        return self._connections[idx]

    def get_degree_of_freedom_by_name(self, name: str) -> DegreeOfFreedom:
        """The degree of freedom called ``name`` (a 1-DOF joint's DOF shares its name)."""
        idx = self._dof_index.get(name)
        if idx is None:
            raise NotFoundError("degree of freedom", name, self._dof_index, where=self._where())
        return self._dofs[idx]

    def has_body(self, name: str) -> bool:
        """Whether a body called ``name`` exists."""
        return name in self._body_index

    def has_connection(self, name: str) -> bool:
        """Whether a connection called ``name`` exists."""
        return name in self._connection_index

    def parent_connection(self, body: Body | str) -> Connection | None:
        """The connection whose child is ``body`` (``None`` for the root)."""
        b = self._as_body(body)
        idx = int(self._parent_connection[b.index])
        return None if idx < 0 else self._connections[idx]

    def child_bodies(self, body: Body | str) -> tuple[Body, ...]:
        """The bodies directly below ``body``."""
        return tuple(self._bodies[i] for i in self._children[self._as_body(body).index])

    def depth(self, body: Body | str) -> int:
        """Number of connections between the root and ``body``."""
        return self._depth[self._as_body(body).index]

    def _as_body(self, body: Body | str) -> Body:
        return self.get_body_by_name(body) if isinstance(body, str) else body

    def connections_of_dof(self, dof: int) -> tuple[Connection, ...]:
        """Connections driven by a degree of freedom (its owner and its mimics)."""
        return tuple(c for c in self._connections if dof in c.dofs)

    # ----------------------------------------------------------------------- tree queries
    def ancestors(self, body: Body | str) -> tuple[Body, ...]:
        """``body`` and every body above it, up to the root (in that order)."""
        idx = self._as_body(body).index
        out = [self._bodies[idx]]
        while (c := int(self._parent_connection[idx])) >= 0:
            idx = self._connections[c].parent
            out.append(self._bodies[idx])
        return tuple(out)

    def is_ancestor(self, ancestor: Body | str, body: Body | str) -> bool:
        """Whether ``ancestor`` lies on the path from the root to ``body`` (a body is its own)."""
        a = self._as_body(ancestor)
        return any(b.index == a.index for b in self.ancestors(body))

    def common_ancestor(self, a: Body | str, b: Body | str) -> Body:
        """The deepest body that is an ancestor of both."""
        above_a = {x.index for x in self.ancestors(a)}
        for x in self.ancestors(b):
            if x.index in above_a:
                return x
        return self.root  # unreachable in a tree; keeps the type checker content

    def compute_chain_of_kinematic_structure_entities(
        self, root: Body | str, tip: Body | str
    ) -> list[Body]:
        """Bodies from ``root`` down to ``tip``, both included; ``root`` must be an ancestor.

        Why an error rather than the reference's bare assertion: a chain whose root is a sibling of
        its tip (the seed HSRB arm) is the commonest semantic mistake, so the message names the
        common ancestor to use instead.
        """
        r, t = self._as_body(root), self._as_body(tip)
        path = self.ancestors(t)
        for i, b in enumerate(path):
            if b.index == r.index:
                return list(reversed(path[: i + 1]))
        common = self.common_ancestor(r, t)
        if self.is_ancestor(t, r):
            detail = f"'{t.name}' is above '{r.name}'; swap root and tip"
        else:
            detail = f"they are on different branches below '{common.name}'"
        raise KinematicsError(
            f"'{r.name}' is not an ancestor of '{t.name}': {detail}",
            kind="chain",
            name=r.name,
            suggestions=(common.name,),
        )

    def compute_chain_of_connections(self, root: Body | str, tip: Body | str) -> list[Connection]:
        """Connections between consecutive bodies of the root-to-tip chain (empty if equal)."""
        bodies = self.compute_chain_of_kinematic_structure_entities(root, tip)
        return [self._connections[int(self._parent_connection[b.index])] for b in bodies[1:]]

    def compute_split_chain_of_kinematic_structure_entities(
        self, root: Body | str, tip: Body | str
    ) -> tuple[list[Body], list[Body], list[Body]]:
        """The path between any two bodies, split at their common ancestor.

        Returns ``(up, [common_ancestor], down)``: ``up`` runs from ``root`` up to (excluding) the
        ancestor, ``down`` from below the ancestor to ``tip``. Works across branches (finger to
        finger), unlike the plain chain.
        """
        r, t = self._as_body(root), self._as_body(tip)
        common = self.common_ancestor(r, t)
        up = list(self.compute_chain_of_kinematic_structure_entities(common, r))[1:]
        up.reverse()
        down = list(self.compute_chain_of_kinematic_structure_entities(common, t))[1:]
        return up, [common], down

    def compute_split_chain_of_connections(
        self, root: Body | str, tip: Body | str
    ) -> tuple[list[Connection], list[Connection]]:
        """Connections up from ``root`` to the common ancestor, and down from it to ``tip``."""
        r, t = self._as_body(root), self._as_body(tip)
        common = self.common_ancestor(r, t)
        up = list(reversed(self.compute_chain_of_connections(common, r)))
        down = self.compute_chain_of_connections(common, t)
        return up, down

    def subtree(self, body: Body | str) -> tuple[Body, ...]:
        """``body`` and every body below it, in topological order."""
        top = self._as_body(body).index
        inside = {top}
        out = [self._bodies[top]]
        for c in self._connections:
            if c.parent in inside:
                inside.add(c.child)
                out.append(self._bodies[c.child])
        return tuple(out)

    # ---------------------------------------------------------------------- new worlds
    def add_frames(self, frames: Iterable[tuple[str, str, Matrix]]) -> World:
        """A new world with extra fixed frames ``(name, parent, parent_T_frame)``.

        Why: URDFs lack frames that semantics need (HSRB's ``hand_gripper_tool_frame``); adding
        them to the world keeps every consumer (FK, chains, collision) consistent.
        """
        bodies = list(self._bodies)
        conns = list(self._connections)
        problems: list[DescriptionError | NotFoundError | DuplicateNameError] = []
        names = set(self._body_index)
        for name, parent, pose in frames:
            if parent not in names:
                problems.append(NotFoundError("link", parent, names, where=self._where()))
                continue
            if name in names:
                problems.append(
                    DuplicateNameError(f"frame '{name}' already exists", kind="link", name=name)
                )
                continue
            pose_arr = np.asarray(pose, dtype=np.float64)
            if pose_arr.shape != (4, 4) or not np.all(np.isfinite(pose_arr)):
                problems.append(DescriptionError(f"frame '{name}': pose must be a finite 4x4"))
                continue
            parent_idx = next(b.index for b in bodies if b.name == parent)
            child = Body(name=name, index=len(bodies))
            bodies.append(child)
            joint = f"{parent}_T_{name}"
            conns.append(
                Connection(
                    name=joint,
                    index=len(conns),
                    type=ConnectionType.FIXED,
                    parent=parent_idx,
                    child=child.index,
                    origin=frozen_array(pose_arr),
                )
            )
            names.add(name)
        raise_collected(problems)
        return World(self.name, bodies, conns, self._dofs, source=self.source)

    def with_base_connection(
        self,
        name: str,
        parent_frame: str,
        type: ConnectionType,
        *,
        axis: tuple[float, float, float] = (0.0, 0.0, 1.0),
    ) -> World:
        """A new world whose root hangs from a new ``parent_frame`` body through ``name``.

        This is how an SRDF virtual joint (``odom_combined`` -planar-> ``base_footprint``) becomes
        the robot's drive connection.
        """
        if parent_frame in self._body_index:
            raise DuplicateNameError(
                f"virtual joint parent frame '{parent_frame}' is already a link of the robot",
                kind="link",
                name=parent_frame,
            )
        if name in self._connection_index:
            raise DuplicateNameError(f"joint '{name}' already exists", kind="joint", name=name)
        bodies = [replace(b, index=b.index + 1) for b in self._bodies]
        bodies.insert(0, Body(name=parent_frame, index=0))
        dofs = [replace(d, index=d.index + type.dof_count) for d in self._dofs]
        new_dofs = [
            DegreeOfFreedom(
                name=name + sfx, index=i, connection=name, lower=-math.inf, upper=math.inf
            )
            for i, sfx in enumerate(type.dof_suffixes)
        ]
        shift = type.dof_count
        conns = [
            replace(
                c,
                index=c.index + 1,
                parent=c.parent + 1,
                child=c.child + 1,
                dofs=tuple(d + shift for d in c.dofs),
            )
            for c in self._connections
        ]
        conns.insert(
            0,
            Connection(
                name=name,
                index=0,
                type=type,
                parent=0,
                child=1,
                origin=frozen_array(np.eye(4)),
                axis=axis,
                dofs=tuple(range(shift)),
            ),
        )
        return World(self.name, bodies, conns, [*new_dofs, *dofs], source=self.source)

    # ---------------------------------------------------------------- semantic annotations
    def add_semantic_annotation(self, annotation: object) -> None:
        """Register a semantic part viewing this world (once; identity decides)."""
        if not any(a is annotation for a in self._annotations):
            self._annotations.append(annotation)

    @property
    def semantic_annotations(self) -> tuple[object, ...]:
        """Every registered semantic part, in registration order."""
        return tuple(self._annotations)

    def get_semantic_annotations_by_type(self, kind: type[_T]) -> list[_T]:
        """The registered parts that are instances of ``kind``."""
        return [a for a in self._annotations if isinstance(a, kind)]

    # ------------------------------------------------------------------------- limits
    def tighten_velocity_limits(self, limits: Mapping[str, float]) -> None:
        """Lower the velocity limit of the named degrees of freedom; never raises one.

        Why mutate: limits are the world's state, and robots tighten them after compiling (the
        seed's semantics); structure stays immutable.
        """
        dofs = list(self._dofs)
        for name, value in limits.items():
            d = self.get_degree_of_freedom_by_name(name)
            if not (value > 0 and math.isfinite(value)):
                raise KinematicsError(
                    f"velocity limit for '{name}' must be positive and finite, got {value}",
                    name=name,
                )
            if float(value) < d.velocity:
                self.loaded_velocity_limits.setdefault(d.name, d.velocity)
            dofs[d.index] = replace(d, velocity=min(d.velocity, float(value)))
        self._dofs = tuple(dofs)

    def default_configuration(self) -> np.ndarray:
        """The robot's one default pose, MoveIt's: 0 where the limits allow it, else mid-range.

        An unbounded DOF whose range excludes 0 takes its finite limit. Collision sampling,
        pictures and named states all start here, so "default" means one thing everywhere.
        """
        q = np.zeros(len(self._dofs), dtype=np.float64)
        for d in self._dofs:
            if d.lower > 0.0 or d.upper < 0.0:
                if d.is_bounded:
                    q[d.index] = (d.lower + d.upper) / 2.0
                else:
                    q[d.index] = d.lower if math.isfinite(d.lower) else d.upper
        return q

    def configuration(self, values: Mapping[str, float] | None = None) -> np.ndarray:
        """A configuration vector: the default pose, with ``values`` set by DOF name.

        A value must be a finite real number: a string, a complex number or an infinity is a
        KinematicsError naming the DOF (not numpy's bare error, nor a vector every query
        refuses later).
        """
        q = self.default_configuration()
        if values is not None and not isinstance(values, Mapping):
            raise KinematicsError(
                f"values must be a mapping of DOF names to numbers, got {type(values).__name__}"
            )
        for name, v in (values or {}).items():
            index = self.get_degree_of_freedom_by_name(name).index
            q[index] = real_number(v, f"value of '{name}'", KinematicsError)
        return q

    def __repr__(self) -> str:
        return (
            f"World({self.name!r}, {len(self._bodies)} bodies, "
            f"{len(self._connections)} connections, {len(self._dofs)} dofs)"
        )


def _moved(record: _R, **changes: int) -> _R:
    """``dataclasses.replace`` for the plain records, without its per-call introspection.

    Why: a 60,000-link tree moves every record once; the records have no ``__post_init__``.
    """
    return type(record)(**{**vars(record), **changes})


def _check_indices(
    bodies: Sequence[Body],
    connections: Sequence[Connection],
    dofs: Sequence[DegreeOfFreedom],
    source: str | None,
) -> None:
    problems: list[DescriptionError] = []
    for i, b in enumerate(bodies):
        if b.index != i:
            raise ValueError(f"body '{b.name}' has index {b.index}, expected {i}")
    for i, c in enumerate(connections):
        if c.index != i:
            raise ValueError(f"connection '{c.name}' has index {c.index}, expected {i}")
        if not (0 <= c.parent < len(bodies) and 0 <= c.child < len(bodies)):
            raise ValueError(f"connection '{c.name}' refers to a body index out of range")
        if c.parent == c.child:
            problems.append(
                DescriptionError(
                    f"joint '{c.name}' connects link '{bodies[c.child].name}' to itself",
                    file=source,
                    line=c.line,
                    kind="joint",
                    name=c.name,
                )
            )
        for d in c.dofs:
            if not 0 <= d < len(dofs):
                raise ValueError(f"connection '{c.name}' refers to a dof index out of range")
    for i, dof in enumerate(dofs):
        if dof.index != i:
            raise ValueError(f"dof '{dof.name}' has index {dof.index}, expected {i}")
    raise_collected(problems)


def _parents_and_root(
    bodies: Sequence[Body], connections: Sequence[Connection], source: str | None
) -> tuple[list[int], int]:
    """Each body's parent connection (-1 at the root) and the one root; else why not a tree."""
    parent_conn = [-1] * len(bodies)
    problems: list[DescriptionError] = []
    for c in connections:
        if parent_conn[c.child] != -1:
            other = connections[parent_conn[c.child]].name
            problems.append(
                DescriptionError(
                    f"link '{bodies[c.child].name}' has two parent joints "
                    f"('{other}' and '{c.name}')",
                    file=source,
                    line=c.line,
                    kind="link",
                    name=bodies[c.child].name,
                )
            )
        else:
            parent_conn[c.child] = c.index
    raise_collected(problems)
    roots = [b.index for b in bodies if parent_conn[b.index] == -1]
    if not roots:
        raise DescriptionError(
            "the joints form a cycle: no link is without a parent", file=source, kind="cycle"
        )
    if len(roots) > 1:
        names = ", ".join(f"'{bodies[i].name}'" for i in roots[:6])
        more = "" if len(roots) <= 6 else f" and {len(roots) - 6} more"
        raise DescriptionError(
            f"the description has {len(roots)} root links ({names}{more}); "
            "a robot must be one tree",
            file=source,
            kind="root",
        )
    return parent_conn, roots[0]


def _topological_order(
    bodies: Sequence[Body],
    connections: Sequence[Connection],
    parent_conn: list[int],
    root: int,
    source: str | None,
) -> list[int]:
    children: list[list[int]] = [[] for _ in bodies]
    for c in connections:
        children[c.parent].append(c.child)
    order: list[int] = []
    stack = [root]
    seen = set()
    while stack:
        b = stack.pop()
        seen.add(b)
        order.append(b)
        stack.extend(reversed(children[b]))
    if len(order) != len(bodies):
        stuck = next(i for i in range(len(bodies)) if i not in seen)
        first = connections[parent_conn[stuck]]
        raise DescriptionError(
            f"the joints form a cycle through link '{bodies[stuck].name}'",
            file=source,
            line=first.line,
            kind="cycle",
            name=bodies[stuck].name,
        )
    return order
