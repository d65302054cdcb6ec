"""Generate the reference pages of ``docs/``, each from the one place its facts live.

Why generated: a reference written by hand drifts from the code the day a field or an option is
added. ``spec-reference.md`` comes from the Pydantic models of :mod:`robotspec.spec.models` (type,
default, and the description, example and unit each field carries into the JSON Schema too) and
from the rule files of ``tests/bad_specs/rules/``; ``cli.md`` from the typer app;
``performance.md`` from the docstrings of ``benchmarks/bench_*.py`` (the figures stay in the
README's table, which the page links to). ``tests/test_docs.py`` fails when a page is stale.

A developer tool that reads the repository, so it is not in the package: ``python
tools/docgen.py`` rewrites the pages, ``--check`` only compares them.
"""

from __future__ import annotations

import argparse
import ast
import inspect
import sys
import types
import typing
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel
from pydantic.fields import FieldInfo

ROOT = Path(__file__).resolve().parents[1]
#: One file per compiler rule shown in the spec reference, in page order.
RULES_DIR = ROOT / "tests" / "bad_specs" / "rules"
COMMAND = "python tools/docgen.py"


class DocgenError(Exception):
    """The code and the documentation data disagree (an undocumented field, a malformed rule)."""


# --------------------------------------------------------------------------- type rendering


def _constraints(metadata: Sequence[Any]) -> str:
    """`` > 0`` / `` >= 0`` from pydantic/annotated-types metadata."""
    out = []
    for m in metadata:
        for attr, sign in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            value = getattr(m, attr, None)
            if isinstance(value, int | float) and not isinstance(value, bool):
                out.append(f"{sign} {value:g}")
        if isinstance(m, FieldInfo):
            out.extend(c for c in [_constraints(m.metadata)] if c)
    return ", ".join(out)


def _is_model(tp: Any) -> bool:
    return isinstance(tp, type) and issubclass(tp, BaseModel)


def _type_text(tp: Any) -> str:
    """A spec field's type in YAML words (``map: name → number``), models as page links."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin is typing.Annotated:
        inner = "name" if args[0] is str else _type_text(args[0])
        cons = _constraints(args[1:])
        return f"{inner} {cons}" if cons else inner
    if origin is typing.Literal:
        values = [str(a) for a in args]
        return values[0] if len(values) == 1 else "one of " + ", ".join(values)
    if origin in (typing.Union, types.UnionType):
        parts = [a for a in args if a is not type(None)]
        text = " or ".join(_type_text(a) for a in parts)
        return f"{text} or null" if len(parts) < len(args) else text
    if origin is tuple:
        if len(args) == 2 and args[1] is Ellipsis:
            return f"list of {_plural(_type_text(args[0]))}"
        if all(a is float for a in args):
            return f"[{len(args)} numbers]"
        return "[" + ", ".join(_type_text(a) for a in args) + "]"
    if origin is list:
        return f"list of {_plural(_type_text(args[0]))}"
    if origin is dict:
        return f"map: {_type_text(args[0])} → {_type_text(args[1])}"
    if _is_model(tp):
        return f"[{tp.__name__}](#{_anchor(tp)})"
    return {str: "string", float: "number", int: "integer", bool: "true or false"}.get(
        tp, getattr(tp, "__name__", str(tp))
    )


def _plural(word: str) -> str:
    if word.startswith("["):
        return word
    return word if word.endswith("s") else word + "s"


def _anchor(model: type[BaseModel]) -> str:
    return model.__name__.lower()


def _default_text(field: FieldInfo) -> str:
    if field.is_required():
        return "required"
    if field.default_factory is not None:
        factory = typing.cast(Callable[[], Any], field.default_factory)
        return f"`{_flow(factory())}`"
    return f"`{_flow(field.default)}`"


def _models_in(tp: Any) -> Iterator[type[BaseModel]]:
    if _is_model(tp):
        yield tp
    for a in typing.get_args(tp):
        yield from _models_in(a)


def _where_suffix(tp: Any) -> str:
    """How a field's value nests: ``.<name>`` under a map, ``[i]`` under a list."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin is typing.Annotated or origin in (typing.Union, types.UnionType):
        for a in args:
            s = _where_suffix(a)
            if s:
                return s
        return ""
    if origin is dict:
        return ".<name>" + _where_suffix(args[1])
    if origin in (list, tuple):
        return "[i]" + _where_suffix(args[0])
    return ""


def _spec_models() -> list[tuple[type[BaseModel], list[str]]]:
    """Every model of the spec format and where it appears, nested ones after their parent."""
    from robotspec.spec.models import RobotSpec

    paths: dict[type[BaseModel], list[str]] = {RobotSpec: ["(the file)"]}
    order: list[type[BaseModel]] = []

    def visit(model: type[BaseModel], where: str) -> None:
        order.append(model)
        for name, field in model.model_fields.items():
            path = name if where == "(the file)" else f"{where}.{name}"
            path += _where_suffix(field.annotation)
            for sub in _models_in(field.annotation):
                if sub in paths:
                    if path not in paths[sub]:
                        paths[sub].append(path)
                    continue
                paths[sub] = [path]
                visit(sub, path)

    visit(RobotSpec, "(the file)")
    return [(m, paths[m]) for m in order]


def _plain(text: str) -> bool:
    """Whether a string reads back as itself as a plain (unquoted) YAML flow scalar."""
    try:
        same = bool(text) and yaml.safe_load(text) == text
    except yaml.YAMLError:
        return False
    return same and not set(text) & set(",[]{}#'\"") and ": " not in text


def _flow(value: Any) -> str:
    """A default or an example as one line of flow-style YAML, as a spec writes it."""
    if isinstance(value, BaseModel):
        value = value.model_dump(exclude_defaults=True)
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_flow(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_flow(v) for v in value) + "]"
    if isinstance(value, str):
        return value if _plain(value) else "'" + value.replace("'", "''") + "'"
    if isinstance(value, bool) or value is None:
        return {True: "true", False: "false", None: "null"}[value]
    return str(value)


def _unit(field: FieldInfo) -> str:
    extra = field.json_schema_extra
    return str(extra.get("unit", "")) if isinstance(extra, dict) else ""


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _model_section(model: type[BaseModel], where: list[str]) -> list[str]:
    at = ", ".join(f"`{w}`" for w in where)
    lines = [
        f"### {model.__name__}",
        "",
        f"Where: {at}. " + inspect.cleandoc(model.__doc__ or "").replace("``", "`"),
        "",
    ]
    lines += [
        "| key | type | unit | default | description | example |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for name, field in model.model_fields.items():
        key = field.alias or name
        if not field.description or not field.examples:
            raise DocgenError(
                f"spec field {model.__name__}.{name} has no description or no example: give them "
                "in its Field(...) in robotspec/spec/models.py"
            )
        annotation: Any = field.annotation
        type_text = _type_text(annotation)
        if annotation is str and any(getattr(m, "min_length", None) for m in field.metadata):
            type_text = "name"
        cons = _constraints(field.metadata)
        if cons:
            head, nullable, _ = type_text.partition(" or null")
            type_text = f"{head} {cons}" + (", or null" if nullable else "")
        example = _cell(f"{key}: {_flow(field.examples[0])}")
        row = [f"`{key}`", _cell(type_text), _unit(field), _cell(_default_text(field))]
        lines.append("| " + " | ".join([*row, _cell(field.description), f"`{example}`"]) + " |")
    return [*lines, ""]


# --------------------------------------------------------------------------- compiler rules


@dataclass(frozen=True)
class Rule:
    """A rule the compiler checks, read from its file in ``tests/bad_specs/rules/``.

    The file is ``# group:``, ``# rule:`` and ``# expect:`` comment lines, then the three lines of
    ``broken.yaml``, the shipped PR2 changed by line 3 (``change``). ``tests/test_compiler.py``
    compiles it as ``broken.yaml`` and compares the output with the ``# expect:`` lines
    (``output``), so the page shows what the compiler prints today without running it here.
    """

    group: str
    rule: str
    change: str
    output: tuple[str, ...]


def read_rules(folder: Path = RULES_DIR) -> list[Rule]:
    """The rule files of ``folder``, in file-name order (the order of the page)."""
    rules = []
    for path in sorted(folder.glob("*.yaml")):
        tags: dict[str, list[str]] = {"group": [], "rule": [], "expect": []}
        body = []
        for line in path.read_text(encoding="utf-8").splitlines():
            tag, sep, text = line.removeprefix("# ").partition(": ")
            if line.startswith("# ") and sep and tag in tags:
                tags[tag].append(text)
            elif not line.startswith("#"):
                body.append(line)
        group, rule, expect = tags["group"], tags["rule"], tags["expect"]
        if len(group) != 1 or len(rule) != 1 or not expect or body[:1] != ["robotspec: 1"]:
            raise DocgenError(f"{path}: needs one '# group:', one '# rule:', '# expect:' lines")
        if len(body) != 3:
            raise DocgenError(f"{path}: needs three lines of spec, the third one the change")
        rules.append(Rule(group[0], rule[0], body[2], tuple(expect)))
    if not rules:
        raise DocgenError(f"no rule files in {folder}")
    return rules


_SPEC_INTRO = """\
A spec is one YAML file whose top level is [RobotSpec](#robotspec). Every mapping refuses
unknown keys; names (links, joints, SRDF groups) are checked against the robot's URDF and SRDF
when the spec is compiled (`robotspec validate`). Units: lengths in metres, angles in radians,
velocities in rad/s (revolute joints) or m/s (prismatic joints); quaternions are `[x, y, z, w]`.
A joint state maps joint names to positions, each in its joint's unit.

For completion and checks in an editor, write the JSON Schema (`robotspec schema -o
robotspec.schema.json`) and point the YAML language server at it with a first line
`# yaml-language-server: $schema=robotspec.schema.json`; `robotspec init` writes that line.
The schema carries what the tables below show: each field's description, example and `unit`.

`extends: NAME` starts from another spec (a file next to this one, or a shipped robot such as
`pr2`): mappings are merged key by key, lists and values are replaced, and the extending file's
lines are the ones errors point at. A base may extend another, up to 100 files deep
(`ROBOTSPEC_MAX_EXTENDS_DEPTH`); a chain deeper than that, or one that comes back to a file, is
an error at the `extends` line that goes on.

Within one file, YAML anchors, aliases and merge keys work as YAML 1.1 defines them: `<<: *arm`
gives a mapping the keys of `arm` it does not write itself, so `{<<: *arm, tip: flange}`
overrides one key wherever it stands, and in `<<: [*a, *b]` the earlier mapping wins. A key
written twice, an alias inside the collection it names and a merge of anything but mappings are
errors at their line; an error inside an alias or a merged key points where the value is written.
"""

_RULES_INTRO = """\
`robotspec validate` reports every problem of a spec at once, one per line, in file order:

```text
FILE:LINE:COL: SEVERITY: LOCATION: MESSAGE
```

`LOCATION` is the dotted path of the YAML node (`chains.left_arm.tip`); messages about a name that
does not exist end with `did you mean ...?` and the closest names in the robot's files. Errors
exit with code 1; warnings do not, unless `--strict` is given. A spec is checked in two stages:
first its shape (keys, types, bounds, as Pydantic validates it), then, once the shape is right,
every name and every rule below. Problems in the SRDF itself (names the URDF lacks) are warnings
pointing into the SRDF, as MoveIt treats them.

Severity policy: an **error** when the spec is provably wrong (a name that does not exist, a chain
that cannot move, a camera height FK proves wrong, two default cameras), a **warning** when it
is only suspicious (a frame named like a laser, a field of view taller than wide, a part nobody
carries). The kinematic checks evaluate forward kinematics: heights are the z coordinate of a
frame's origin in the robot's root frame, over the limits of every joint that moves it
(continuous joints over one turn, other joints at their default), and agree within 1 cm. They
are exact when every moving joint above the frame is a vertical lift or a pan, except a last
joint (a tilt): the height is then a sum of terms, each bounded in closed form. Otherwise they
are sampled (about 2,000 seeded configurations and the limit box's corners, the best refined
joint by joint): a height the samples reach is proof (the message names the joint values), a
spec height beyond them only a warning. The message says which method ran.

Each example below is a complete file `broken.yaml` that changes the shipped PR2 by one line
(line 3), and the exact output of `robotspec validate broken.yaml` for it:

<!-- fragment: a template, line 3 varies -->
```yaml
robotspec: 1
extends: pr2
chains: {left_arm: {tipp: x}}
```
"""


def spec_reference() -> str:
    """The text of ``docs/spec-reference.md``."""
    from robotspec.spec.models import SPEC_VERSION

    lines = [
        "# Spec reference",
        "",
        f"<!-- Generated by `{COMMAND}` from robotspec/spec/models.py and tests/bad_specs/rules/ "
        "(whose outputs tests/test_compiler.py checks against the compiler); do not edit. -->",
        "",
        f"Spec format version {SPEC_VERSION}. " + _SPEC_INTRO,
    ]
    models = _spec_models()
    lines += ["## Fields", ""]
    lines += [
        f"- [{m.__name__}](#{_anchor(m)}): " + ", ".join(f"`{p}`" for p in w) for m, w in models
    ]
    lines.append("")
    for model, where in models:
        lines += _model_section(model, where)
    lines += ["## Rules the compiler checks", "", _RULES_INTRO]
    groups: list[str] = []
    for rule in read_rules():
        if not groups or rule.group != groups[-1]:
            if rule.group in groups:
                raise DocgenError(f"the rules of group '{rule.group}' are not numbered together")
            groups.append(rule.group)
            lines += ["", f"### {rule.group}", "", "| rule | line 3 | output |", "| --- " * 3 + "|"]
        shown = "<br>".join(f"`{_cell(m)}`" for m in rule.output)
        lines.append(f"| {_cell(rule.rule)} | `{_cell(rule.change)}` | {shown} |")
    lines.append("")
    return "\n".join(lines)


# --------------------------------------------------------------------------- CLI reference


def _param_row(param: Any, ctx: Any) -> str | None:
    """One table row for a parameter, from the help record ``--help`` prints (none for --help)."""
    if "--help" in param.opts or getattr(param, "hidden", False):
        return None
    record = param.get_help_record(ctx)
    if record is None:
        return None
    names, help_text = record
    return f"| `{_cell(names)}` | {_cell(' '.join(help_text.split()))} |"


def _command_sections(cmd: Any, path: list[str], parent_ctx: Any, out: list[str]) -> None:
    from typer._click import Context

    ctx = Context(cmd, info_name=path[-1], parent=parent_ctx, max_content_width=200)
    name = " ".join(path)
    level = "##" if len(path) <= 2 else "###"
    out += [f"{level} `{name}`", ""]
    help_text = inspect.cleandoc(cmd.help or "").replace("``", "`")
    if help_text:
        out += [help_text, ""]
    pieces = " ".join(cmd.collect_usage_pieces(ctx))
    out += ["```text", f"{name} {pieces}".rstrip(), "```", ""]
    rows = [r for r in (_param_row(p, ctx) for p in cmd.get_params(ctx)) if r is not None]
    if rows:
        out += ["| argument / option | help |", "| --- | --- |"]
        out += [*rows, ""]
    sub = getattr(cmd, "commands", None)
    if sub:
        if len(path) > 1:
            out += ["Commands: " + ", ".join(f"`{name} {n}`" for n in sub), ""]
        for sub_name in sub:
            _command_sections(sub[sub_name], [*path, sub_name], ctx, out)


def cli_reference() -> str:
    """The text of ``docs/cli.md``, walked from the typer app's click commands."""
    import typer.main

    from robotspec.cli.app import app

    group = typer.main.get_command(app)
    out = [
        "# CLI reference",
        "",
        f"<!-- Generated by `{COMMAND}` from the typer app (robotspec/cli); do not edit. -->",
        "",
        "Exit codes: 0 success, 1 an invalid input (every problem printed as "
        "`file:line:col: error: message` on standard error, or on standard output by "
        "`validate`), 2 a usage error, 3 an internal error (a bug: rerun with `--verbose`). "
        "Colours only on a terminal; `NO_COLOR` turns them off.",
        "",
    ]
    _command_sections(group, ["robotspec"], None, out)
    return "\n".join(out).rstrip("\n") + "\n"


# --------------------------------------------------------------------------- performance


def _benchmark_notes(folder: Path) -> list[str]:
    """One entry per ``benchmarks/bench_*.py``: its summary, what it compares and its command."""
    out: list[str] = []
    for path in sorted(folder.glob("bench_*.py")):
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
        raw = [p.strip() for p in doc.split("\n\n") if p.strip()]
        summary = " ".join(raw[0].split()) if raw else path.stem
        run = next((" ".join(p.split()) for p in raw if p.startswith("Run:")), "")
        command = run.partition("``")[2].partition("``")[0] or f"python benchmarks/{path.name}"
        after = run.partition("``")[2].partition("``")[2].lstrip(" .")
        out += [f"### `benchmarks/{path.name}`", "", summary.replace("``", "`"), ""]
        out += ["```sh", command, "```", ""]
        if after:
            out += [after[0].upper() + after[1:].replace("``", "`"), ""]
        for p in raw[1:]:
            if not p.startswith("Run:"):
                out += [p.replace("``", "`"), ""]
    return out


def performance_page() -> str:
    """The text of ``docs/performance.md``: each benchmark's command, and where its figures are."""
    lines = [
        "# Performance",
        "",
        f"<!-- Generated by `{COMMAND}` from the docstrings of benchmarks/*.py; do not edit. -->",
        "",
        "The figures are in one place, the [README's benchmark table](../README.md#benchmarks): "
        "each row gives robotspec's time, the peer's time measured in the same run, their ratio, "
        "and the command below that measured them. This page says what each command compares; it "
        "is generated from the benchmarks' own docstrings and copies no figure.",
        "",
        "## The benchmarks",
        "",
        "Each runs from the repository root with the dev extra installed "
        "(`pip install -e '.[dev]'`; each names its peer and any extra it needs below); "
        "peers run in the same process, one after the other, so ratios compare like with like.",
        "",
    ]
    lines += _benchmark_notes(ROOT / "benchmarks")
    return "\n".join(lines).rstrip("\n") + "\n"


# --------------------------------------------------------------------------- pages


#: Generated pages: file name in ``docs/`` -> generator.
GENERATED_PAGES: dict[str, Callable[[], str]] = {
    "spec-reference.md": spec_reference,
    "cli.md": cli_reference,
    "performance.md": performance_page,
}


def generate_pages() -> dict[str, str]:
    """Every generated page's text, by file name."""
    return {name: make() for name, make in GENERATED_PAGES.items()}


def stale_pages(docs: Path, pages: dict[str, str] | None = None) -> list[str]:
    """Names of generated pages whose file in ``docs`` is missing or differs."""
    pages = generate_pages() if pages is None else pages
    current = {p.name: p.read_text(encoding="utf-8") for p in docs.glob("*.md")}
    return [name for name, text in pages.items() if current.get(name) != text]


def main(argv: Sequence[str] | None = None) -> int:
    """``python tools/docgen.py [--check] [--docs DIR]``: rewrite (or check) the pages."""
    parser = argparse.ArgumentParser(
        prog=COMMAND, description="Rewrite the generated pages: " + ", ".join(GENERATED_PAGES)
    )
    parser.add_argument("--check", action="store_true", help="only report stale pages (exit 1)")
    parser.add_argument("--docs", type=Path, default=ROOT / "docs", help="the docs folder")
    args = parser.parse_args(argv)
    docs: Path = args.docs
    pages = generate_pages()
    stale = stale_pages(docs, pages)
    if args.check:
        for name in stale:
            sys.stderr.write(f"{docs / name}: stale; run `{COMMAND}`\n")
        return 1 if stale else 0
    docs.mkdir(parents=True, exist_ok=True)
    for name in stale:
        (docs / name).write_text(pages[name], encoding="utf-8")
        sys.stderr.write(f"wrote {docs / name}\n")
    if not stale:
        sys.stderr.write("generated pages are up to date\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
