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
* ``${...}`` expressions are evaluated by xacro's own restricted evaluator: no builtins except
  a few conversions and ``math``, and names starting with ``__`` refused. xacro 2.1.1 checks
  that only for the outer expression, so ``${[x.__class__ for x in [0]]}`` reaches any Python
  object; the guard here checks nested code (comprehensions, lambdas) too, and disables
  ``python.vars``/``python.type``, which give the same reach through string keys.
* ``$(eval ...)`` in xacro 2.1.1 runs with Python's full builtins (``open``, ``exec``); here it
  gets only the conversions xacro meant to allow.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import threading
import types
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any
from xml.parsers import expat

from robotspec.errors import DescriptionError, PathOutsideRootsError, RobotSpecError
from robotspec.files.packages import PackageResolver
from robotspec.files.xmlsafe import MAX_XML_BYTES

__all__ = ["process_xacro"]

#: xacro keeps its state (file stack, substitution args, hooks) in module globals, so only one
#: expansion may run at a time; this lock is the module's only state.
_LOCK = threading.Lock()

#: ``python.*`` helpers disabled during expansion: with string keys they reach object internals.
_DISABLED_PYTHON_HELPERS = ("vars", "type")


def _current_file(xacro: Any) -> str | None:
    stack = [f for f in (getattr(xacro, "filestack", None) or []) if f]
    return str(stack[-1]) if stack else None


def _check_entities(data: bytes, file: str) -> None:
    """Refuse XML declaring entities, with :mod:`robotspec.files.xmlsafe`'s wording.

    Why here: xacro parses with minidom (expat), which expands internal entities.
    """
    doctype = data.find(b"<!DOCTYPE")
    if doctype < 0:
        return
    entity = data.find(b"<!ENTITY", doctype)
    if entity < 0:
        return
    name = data[entity + 8 : entity + 80].split()[:1]
    shown = name[0].decode("utf-8", "replace") if name else "?"
    raise DescriptionError(
        f"XML entity declarations are not allowed (found '{shown}')",
        file=file,
        line=data.count(b"\n", 0, entity) + 1,
        kind="entity",
        name=shown,
    )


def _guarded_open(resolver: PackageResolver, xacro: Any) -> Callable[..., Any]:
    """An ``open`` for xacro's module: reads only allowed files, refuses entity declarations."""

    def guarded(filename: Any, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
        if any(c in mode for c in "wax+"):
            raise DescriptionError(f"xacro tried to write '{filename}'", file=_current_file(xacro))
        path = os.path.abspath(os.fspath(filename))
        stack = [str(f) for f in (getattr(xacro, "filestack", None) or []) if f]
        # xacro pushes an include on its file stack before opening it; report the includer.
        if stack and os.path.abspath(stack[-1]) == path:
            stack.pop()
        includer = stack[-1] if stack else None
        if not resolver.is_allowed(path):
            shown = ", ".join(str(r) for r in resolver.roots) or "none"
            raise PathOutsideRootsError(
                f"xacro file '{filename}' resolves to {os.path.realpath(path)}, "
                f"outside the allowed folders ({shown})",
                file=includer,
                kind="path",
                name=str(filename),
            )
        with open(path, "rb") as handle:  # OSError stays OSError: xacro handles optional includes
            data = handle.read(MAX_XML_BYTES + 1)
        if len(data) > MAX_XML_BYTES:
            raise DescriptionError(f"file larger than {MAX_XML_BYTES} bytes", file=path)
        if data.lstrip()[:1] == b"<":
            _check_entities(data, path)
        return io.BytesIO(data)

    return guarded


def _nested_names(code: types.CodeType) -> Iterator[str]:
    yield from code.co_names
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            yield from _nested_names(const)


def _strict_safe_eval(original: Callable[..., Any]) -> Callable[..., Any]:
    """A ``safe_eval`` for xacro whose dunder check also covers nested code objects."""

    def safe_eval(expr: str, globals: Any, locals: Any = None) -> Any:
        code = compile(expr.strip(), "<expression>", "eval")
        bad = sorted({n for n in _nested_names(code) if n.startswith("__")})
        if bad:
            raise DescriptionError(
                f"xacro expression uses {', '.join(bad)}, which robotspec does not allow "
                f"(dunder names reach outside xacro's sandbox): '{expr.strip()}'"
            )
        return original(expr, globals, locals)

    return safe_eval


def _restricted_eval(builtins: Mapping[str, Any]) -> Callable[..., Any]:
    """The ``eval`` of ``$(eval ...)``, with only the builtins xacro meant to expose."""

    def restricted(source: str, _globals: Any, locals: Any = None) -> Any:
        return eval(source, {"__builtins__": dict(builtins)}, locals)

    return restricted


def _disabled(name: str) -> Callable[..., Any]:
    def refuse(*_args: Any, **_kwargs: Any) -> Any:
        raise DescriptionError(
            f"python.{name}() is disabled by robotspec: it reaches outside xacro's sandbox"
        )

    return refuse


@contextlib.contextmanager
def _patched(resolver: PackageResolver) -> Iterator[Any]:
    """Install the hooks described in the module docstring; restore them on exit."""
    import xacro
    import xacro.substitution_args as subst

    def find(pkg: str) -> str:
        return str(resolver.find_package(pkg, file=_current_file(xacro)))

    python_ns = xacro._global_symbols.get("python")
    saved_python = {
        k: dict.__getitem__(python_ns, k)
        for k in _DISABLED_PYTHON_HELPERS
        if python_ns is not None and k in python_ns
    }
    saved_find = subst._eval_find
    saved_dict_find = subst._eval_dict.get("find")
    saved_safe_eval = xacro.safe_eval
    saved_includes = list(xacro.all_includes)
    builtins = dict(subst._eval_dict.get("__builtins__", {}))
    try:
        subst._eval_find = find
        subst._eval_dict["find"] = find
        subst.eval = _restricted_eval(builtins)
        xacro.open = _guarded_open(resolver, xacro)
        xacro.safe_eval = _strict_safe_eval(saved_safe_eval)
        for k in saved_python:
            dict.__setitem__(python_ns, k, _disabled(k))
        yield xacro
    finally:
        subst._eval_find = saved_find
        if saved_dict_find is not None:
            subst._eval_dict["find"] = saved_dict_find
        with contextlib.suppress(AttributeError):
            del subst.eval
        with contextlib.suppress(AttributeError):
            del xacro.open
        xacro.safe_eval = saved_safe_eval
        for k, v in saved_python.items():
            dict.__setitem__(python_ns, k, v)
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
    try:
        text = Path(file).read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
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
            if inner.file is None:
                return inner.located(file=file, line=inner.line, column=inner.column)
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
    expr = re.search(r"when evaluating expression '(.*)'", str(exc))
    line = None
    if expr is not None:
        line = _line_of(file, re.compile(r"\$\{" + re.escape(expr.group(1)) + r"\}"))
    return DescriptionError(f"xacro failed: {message}", file=file, line=line, kind="xacro")


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
    with (
        _LOCK,
        contextlib.redirect_stdout(sink),
        contextlib.redirect_stderr(sink),
        _patched(resolver) as xacro,
    ):
        try:
            doc = xacro.process_file(str(top), mappings=mappings)
            text = doc.toprettyxml(indent="  ")
        except RecursionError:
            raise DescriptionError(
                "xacro recursion too deep (a macro or include calls itself)", file=str(top)
            ) from None
        except Exception as exc:  # noqa: BLE001 - xacro raises anything; all become ours
            raise _convert(exc, xacro, top) from None
        finally:
            xacro.filestack = None
    data: bytes = text.encode("utf-8")
    return data
