"""Expand xacro files with the real ``xacro`` package, without ROS and without trusting the input.

Why the real xacro: its macro language has many corner cases (scoped properties, ``load_yaml``,
in-order processing) that a re-implementation would get subtly wrong, and the shipped URDFs of
the robots robotspec targets were made with it. Why the patches: PyPI's xacro resolves
``$(find PKG)`` through ``ament_index_python`` (absent without ROS), opens any file an include
names, lets minidom expand XML entities, and its expression sandbox is escapable. While a file
is expanded, robotspec therefore swaps a few of xacro's module-level hooks, under one lock, and
restores them afterwards:

* ``substitution_args._eval_find`` (and the ``find`` of ``$(eval ...)``) asks the
  :class:`~robotspec.files.packages.PackageResolver`.
* ``open`` inside ``xacro`` (used for the top file, every ``<xacro:include>`` and
  ``xacro.load_yaml``) is shadowed by a guard that refuses paths outside the resolver's allowed
  roots and XML that declares entities, before minidom sees a byte.
* xacro's symbol table is made fresh for every document (``create_global_symbols``), so
  nothing a document does to ``math`` or ``xacro`` is seen by the next one.
* ``${...}`` and ``$(eval ...)`` are evaluated by :class:`~robotspec.files.xacro_sandbox.Budget`:
  a checked and rewritten expression with no route to module globals, and budgets of value
  size, integer size, loop steps and wall time; macro calls are counted and their nesting
  bounded. ``python.vars``/``python.type`` are disabled (they reach object internals).
* ``xacro.load_yaml`` reads through robotspec's bounded YAML reader (depth and alias caps)
  and the same allowed roots.

Every budget is a field of :class:`~robotspec.files.limits.Limits`, raised with an environment
variable. The hooks are module globals of xacro 2.x, which is why ``pyproject.toml`` pins
``xacro>=2.0,<2.2``; ``tests/test_xacro.py`` checks the hooks still exist.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import threading
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any
from xml.parsers import expat

from robotspec.errors import DescriptionError, PathOutsideRootsError, RobotSpecError
from robotspec.files.limits import limits
from robotspec.files.packages import PackageResolver
from robotspec.files.reading import read_bounded, read_head, refuse_entities
from robotspec.files.xacro_legacy import prefix_legacy_tags
from robotspec.files.xacro_sandbox import Budget, math_limits, unbounded_math

__all__ = ["process_xacro"]

#: xacro keeps its state (file stack, substitution args, hooks) in module globals, so only one
#: expansion may run at a time; this lock is the module's only state.
_LOCK = threading.Lock()

#: ``python.*`` helpers disabled during expansion: with string keys they reach object internals.
_DISABLED_PYTHON_HELPERS = ("vars", "type")


def _current_file(xacro: Any) -> str | None:
    stack = [f for f in (getattr(xacro, "filestack", None) or []) if f]
    return str(stack[-1]) if stack else None


def _refuse_outside(resolver: PackageResolver, xacro: Any, filename: Any, path: str) -> None:
    if resolver.is_allowed(path):
        return
    stack = [str(f) for f in (getattr(xacro, "filestack", None) or []) if f]
    # xacro pushes an include on its file stack before opening it; report the includer.
    if stack and os.path.abspath(stack[-1]) == path:
        stack.pop()
    shown = ", ".join(str(r) for r in resolver.roots) or "none"
    raise PathOutsideRootsError(
        f"xacro file '{filename}' resolves to {os.path.realpath(path)}, "
        f"outside the allowed folders ({shown})",
        file=stack[-1] if stack else None,
        kind="path",
        name=str(filename),
    )


def _guarded_open(resolver: PackageResolver, xacro: Any, budget: Budget) -> Callable[..., Any]:
    """An ``open`` for xacro's module: allowed files only, bounded, no entity declarations."""

    def guarded(filename: Any, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
        if any(c in mode for c in "wax+"):
            raise DescriptionError(f"xacro tried to write '{filename}'", file=_current_file(xacro))
        path = os.path.abspath(os.fspath(filename))
        _refuse_outside(resolver, xacro, filename, path)
        budget.check_time()
        budget.files_opened += 1
        if budget.files_opened > budget.limits.max_xacro_includes:
            raise budget.over(
                "opened too many files", "max_xacro_includes", budget.limits.max_xacro_includes
            )
        if not os.path.lexists(path):  # an OSError: xacro skips optional includes on it
            raise FileNotFoundError(2, "No such file or directory", str(filename))
        try:
            data = read_bounded(
                path,
                cap=budget.limits.max_xacro_include_bytes,
                cap_name="max_xacro_include_bytes",
                what="a xacro file",
                error_type=DescriptionError,
            )
        except RobotSpecError as exc:
            # The includer named the file: point at it, not at the spec that named the top file.
            stack = [str(f) for f in (getattr(xacro, "filestack", None) or []) if f]
            includer = stack[-2] if len(stack) > 1 else None
            raise DescriptionError(
                f"xacro include '{path}' {exc.message}",
                file=includer,
                line=_line_of(includer, re.compile(re.escape(os.path.basename(path)))),
                kind="xacro include",
                name=str(filename),
            ) from None
        refuse_entities(data, path, DescriptionError)
        return io.BytesIO(prefix_legacy_tags(data))  # ROS 1's unprefixed <macro>, <property>

    return guarded


def _load_yaml(resolver: PackageResolver, xacro: Any, budget: Budget) -> Callable[[str], Any]:
    """``xacro.load_yaml`` through the allowed roots and robotspec's bounded YAML reader."""
    import yaml

    from robotspec.files.yamlio import check_yaml_shape

    class Loader(yaml.SafeLoader):
        """xacro's unit tags (``!degrees``) on a private loader, not on PyYAML's global one."""

    for unit in xacro.ConstructUnits:
        Loader.add_constructor(unit.value.tag, unit.constructor)

    def load_yaml(filename: Any) -> Any:
        name = xacro.abs_filename_spec(str(filename))
        path = os.path.abspath(name)
        _refuse_outside(resolver, xacro, filename, path)
        budget.check_time()
        data = read_bounded(
            path,
            cap=budget.limits.max_yaml_bytes,
            cap_name="max_yaml_bytes",
            what="a YAML file",
            error_type=DescriptionError,
        )
        text = data.decode("utf-8", errors="replace")
        check_yaml_shape(text, path)
        xacro.filestack.append(name)
        try:
            # A SafeLoader subclass: only plain data and the unit tags.
            return xacro.YamlListWrapper.wrap(yaml.load(text, Loader=Loader))
        except yaml.YAMLError as exc:
            raise DescriptionError(f"invalid YAML: {exc}", file=path) from None
        finally:
            xacro.filestack.pop()
            xacro.all_includes.append(name)

    return load_yaml


def _disabled(name: str) -> Callable[..., Any]:
    def refuse(*_args: Any, **_kwargs: Any) -> Any:
        raise DescriptionError(
            f"python.{name}() is disabled by robotspec: it reaches outside xacro's sandbox"
        )

    return refuse


def _fresh_symbols(xacro: Any, resolver: PackageResolver, budget: Budget) -> Any:
    """Xacro's global symbol table, new for this document, with robotspec's replacements."""
    symbols = xacro.create_global_symbols()
    load = _load_yaml(resolver, xacro, budget)
    bounded_range = budget.range
    for table in (symbols, symbols.get("python"), symbols.get("xacro"), symbols.get("math")):
        if table is None:
            continue
        for key in [k for k in dict.keys(table) if k in ("load_yaml", "range")]:
            dict.__setitem__(table, key, load if key == "load_yaml" else bounded_range)
    python_ns = symbols.get("python")
    if python_ns is not None:
        for key in _DISABLED_PYTHON_HELPERS:
            dict.__setitem__(python_ns, key, _disabled(key))
    _bound_math(symbols, budget)
    math_ns = symbols.get("math")
    if math_ns is not None:
        _bound_math(math_ns, budget)
    return symbols


def _bound_math(table: dict[str, Any], budget: Budget) -> None:
    for name, cap in math_limits().items():
        if name in table:
            dict.__setitem__(table, name, budget.bounded(dict.__getitem__(table, name), name, cap))
    for name in unbounded_math():
        if name in table:
            dict.__delitem__(table, name)


def _counted_macro_call(original: Callable[..., Any], budget: Budget) -> Callable[..., Any]:
    """Xacro's ``handle_macro_call`` counting calls and nesting against the budget."""

    def handle_macro_call(node: Any, macros: Any, symbols: Any) -> Any:
        tag = getattr(node, "tagName", "")
        if not (isinstance(tag, str) and tag.startswith("xacro:")):
            return original(node, macros, symbols)
        budget.check_time()
        budget.macro_calls += 1
        if budget.macro_calls > budget.limits.xacro_macro_calls:
            raise budget.over(
                f"expanded too many macro calls (in <{tag}>)",
                "xacro_macro_calls",
                budget.limits.xacro_macro_calls,
            )
        budget.macro_depth += 1
        try:
            if budget.macro_depth > budget.limits.xacro_macro_depth:
                raise budget.over(
                    f"macro calls nested too deeply (in <{tag}>)",
                    "xacro_macro_depth",
                    budget.limits.xacro_macro_depth,
                )
            return original(node, macros, symbols)
        finally:
            budget.macro_depth -= 1

    return handle_macro_call


@contextlib.contextmanager
def _patched(resolver: PackageResolver, budget: Budget) -> Iterator[Any]:
    """Install the hooks described in the module docstring; restore them on exit."""
    import xacro
    import xacro.substitution_args as subst

    def find(pkg: str) -> str:
        return str(resolver.find_package(pkg, file=_current_file(xacro)))

    budget.namespace_types = (xacro.NameSpace,)
    budget.mapping_types = (xacro.YamlDictWrapper,)
    saved_symbols = xacro._global_symbols
    saved_find = subst._eval_find
    saved_eval_dict = dict(subst._eval_dict)
    saved_safe_eval = xacro.safe_eval
    saved_macro_call = xacro.handle_macro_call
    saved_includes = list(xacro.all_includes)
    eval_builtins = dict(subst._eval_dict.get("__builtins__", {}))
    try:
        xacro._global_symbols = _fresh_symbols(xacro, resolver, budget)
        subst._eval_find = find
        subst._eval_dict["find"] = find
        _bound_math(subst._eval_dict, budget)
        subst.eval = lambda source, _g, locals=None: budget.eval(
            source, {}, locals, extra=eval_builtins
        )
        xacro.open = _guarded_open(resolver, xacro, budget)
        xacro.safe_eval = budget.eval
        xacro.handle_macro_call = _counted_macro_call(saved_macro_call, budget)
        yield xacro
    finally:
        xacro._global_symbols = saved_symbols
        subst._eval_find = saved_find
        subst._eval_dict.clear()
        subst._eval_dict.update(saved_eval_dict)
        with contextlib.suppress(AttributeError):
            del subst.eval
        with contextlib.suppress(AttributeError):
            del xacro.open
        xacro.safe_eval = saved_safe_eval
        xacro.handle_macro_call = saved_macro_call
        xacro.all_includes[:] = saved_includes
        xacro.substitution_args_context["arg"] = {}


def _chain(exc: BaseException) -> Iterator[BaseException]:
    """``exc`` and the exceptions xacro wrapped in it (``XacroException.exc``), outermost first."""
    seen: set[int] = set()
    current: BaseException | None = exc
    while current is not None and id(current) not in seen:
        seen.add(id(current))
        yield current
        inner = getattr(current, "exc", None)
        current = inner if isinstance(inner, BaseException) else current.__cause__


def _line_of(file: str | None, needle: re.Pattern[str]) -> int | None:
    """The first line of ``file`` matching ``needle``; xacro itself reports no lines."""
    if file is None:
        return None
    data = read_head(file, limits().max_xacro_include_bytes)
    if data is None:
        return None
    text = data.decode("utf-8", errors="replace")
    found = needle.search(text)
    return None if found is None else text.count("\n", 0, found.start()) + 1


def _message(exc: BaseException) -> str:
    text = str(exc).strip()
    return "; ".join(part.strip() for part in text.splitlines() if part.strip())


def _convert(exc: BaseException, xacro: Any, top: Path) -> RobotSpecError:
    """One :class:`DescriptionError` (or the robotspec error inside) for a failed expansion."""
    from xacro.substitution_args import ArgException

    file = _current_file(xacro) or str(top)
    for inner in _chain(exc):
        if isinstance(inner, RobotSpecError):
            if inner.line is None:
                where = inner.file or file
                return inner.located(file=where, line=_expression_line(exc, where))
            return inner
    for inner in _chain(exc):
        if isinstance(inner, ArgException):
            name = str(inner.args[0]) if inner.args else "?"
            pattern = re.compile(r"\$\(arg\s+" + re.escape(name) + r"\s*\)|arg\(['\"]" + name)
            return DescriptionError(
                f"xacro argument '{name}' is not set; pass it as xacro_args",
                file=file,
                line=_line_of(file, pattern),
                kind="xacro argument",
                name=name,
            )
        if isinstance(inner, expat.ExpatError):
            return DescriptionError(
                f"malformed XML: {expat.ErrorString(inner.code)}",
                file=file,
                line=inner.lineno or None,
                column=(inner.offset + 1) if inner.lineno else None,
            )
        if isinstance(inner, OSError) and inner.filename is not None:
            reason = inner.strerror or type(inner).__name__
            return DescriptionError(
                f"xacro cannot read '{inner.filename}': {reason}",
                file=file,
                kind="file",
                name=str(inner.filename),
            )
    message = _message(exc) or type(exc).__name__
    if len(message) > 400:
        message = message[:400] + "..."
    return DescriptionError(
        f"xacro failed: {message}", file=file, line=_expression_line(exc, file), kind="xacro"
    )


def _expression_line(exc: BaseException, file: str) -> int | None:
    """The line of the ``${...}`` xacro names in its message, or of the macro call."""
    text = str(exc)
    expr = re.search(r"when evaluating expression '(.*)'", text)
    if expr is not None:
        return _line_of(file, re.compile(r"\$\{" + re.escape(expr.group(1)) + r"\}"))
    tag = re.search(r"\(in <(xacro:[\w.:-]+)>\)", text)
    if tag is not None:
        return _line_of(file, re.compile("<" + re.escape(tag.group(1)) + r"[\s/>]"))
    return None


def process_xacro(
    path: Path, resolver: PackageResolver, args: Mapping[str, str] | None = None
) -> bytes:
    """Expand the xacro file ``path`` into URDF XML bytes (UTF-8).

    ``$(find PKG)`` uses ``resolver``; ``$(arg x)`` reads ``args``; ``$(env X)`` and
    ``$(optenv X)`` read the process environment, as xacro does. Every file xacro opens
    (includes, ``load_yaml``) must lie inside ``resolver``'s allowed roots and must not declare
    XML entities. ``${...}`` is evaluated by xacro's restricted evaluator (math and a few
    conversions, no other builtins), hardened as the module docstring explains. xacro's warnings
    go to a captured buffer, not the terminal (``sys.stdout``/``sys.stderr`` are process-wide, so
    other threads' prints during an expansion are swallowed too).

    Raises:
        DescriptionError: for any failure, with the file xacro was in (and a line when it can
            be found); :class:`~robotspec.errors.PackageNotFoundError` and
            :class:`~robotspec.errors.PathOutsideRootsError` pass through.
    """
    mappings = {str(k): str(v) for k, v in (args or {}).items()}
    top = Path(path)
    sink = io.StringIO()
    with _LOCK:
        budget = Budget(limits())  # the clock starts once the lock is held
        with (
            contextlib.redirect_stdout(sink),
            contextlib.redirect_stderr(sink),
            _patched(resolver, budget) as xacro,
        ):
            return _expand(xacro, top, mappings)


def _expand(xacro: Any, top: Path, mappings: dict[str, str]) -> bytes:
    """Run xacro on ``top`` with the hooks installed; every failure becomes ours."""
    try:
        doc = xacro.process_file(str(top), mappings=mappings)
        text: str = doc.toprettyxml(indent="  ")
    except RecursionError:
        raise DescriptionError(
            "xacro recursion too deep (a macro or include calls itself)", file=str(top)
        ) from None
    except Exception as exc:  # noqa: BLE001 - xacro raises anything; all become ours
        raise _convert(exc, xacro, top) from None
    finally:
        xacro.filestack = None
    return text.encode("utf-8")
