"""Print every function of the package longer than a limit, longest first, as file:line.

Why: a function over 80 lines usually does two jobs, and the seam between them is where a
newcomer would look for one of them. Counting is by source lines from ``def`` to the last line
of the body (docstring, comments and blank lines included), nested functions counted apart
and inside their parent, as ``ast`` reports them.

    python tools/long_functions.py                  # robotspec/, over 80 lines
    python tools/long_functions.py --limit 60 robotspec/driver tools
    python tools/long_functions.py --modules 600    # modules over 600 lines too

Exit status 0 always: this is a report, not a gate.
"""

from __future__ import annotations

import argparse
import ast
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Long:
    """One function over the limit: where it starts, its qualified name and its length.

    ``body`` counts from the first statement after the docstring: a command whose options
    fill its signature (typer's ``Annotated`` parameters) is long without a long body.
    """

    path: Path
    line: int
    name: str
    lines: int
    body: int


def _functions(tree: ast.AST, prefix: str = "") -> Iterator[tuple[str, ast.AST]]:
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            yield f"{prefix}{node.name}", node
            yield from _functions(node, f"{prefix}{node.name}.")
        elif isinstance(node, ast.ClassDef):
            yield from _functions(node, f"{prefix}{node.name}.")
        else:
            yield from _functions(node, prefix)


def long_functions(paths: list[Path], limit: int) -> list[Long]:
    """Every function under ``paths`` longer than ``limit`` lines, longest first."""
    found = []
    for path in _python_files(paths):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for name, node in _functions(tree):
            assert isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
            first = min([node.lineno, *(d.lineno for d in node.decorator_list)])
            length = (node.end_lineno or node.lineno) - first + 1
            if length > limit:
                found.append(Long(path, node.lineno, name, length, _body_lines(node)))
    return sorted(found, key=lambda f: (-f.lines, str(f.path), f.line))


def _body_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    first = node.body[0]
    docstring = isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
    if docstring and len(node.body) > 1:
        first = node.body[1]
    return (node.end_lineno or node.lineno) - first.lineno + 1


def _python_files(paths: list[Path]) -> list[Path]:
    files: list[Path] = []
    for p in paths:
        files += sorted(p.rglob("*.py")) if p.is_dir() else [p]
    return [f for f in files if "__pycache__" not in f.parts]


def _show(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(ROOT))
    except ValueError:
        return str(path)


def main(argv: list[str] | None = None) -> int:
    """Print the report; see the module docstring."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", type=Path, default=[ROOT / "robotspec"])
    parser.add_argument("--limit", type=int, default=80, help="lines a function may have")
    parser.add_argument("--modules", type=int, default=0, help="also list modules over N lines")
    args = parser.parse_args(argv)
    found = long_functions(args.paths, args.limit)
    out = [f"{_show(f.path)}:{f.line}: {f.name} {f.lines} lines (body {f.body})" for f in found]
    out.append(f"{len(found)} function(s) over {args.limit} lines")
    if args.modules:
        sizes = [
            (len(p.read_text(encoding="utf-8").splitlines()), p) for p in _python_files(args.paths)
        ]
        big = sorted(((n, p) for n, p in sizes if n > args.modules), reverse=True)
        out += [f"{_show(p)}: {n} lines" for n, p in big]
        out.append(f"{len(big)} module(s) over {args.modules} lines")
    sys.stdout.write("\n".join(out) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
