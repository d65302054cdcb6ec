"""The evaluator of xacro's ``${...}`` and ``$(eval ...)``: a closed namespace with budgets.

Why not xacro's own ``safe_eval``: it checks for ``__`` names only in the outer compiled code,
so ``${[x.__class__ for x in [0]]}``, a run-time built ``'{0.__globals__}'.format(f)`` or
``${math.update(pi=0.5)}`` (which changed ``math.pi`` for every later document) all worked, and
``${9**9**9}`` or ``${'a'*3000000000}`` ran until memory or patience ran out.

Here an expression is parsed, checked and rewritten before it runs:

* no name or attribute starting with ``_``; no ``:=``;
* attribute access goes through :meth:`Budget.getattr`: a xacro namespace or YAML mapping is
  read by key (``math.pi``, ``config.arm.length``), other objects only for a small allow-list of
  harmless methods (no ``format``/``format_map``, nothing that reaches a module);
* ``**``, ``*``, ``<<``, ``+`` and ``%`` on sized values check the size of their result
  *before* computing it (integer bits, string and list lengths);
* every comprehension's iterable, and every ``range``, is counted against the document's step
  budget, and the wall-clock deadline is checked as it goes.

The namespace itself is made fresh for every document by the caller
(:func:`robotspec.files.xacro.process_xacro`), so nothing one document does is seen by the next.
"""

from __future__ import annotations

import ast
import math
import re
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from robotspec.errors import DescriptionError
from robotspec.files.limits import Limits, env_name

__all__ = ["Budget"]

#: Methods an expression may call on plain values, by type. Nothing here builds a value larger
#: than its input, formats with attribute lookups, or returns a module, type or frame.
_METHODS: dict[type, frozenset[str]] = {
    str: frozenset(
        "upper lower strip lstrip rstrip split rsplit startswith endswith capitalize title "
        "isdigit isalpha isalnum isspace count find rfind index".split()
    ),
    int: frozenset(("bit_length", "real", "imag", "is_integer")),
    float: frozenset(("is_integer", "real", "imag")),
    bool: frozenset(),
    list: frozenset(("index", "count")),
    tuple: frozenset(("index", "count")),
    dict: frozenset(("get", "keys", "values", "items")),
}

_HELPERS = ("pow", "mul", "lshift", "add", "mod", "getattr", "iter")
_BIG_WIDTH = re.compile(r"%[-+ #0]*(\d{5,}|\*)|\.(\d{5,})")


@dataclass
class Budget:
    """What one xacro document may still spend; every overdraft is a located error."""

    limits: Limits
    namespace_types: tuple[type, ...] = ()
    mapping_types: tuple[type, ...] = ()
    deadline: float = 0.0
    steps: int = 0
    macro_calls: int = 0
    macro_depth: int = 0
    files_opened: int = 0
    _codes: dict[str, Any] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if not self.deadline:
            self.deadline = time.monotonic() + self.limits.xacro_seconds

    # ---------------------------------------------------------------- budgets
    def over(self, what: str, cap_name: str, cap: float) -> DescriptionError:
        """The error for an exceeded budget (located by the caller)."""
        return DescriptionError(
            f"xacro {what} (the limit is {cap:,}; set {env_name(cap_name)} to raise it)",
            kind="xacro budget",
        )

    def check_time(self) -> None:
        """Stop when the document's wall-clock budget is spent."""
        if time.monotonic() > self.deadline:
            raise self.over("took too long to expand", "xacro_seconds", self.limits.xacro_seconds)

    def spend(self, steps: int) -> None:
        """Count ``steps`` loop iterations or items made against the document's budget."""
        self.steps += steps
        if self.steps > self.limits.xacro_loop_steps:
            raise self.over(
                "expressions loop or build too much",
                "xacro_loop_steps",
                self.limits.xacro_loop_steps,
            )

    def _size(self, n: int) -> None:
        if n > self.limits.xacro_value_size:
            raise self.over(
                f"value too large ({n} items)", "xacro_value_size", self.limits.xacro_value_size
            )
        self.spend(n // 64)

    def _bits(self, bits: int) -> None:
        if bits > self.limits.xacro_int_bits:
            raise self.over(
                f"integer too large (about {bits} bits)",
                "xacro_int_bits",
                self.limits.xacro_int_bits,
            )

    # ---------------------------------------------------------------- checked operations
    def pow(self, a: Any, b: Any) -> Any:
        """``a ** b``, its integer size checked first."""
        if _is_int(a) and _is_int(b) and b > 0 and abs(a) > 1:
            self._bits(int(max(1, abs(a).bit_length() - 1) * min(b, 1 << 40)))
        return a**b

    def mul(self, a: Any, b: Any) -> Any:
        """``a * b``, its integer size or repeated length checked first."""
        if _is_int(a) and _is_int(b):
            self._bits(abs(a).bit_length() + abs(b).bit_length())
        elif _sized(a) and _is_int(b):
            self._size(len(a) * max(b, 0))
        elif _sized(b) and _is_int(a):
            self._size(len(b) * max(a, 0))
        return a * b

    def lshift(self, a: Any, b: Any) -> Any:
        """``a << b``, its integer size checked first."""
        if _is_int(a) and _is_int(b) and b > 0:
            self._bits(abs(a).bit_length() + min(b, 1 << 40))
        return a << b

    def add(self, a: Any, b: Any) -> Any:
        """``a + b``, a concatenation's length checked first."""
        if _sized(a) and _sized(b):
            self._size(len(a) + len(b))
        return a + b

    def mod(self, a: Any, b: Any) -> Any:
        """``a % b``; a printf format with a huge width is refused."""
        if isinstance(a, str) and _BIG_WIDTH.search(a):
            raise DescriptionError(
                "xacro format width or precision too large (at most 4 digits)", kind="xacro"
            )
        out = a % b
        if isinstance(out, str):
            self._size(len(out))
        return out

    def getattr(self, obj: Any, name: str) -> Any:
        """``obj.name`` for a namespace key, a YAML key, or an allowed method."""
        if name.startswith("_"):
            raise _refused(f"attribute '{name}'")
        value: Any = obj
        if self.namespace_types and isinstance(obj, self.namespace_types):
            try:
                return value[name]
            except KeyError:
                raise NameError(f"name '{name}' is not defined") from None
        if self.mapping_types and isinstance(obj, self.mapping_types):
            if name in dict.keys(value) or name not in _METHODS[dict]:
                return getattr(value, name)  # the YAML wrapper reads keys as attributes
        for kind in type(obj).__mro__:
            allowed = _METHODS.get(kind)
            if allowed is not None:
                if name in allowed:
                    return getattr(obj, name)
                break
        raise _refused(f"attribute '{name}' of a {type(obj).__name__}")

    def iter(self, items: Iterable[Any]) -> Iterator[Any]:
        """The items of ``items``, each counted against the step budget."""
        for i, item in enumerate(items):
            if i % 1024 == 0:
                self.check_time()
            self.spend(1)
            yield item

    def range(self, *args: int) -> range:
        """``range`` whose length counts against the step budget when it is made."""
        r = range(*args)
        self.spend(len(r))
        return r

    def bounded(self, fn: Callable[..., Any], name: str, cap: int) -> Callable[..., Any]:
        """``fn`` refusing integer arguments above ``cap`` (``math.factorial`` and kin)."""

        def call(*args: Any) -> Any:
            if any(_is_int(a) and abs(a) > cap for a in args):
                raise DescriptionError(
                    f"xacro math.{name}() argument too large (at most {cap})", kind="xacro"
                )
            return fn(*args)

        return call

    # ---------------------------------------------------------------- evaluation
    def builtins(self, extra: dict[str, Any] | None = None) -> dict[str, Any]:
        """The ``__builtins__`` of an evaluation: the helpers the rewrite calls, nothing else."""
        out: dict[str, Any] = {f"__rs_{h}": getattr(self, h) for h in _HELPERS}
        out.update(extra or {})
        return out

    def compile(self, expr: str) -> Any:
        """``expr`` checked and rewritten, compiled once per distinct text."""
        code = self._codes.get(expr)
        if code is None:
            try:
                tree = ast.parse(expr.strip(), "<expression>", "eval")
            except (SyntaxError, ValueError, MemoryError, RecursionError) as exc:
                raise SyntaxError(f"invalid expression: {exc}") from None
            _Check().visit(tree)
            tree = ast.fix_missing_locations(_Rewrite().visit(tree))
            code = compile(tree, "<expression>", "eval")
            if len(self._codes) < 4096:
                self._codes[expr] = code
        return code

    def eval(self, expr: str, globals: Any, locals: Any = None, extra: Any = None) -> Any:
        """Evaluate ``expr`` in ``globals`` (xacro's symbol table) under this budget."""
        self.check_time()
        code = self.compile(expr)
        dict.__setitem__(globals, "__builtins__", self.builtins(extra))
        try:
            result = eval(code, globals, locals)
        except (OverflowError, MemoryError, RecursionError) as exc:
            raise DescriptionError(
                f"xacro expression failed: {type(exc).__name__}: {exc}", kind="xacro"
            ) from None
        if _sized(result):
            self._size(len(result))
        elif _is_int(result):
            self._bits(abs(result).bit_length())
        return result


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _sized(value: Any) -> bool:
    return isinstance(value, (str, bytes, list, tuple, dict, set, frozenset))


def _refused(what: str) -> DescriptionError:
    return DescriptionError(
        f"{what} is not allowed in xacro expressions by robotspec "
        "(it could reach outside the sandbox)",
        kind="xacro",
    )


class _Check(ast.NodeVisitor):
    """Refuse what no robot description needs and what reaches outside the sandbox."""

    def visit_Name(self, node: ast.Name) -> None:
        if node.id.startswith("__"):
            raise _refused(f"name '{node.id}'")

    def visit_Attribute(self, node: ast.Attribute) -> None:
        if node.attr.startswith("_"):
            raise _refused(f"attribute '{node.attr}'")
        self.generic_visit(node)

    def visit_NamedExpr(self, node: ast.NamedExpr) -> None:
        raise _refused("assignment ':='")

    def visit_FormattedValue(self, node: ast.FormattedValue) -> None:
        spec = node.format_spec
        if spec is not None:
            text = ast.unparse(spec)
            if any(not isinstance(v, ast.Constant) for v in getattr(spec, "values", [])) or (
                re.search(r"\d{5,}", text)
            ):
                raise _refused("a computed or very wide format specification")
        self.generic_visit(node)


_BINOPS = {ast.Pow: "pow", ast.Mult: "mul", ast.LShift: "lshift", ast.Add: "add", ast.Mod: "mod"}


class _Rewrite(ast.NodeTransformer):
    """Route size-changing operators, attribute reads and loops through the budget."""

    @staticmethod
    def _call(helper: str, *args: ast.expr) -> ast.Call:
        return ast.Call(ast.Name(f"__rs_{helper}", ast.Load()), list(args), [])

    def visit_BinOp(self, node: ast.BinOp) -> ast.expr:
        self.generic_visit(node)
        helper = _BINOPS.get(type(node.op))
        if helper is None:
            return node
        return ast.copy_location(self._call(helper, node.left, node.right), node)

    def visit_Attribute(self, node: ast.Attribute) -> ast.expr:
        self.generic_visit(node)
        if not isinstance(node.ctx, ast.Load):
            raise _refused(f"assignment to attribute '{node.attr}'")
        return ast.copy_location(self._call("getattr", node.value, ast.Constant(node.attr)), node)

    def visit_comprehension(self, node: ast.comprehension) -> ast.comprehension:
        self.generic_visit(node)
        node.iter = self._call("iter", node.iter)
        return node


def math_limits() -> dict[str, int]:
    """Integer-argument caps for the ``math`` functions whose cost grows with their argument."""
    return {"factorial": 2000, "comb": 2000, "perm": 2000, "isqrt": 1 << 1024}


def unbounded_math() -> tuple[str, ...]:
    """``math`` functions removed outright (their cost depends on an iterable's values)."""
    return ("prod",)


_ = math  # math's functions are exposed by xacro; the caps above name the costly ones
