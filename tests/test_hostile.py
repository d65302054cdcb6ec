"""Hostile robot files: each case runs the CLI in a subprocess under memory and CPU limits.

Every case asserts the exact located message and exit code 1 (never 3, never a signal), and that
no file outside the allowed roots was opened: a canary file sits beside the robot's folder and
its path must not appear among the files the process opened (an audit hook logs them, see
``hostile_runner.py``), nor its content in the output.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

RUNNER = Path(__file__).with_name("hostile_runner.py")
MEMORY = 3 * 1024**3  # address space: numpy and coal map far more than they use
CPU_SECONDS = 60
CANARY = "CANARY-SECRET-7f3a"
XACRO_HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
BOX_LINK = '<link name="base"><visual><geometry><box size="1 1 1"/></geometry></visual></link>\n'


@dataclass(frozen=True)
class Result:
    code: int
    out: str
    err: str
    opened: list[str]

    @property
    def text(self) -> str:
        """Everything printed (``validate`` reports problems on stdout, others on stderr)."""
        return self.out + self.err


def run_cli(
    tmp: Path, *args: str, cwd: Path | None = None, env: dict[str, str] | None = None
) -> Result:
    log = tmp / "opened.log"
    environ = {
        k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH")
    }
    environ.update({"NO_COLOR": "1", "OPENBLAS_NUM_THREADS": "1", "COLUMNS": "200"})
    environ.update(env or {})
    proc = subprocess.run(
        [sys.executable, str(RUNNER), str(MEMORY), str(CPU_SECONDS), str(log), "--", *args],
        cwd=cwd or tmp / "work",
        env=environ,
        capture_output=True,
        text=True,
        timeout=CPU_SECONDS * 3,
    )
    opened = log.read_text().splitlines() if log.exists() else []
    return Result(proc.returncode, proc.stdout, proc.stderr, opened)


@pytest.fixture
def tmp(tmp_path: Path) -> Path:
    """``tmp/work`` is where the user runs robotspec; ``tmp/outside`` holds the canary."""
    (tmp_path / "work").mkdir()
    (tmp_path / "outside").mkdir()
    (tmp_path / "outside" / "secret.yaml").write_text(f"token: {CANARY}\n")
    (tmp_path / "work" / "secret.yaml").write_text(f"token: {CANARY}\n")  # beside a package
    return tmp_path


def fenced(r: Result, tmp: Path) -> None:
    """Nothing outside the allowed roots was opened or echoed."""
    assert r.code in (0, 1, 2), r.err
    assert CANARY not in r.out + r.err
    assert not [p for p in r.opened if "secret.yaml" in p], r.opened


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def spec(folder: Path, urdf: str, extra: str = "", name: str = "spec.yaml") -> Path:
    return write(
        folder / name,
        f"robotspec: 1\nname: R\nroot: base\ndescription:\n  urdf: {urdf}\n{extra}",
    )


def xacro(folder: Path, body: str, name: str = "r.urdf.xacro") -> Path:
    return write(folder / name, XACRO_HEAD + BOX_LINK + body + "\n</robot>\n")


# --------------------------------------------------------------------------- fences
def test_spec_package_paths_cannot_widen_the_roots(tmp: Path) -> None:
    a = tmp / "work" / "a"
    xacro(a, f"<link name=\"${{xacro.load_yaml('{tmp}/outside/secret.yaml')['token']}}\"/>")
    spec(a, "r.urdf.xacro", "  package_paths: [/]\n")
    r = run_cli(tmp, "export", "urdf", "a/spec.yaml")
    fenced(r, tmp)
    assert r.code == 1
    assert r.err == (
        "a/spec.yaml:6:19: error: package path '/' resolves to /, which a spec may not name: "
        f"it lies outside the spec's project {a} (a spec may name files and folders inside its "
        "own project, never hidden or system ones; allow it with -P/--package-path /, "
        "or ROS_PACKAGE_PATH)\n"
    )


def test_xacro_cannot_read_outside_even_when_the_spec_is_silent(tmp: Path) -> None:
    a = tmp / "work" / "a"
    xacro(a, f"<link name=\"${{xacro.load_yaml('{tmp}/outside/secret.yaml')['token']}}\"/>")
    spec(a, "r.urdf.xacro")
    r = run_cli(tmp, "export", "urdf", "a/spec.yaml")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.startswith(
        f"{a}/r.urdf.xacro:4: error: xacro file '{tmp}/outside/secret.yaml' resolves to "
        f"{tmp}/outside/secret.yaml, outside the allowed folders ({a}"
    )


def test_a_package_xml_does_not_open_its_parent(tmp: Path) -> None:
    evil = tmp / "work" / "evil"
    write(evil / "package.xml", '<package format="2"><name>evil</name></package>\n')
    xacro(evil / "urdf", "<link name=\"${xacro.load_yaml('../../secret.yaml')['token']}\"/>")
    r = run_cli(tmp, "init", "evil/urdf/r.urdf.xacro")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.startswith(
        f"{evil}/urdf/r.urdf.xacro:4: error: xacro file '../../secret.yaml' resolves to "
        f"{tmp}/work/secret.yaml, outside the allowed folders ({evil}/urdf, {evil}, "
    )


def test_minus_p_allows_a_spec_package_path_and_resolves_against_the_cwd(tmp: Path) -> None:
    pkgs = tmp / "pkgs"
    write(pkgs / "meshes_pkg" / "package.xml", "<package><name>meshes_pkg</name></package>\n")
    a = tmp / "work" / "a"
    write(
        a / "r.urdf",
        '<robot name="r"><link name="base"><visual><geometry>'
        '<mesh filename="package://meshes_pkg/missing.stl"/></geometry></visual></link></robot>\n',
    )
    spec(a, "r.urdf", f"  package_paths: [{pkgs}]\n")
    refused = run_cli(tmp, "validate", "a/spec.yaml")
    assert refused.code == 1 and "outside the spec's project" in refused.text
    allowed = run_cli(tmp, "validate", "a/spec.yaml", "-P", "../pkgs")
    fenced(allowed, tmp)
    assert "lies outside" not in allowed.text
    assert "meshes_pkg/missing.stl" in allowed.text  # found the package; its mesh is missing


def test_a_missing_minus_p_folder_is_a_usage_error_naming_it(tmp: Path) -> None:
    a = tmp / "work" / "a"
    write(a / "r.urdf", '<robot name="r"><link name="base"/></robot>\n')
    spec(a, "r.urdf")
    r = run_cli(tmp, "validate", "a/spec.yaml", "-P", "nowhere")
    assert r.code == 2
    flat = " ".join(re.sub("[│╭╮╰╯─]", " ", r.text).split())  # rich draws a wrapped box
    assert f"folder does not exist: {tmp}/work/nowhere (searched: {tmp}/work/nowhere)" in flat


# --------------------------------------------------------------------------- xacro sandbox
def test_xacro_namespace_does_not_leak_between_documents(tmp: Path) -> None:
    work = tmp / "work"
    xacro(work / "evil", '<link name="l${math.update(pi=0.5) or 1}"/>')
    spec(work / "evil", "r.urdf.xacro")
    xacro(
        work / "victim",
        '<link name="l${int(math.pi * 1000)}"/>\n'
        '<joint name="j" type="fixed"><parent link="base"/><child link="l3141"/></joint>',
    )
    spec(work / "victim", "r.urdf.xacro")
    r = run_cli(tmp, "validate", "evil/spec.yaml", "victim/spec.yaml")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == (
        f"{work}/evil/r.urdf.xacro:4: error: xacro failed: name 'update' is not defined; "
        "when evaluating expression 'math.update(pi=0.5) or 1'"
    )
    assert "1 of 2 specs valid" in r.text  # the victim still sees math.pi


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (
            "<link name=\"${(str(dict())[0] + '0.__globals__' + str(dict())[1])"
            '.format(xacro.load_yaml)}"/>',
            "attribute 'format' of a str is not allowed in xacro expressions by robotspec "
            "(it could reach outside the sandbox)",
        ),
        (
            "<link name=\"${len('a'*3000000000)}\"/>",
            "xacro value too large (3000000000 items) (the limit is 1,000,000; "
            "set ROBOTSPEC_XACRO_VALUE_SIZE to raise it)",
        ),
        (
            '<link name="${9**9**9 % 7}"/>',
            "xacro integer too large (about 1162261467 bits) (the limit is 1,024; "
            "set ROBOTSPEC_XACRO_INT_BITS to raise it)",
        ),
        (
            '<link name="${len([x for x in range(10**5) for y in range(10**5)])}"/>',
            "xacro expressions loop or build too much (the limit is 1,000,000; "
            "set ROBOTSPEC_XACRO_LOOP_STEPS to raise it)",
        ),
        (
            '<link name="${math.factorial(10**7)}"/>',
            "xacro math.factorial() argument too large (at most 2000)",
        ),
    ],
)
def test_xacro_expression_bombs_are_located_errors(tmp: Path, body: str, message: str) -> None:
    a = tmp / "work" / "a"
    xacro(a, body)
    spec(a, "r.urdf.xacro")
    r = run_cli(tmp, "validate", "a/spec.yaml")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == f"{a}/r.urdf.xacro:4: error: {message}"


def test_xacro_macro_fan_out_is_bounded(tmp: Path) -> None:
    a = tmp / "work" / "a"
    macros = '<xacro:macro name="m0"><link name="x"/></xacro:macro>\n' + "".join(
        f'<xacro:macro name="m{i + 1}">' + f"<xacro:m{i}/>" * 8 + "</xacro:macro>\n"
        for i in range(6)
    )
    xacro(a, macros + "<xacro:m6/>")
    spec(a, "r.urdf.xacro")
    r = run_cli(tmp, "validate", "a/spec.yaml", env={"ROBOTSPEC_XACRO_MACRO_CALLS": "2000"})
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == (
        f"{a}/r.urdf.xacro:5: error: xacro expanded too many macro calls (in <xacro:m0>) "
        "(the limit is 2,000; set ROBOTSPEC_XACRO_MACRO_CALLS to raise it)"
    )


def test_xacro_include_of_a_fifo_is_refused(tmp: Path) -> None:
    a = tmp / "work" / "a"
    os.makedirs(a)
    os.mkfifo(a / "pipe.xacro")
    xacro(a, '<xacro:include filename="pipe.xacro"/>')
    spec(a, "r.urdf.xacro")
    r = run_cli(tmp, "validate", "a/spec.yaml")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == (
        f"{a}/r.urdf.xacro:4: error: xacro include '{a}/pipe.xacro' is not a regular file "
        "(a device, FIFO or socket), not a xacro file"
    )


@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16"])
def test_an_included_xacro_cannot_hide_entities_behind_a_bom(tmp: Path, encoding: str) -> None:
    a = tmp / "work" / "a"
    a.mkdir()
    (a / "inc.xacro").write_bytes(
        '<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY lol "lol">]>\n'
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="&lol;"/></robot>\n'.encode(
            encoding
        )
    )
    xacro(a, '<xacro:include filename="inc.xacro"/>')
    spec(a, "r.urdf.xacro")
    r = run_cli(tmp, "validate", "a/spec.yaml")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == (
        f"{a}/inc.xacro:2: error: XML entity declarations are not allowed (found 'lol')"
    )


# --------------------------------------------------------------------------- bounded reading
def test_yaml_alias_bomb_is_refused_before_it_expands(tmp: Path) -> None:
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 10)]
    write(tmp / "work" / "bomb.yaml", "\n".join(lines) + "\n")
    r = run_cli(tmp, "validate", "bomb.yaml")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == (
        "bomb.yaml:6:10: error: YAML aliases stand for too many nodes (more than 100000 in "
        "all; set ROBOTSPEC_MAX_YAML_ALIAS_NODES to raise it)"
    )


def test_deep_yaml_does_not_crash_the_parser(tmp: Path) -> None:
    write(tmp / "work" / "deep.yaml", "[" * 50_000)
    r = run_cli(tmp, "validate", "deep.yaml")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == (
        "deep.yaml:1:101: error: YAML nested too deeply (more than 100 levels; "
        "set ROBOTSPEC_MAX_YAML_DEPTH to raise it)"
    )


def test_srdf_on_a_device_is_refused(tmp: Path) -> None:
    a = tmp / "work" / "a"
    write(a / "r.urdf", '<robot name="r"><link name="base"/></robot>\n')
    spec(a, "r.urdf", "  srdf: /dev/zero\n")
    r = run_cli(tmp, "validate", "a/spec.yaml")
    fenced(r, tmp)
    assert r.code == 1
    # A spec may not name a device at all; the user may allow /dev, and then the file is
    # still refused as no regular file. Both errors point at the spec's line.
    assert r.text.splitlines()[0].startswith(
        "a/spec.yaml:6:9: error: SRDF '/dev/zero' resolves to /dev/zero, which a spec may not "
        "name: it lies in the system folder /dev"
    )
    r = run_cli(tmp, "validate", "a/spec.yaml", "-P", "/dev")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == (
        "a/spec.yaml:6:9: error: /dev/zero: is not a regular file (a device, FIFO or socket), "
        "not an SRDF file"
    )


def test_a_file_over_its_cap_is_refused_with_the_variable_that_raises_it(tmp: Path) -> None:
    a = tmp / "work" / "a"
    write(a / "r.urdf", '<robot name="r"><link name="base"/></robot>\n' + " " * 5000)
    spec(a, "r.urdf")
    r = run_cli(tmp, "validate", "a/spec.yaml", env={"ROBOTSPEC_MAX_URDF_BYTES": "1000"})
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == (
        f"{a}/r.urdf: error: file larger than 1000 bytes (the cap for this kind of file; "
        "set ROBOTSPEC_MAX_URDF_BYTES to raise it)"
    )


# --------------------------------------------------------------------------- numbers and names
@pytest.mark.parametrize(
    ("line", "message"),
    [
        (
            "states: {home: {j: .nan}}",
            "spec.yaml:4:20: error: states.home.j: Input should be a finite number (got nan)",
        ),
        (
            "states: {home: {j: " + "9" * 5000 + "}}",
            "spec.yaml:4:20: error: integer '9999999999999999999999999999999999999999... "
            "(5000 characters)' is too large (more than 64 bits)",
        ),
        (
            "states: {home: {j: 2024-13-45}}",
            "spec.yaml:4:20: error: invalid timestamp '2024-13-45': month must be in 1..12",
        ),
        (
            'chains: {"arm\\e[2J": {root: base, tip: base}}',
            "spec.yaml:4:22: error: chains.arm\\x1b[2J: names must not contain control "
            "characters (found U+001B) (got 'arm\\x1b[2J')",
        ),
    ],
)
def test_numbers_and_names_are_checked_where_they_enter(tmp: Path, line: str, message: str) -> None:
    work = tmp / "work"
    write(work / "r.urdf", '<robot name="r"><link name="base"/></robot>\n')
    write(
        work / "spec.yaml",
        f"robotspec: 1\nname: R\nroot: base\n{line}\ndescription: {{urdf: r.urdf}}\n",
    )
    r = run_cli(tmp, "validate", "spec.yaml")
    fenced(r, tmp)
    assert r.code == 1
    assert r.text.splitlines()[0] == message


def test_terminal_escapes_in_names_are_echoed_escaped(tmp: Path) -> None:
    work = tmp / "work"
    write(work / "r.urdf", '<robot name="r"><link name="base"/></robot>\n')
    spec(work, "r.urdf", 'chains: {arm: {root: base, tip: "x\\e]0;pwned\\a"}}\n')
    r = run_cli(tmp, "validate", "spec.yaml")
    assert r.code == 1
    assert "\x1b" not in r.text and "\x07" not in r.text
    assert "x\\x1b]0;pwned\\x07" in r.text


# --------------------------------------------------------------------------- deep but valid
def test_deep_srdf_groups_and_a_long_chain_are_no_internal_errors(tmp: Path) -> None:
    work = tmp / "work"
    n = 2000
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i in range(n)
    )
    write(work / "r.urdf", f'<robot name="r">{links}{joints}</robot>\n')
    groups = '<group name="g0"><joint name="j0"/></group>' + "".join(
        f'<group name="g{i}"><group name="g{i - 1}"/></group>' for i in range(1, 1500)
    )
    write(work / "r.srdf", f'<robot name="r">{groups}</robot>\n')
    write(
        work / "spec.yaml",
        "robotspec: 1\nname: R\nroot: l0\ndescription: {urdf: r.urdf, srdf: r.srdf}\n"
        f"chains: {{arm: {{root: l0, tip: l{n}}}}}\n",
    )
    r = run_cli(tmp, "validate", "spec.yaml")
    assert r.code == 0, r.text
    r = run_cli(tmp, "inspect", "tree", "spec.yaml")
    assert r.code == 0, r.err
    assert len(r.out.splitlines()) == n + 2


# --------------------------------------------------------------------------- property tests
FRAGMENTS = st.sampled_from(
    [
        "[",
        "]",
        "{",
        "}",
        "&a ",
        "*a",
        "!!python/object ",
        "- ",
        ": ",
        "\n",
        "  ",
        ",",
        "x",
        "9" * 50,
        ".nan",
        "2024-13-45",
        "<<: *a",
        "'",
        '"',
        "\\e",
        "\t",
        "? ",
    ]
)


@settings(
    max_examples=6, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(st.lists(FRAGMENTS, min_size=1, max_size=60))
def test_any_yaml_text_is_a_located_error_or_valid(tmp: Path, parts: list[str]) -> None:
    write(tmp / "work" / "any.yaml", "".join(parts) * 3)
    r = run_cli(tmp, "validate", "any.yaml")
    fenced(r, tmp)
    assert r.code in (0, 1), r.err
    assert "internal error" not in r.text
    assert all(line.startswith(("any.yaml", "0 of 1", "1 of 1")) for line in r.text.splitlines())


EXPRESSIONS = st.sampled_from(
    [
        "9**9**9",
        "'a'*10**9",
        "[0]*10**9",
        "math.pi",
        "python.type(0)",
        "xacro.load_yaml",
        "'{0}'.format(1)",
        "(1).__class__",
        "[x for x in range(10**7)]",
        "1<<10**9",
        "'%0999999d' % 1",
        "str(10**400)",
        "1/0",
        "math.update(pi=1)",
        "lambda: 1",
        "abs(-1)",
    ]
)


@settings(
    max_examples=6, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(st.lists(EXPRESSIONS, min_size=1, max_size=3), st.sampled_from([" + ", " * ", ", "]))
def test_any_xacro_expression_is_a_located_error_or_a_value(
    tmp: Path, exprs: list[str], op: str
) -> None:
    a = tmp / "work" / "a"
    expr = op.join(exprs)
    xacro(a, f'<link name="l${{str({expr})[:20]}}"/>')
    spec(a, "r.urdf.xacro")
    r = run_cli(tmp, "validate", "a/spec.yaml")
    fenced(r, tmp)
    assert r.code in (0, 1), r.err
    assert "internal error" not in r.text
    if r.code == 1:
        assert r.text.startswith(f"{a}/r.urdf.xacro"), r.text
