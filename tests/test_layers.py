"""The package's layers import one way: the contract written in the README's layout section.

Every ``import`` of the package is read from the source (module level, inside functions and
under ``TYPE_CHECKING`` alike: a lazy import is still a dependency), and each edge between two
rooms must go down the stack. This is the import-linter contract, kept as a test so it needs no
extra tool.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "robotspec"

#: The stack, bottom first. A room may import rooms of lower floors and its own room only.
FLOORS: tuple[tuple[str, ...], ...] = (
    ("errors", "shipped", "arrays", "accel", "exact"),
    ("diagnostics", "extras"),
    ("files",),
    ("model",),
    ("description", "spec"),
    ("semantic",),
    ("compose",),
    ("compiler",),
    ("robots", "collision", "export"),
    ("render", "interop"),
    ("setup",),
    ("cli",),
)
#: Rooms beside the stack, with the only rooms they may use.
BESIDE: dict[str, frozenset[str]] = {
    # extras: the one fence of optional packages (MuJoCo for the plant, Robot Raconteur to serve).
    "driver": frozenset({"errors", "arrays", "exact", "extras", "files", "model"}),
    "service": frozenset({"errors", "arrays", "driver", "extras"}),
}
#: Which rooms of the stack may use a room beside it (the outputs and the CLI).
USED_BY: dict[str, frozenset[str]] = {
    "driver": frozenset({"export", "render", "cli"}),
    "service": frozenset({"cli"}),
}
#: Same-floor rooms that may use each other one way (importer -> imported).
SAME_FLOOR_ALLOWED: frozenset[tuple[str, str]] = frozenset(
    {
        ("spec", "description"),  # drafting a spec reads the robot's files
        ("export", "robots"),
        ("export", "collision"),
        ("collision", "robots"),
    }
)
#: The only upward edges, each a lazy import inside one method (module, imported module): a
#: robot hands itself to a room above it. ``AbstractRobot.to_pinocchio()`` is the entry point
#: pinocchio users look for on a robot (issue 20); the work is the interop room's.
UPWARD_METHODS: frozenset[tuple[str, str]] = frozenset(
    {
        ("robotspec.semantic.robot", "robotspec.interop.pinocchio"),
        # ``robotspec.accel.accelerated()`` / ``report()`` answer for every compiled core (issue
        # 34 names that entry point); each core's choice lives with the room that owns it.
        ("robotspec.accel", "robotspec.collision"),
        ("robotspec.accel", "robotspec.model"),
    }
)
#: Rooms that are the package's faces, not floors: they may import anything.
FACES = frozenset({"__init__", "__main__"})


def _room(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _floor(room: str) -> int | None:
    for i, rooms in enumerate(FLOORS):
        if room in rooms:
            return i
    return None


def _edges() -> list[tuple[str, str, int, str]]:
    """(importing module, imported module, line, importing room) for every package import."""
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        module = ".".join(rel.parts).removesuffix(".__init__")
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            names: list[str] = []
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            for name in names:
                if name == "robotspec" or name.startswith("robotspec."):
                    out.append((module, name, node.lineno, _room(module)))
    return out


def _allowed(src_room: str, dst_room: str) -> bool:
    if src_room == dst_room or src_room in FACES:
        return True
    if src_room in BESIDE:
        return dst_room in BESIDE[src_room]
    if dst_room in BESIDE:
        return src_room in USED_BY[dst_room]
    src, dst = _floor(src_room), _floor(dst_room)
    if src is None or dst is None:
        return False
    return dst < src or (dst == src and (src_room, dst_room) in SAME_FLOOR_ALLOWED)


def test_every_room_is_on_the_map() -> None:
    rooms = {_room(m) for m, *_ in _edges()} | {
        p.stem if p.is_file() else p.name
        for p in PACKAGE.iterdir()
        if (p.suffix == ".py" or (p / "__init__.py").exists()) and p.name != "__pycache__"
    }
    mapped = {r for floor in FLOORS for r in floor} | set(BESIDE) | FACES
    assert rooms - mapped == set(), "add new rooms to FLOORS or BESIDE (and the README layout)"


def test_imports_go_down_the_stack() -> None:
    wrong = [
        f"{src} (line {line}) imports {dst}"
        for src, dst, line, room in _edges()
        if not _allowed(room, _room(dst)) and (src, dst) not in UPWARD_METHODS
    ]
    assert wrong == []


def test_upward_edges_are_lazy() -> None:
    """An allowed upward edge is an import inside a function, never at module level."""
    for src, dst in UPWARD_METHODS:
        path = PACKAGE.parent.joinpath(*src.split(".")).with_suffix(".py")
        tree = ast.parse(path.read_text(encoding="utf-8"))
        top = [n.module for n in tree.body if isinstance(n, ast.ImportFrom)] + [
            n.module
            for block in tree.body
            if isinstance(block, ast.If)
            for n in block.body
            if isinstance(n, ast.ImportFrom)
        ]
        assert dst not in top, f"{src} imports {dst} at module level"


def test_nothing_imports_the_cli() -> None:
    users = {src for src, dst, _, room in _edges() if _room(dst) == "cli" and room not in FACES}
    assert {u for u in users if _room(u) != "cli"} == set()


def test_commands_never_import_commands() -> None:
    # Shared CLI work lives in plain modules (validation_report, chain_table, driving).
    calls = {
        (src, dst)
        for src, dst, _, room in _edges()
        if src.endswith("_cmd") and dst.endswith("_cmd") and src != dst
    }
    assert calls == set()


@pytest.mark.parametrize("room", ["driver", "service"])
def test_rooms_beside_the_stack_stay_beside_it(room: str) -> None:
    used = {_room(dst) for src, dst, _, r in _edges() if r == room} - {room}
    assert used <= BESIDE[room]
