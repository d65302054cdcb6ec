"""No import cycle between the package's rooms: files of two rooms never import each other round.

Every import of the package counts (module level, inside a function, under ``TYPE_CHECKING``):
a lazy import is still a dependency, and a cycle through one means neither room can be read,
tested or moved without the other. ``robot.to_pinocchio()`` once closed such a cycle
(semantic -> interop.pinocchio -> collision -> semantic); collision and interop now read a robot
through protocols (``robotspec.collision.robot_view``), and this test keeps it that way.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "robotspec"

#: Cycles across rooms that stand today, each with why it is tolerated (none may be added).
#: ``robotspec.accel.report()`` answers for each compiled core, whose choice imports accel back.
KNOWN: frozenset[frozenset[str]] = frozenset(
    {frozenset({"robotspec.accel", "robotspec.collision.meshcore", "robotspec.model.kincore"})}
)


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        out[".".join(rel.parts).removesuffix(".__init__")] = path
    return out


def _imports(tree: ast.AST, known: dict[str, Path]) -> Iterator[str]:
    """The package modules a file names: ``from a.b import c`` is ``a.b.c`` when that is one."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names if a.name in known)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            subs = [f"{node.module}.{a.name}" for a in node.names]
            found = [s for s in subs if s in known]
            yield from found
            if len(found) < len(subs) and node.module in known:
                yield node.module


def _graph() -> dict[str, set[str]]:
    known = _modules()
    return {
        m: {d for d in _imports(ast.parse(p.read_text(encoding="utf-8")), known) if d != m}
        for m, p in known.items()
    }


def _cycles(graph: dict[str, set[str]]) -> list[frozenset[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[frozenset[str]] = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                members = set()
                while True:
                    top = stack.pop()
                    on_stack.discard(top)
                    members.add(top)
                    if top == node:
                        break
                if len(members) > 1:
                    out.append(frozenset(members))
    return out


def _room(module: str) -> str:
    return module.split(".")[1] if "." in module else "__init__"


def _across_rooms(cycle: frozenset[str]) -> frozenset[str]:
    """The part of a cycle that crosses rooms: a cycle inside one room is that room's affair."""
    return cycle if len({_room(m) for m in cycle}) > 1 else frozenset()


def test_no_cycle_between_rooms() -> None:
    crossing = [c for c in map(_across_rooms, _cycles(_graph())) if c]
    assert sorted(sorted(c) for c in crossing if c not in KNOWN) == []


def test_semantic_robot_reaches_no_room_that_reaches_it_back() -> None:
    graph = _graph()
    cycle = next((c for c in _cycles(graph) if "robotspec.semantic.robot" in c), frozenset())
    assert {_room(m) for m in cycle} <= {"semantic"}


def test_the_cycle_finder_finds_a_cycle() -> None:
    graph = {"robotspec.a.x": {"robotspec.b.y"}, "robotspec.b.y": {"robotspec.a.x"}}
    graph["robotspec.c"] = set()
    assert _cycles(graph) == [frozenset({"robotspec.a.x", "robotspec.b.y"})]
