"""xacro expansion without ROS: real robots match their shipped URDFs, hostile input is refused."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

from robotspec.errors import DescriptionError, PackageNotFoundError, PathOutsideRootsError
from robotspec.files.packages import PackageResolver
from robotspec.files.xacro import process_xacro
from robotspec.files.xmlsafe import parse_xml_bytes

from .conftest import DATA, shared_path

PKGS = DATA / "packages"
ROBOT_XACRO = PKGS / "alpha_dir" / "urdf" / "robot.urdf.xacro"
NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'


def resolver_for(path: Path, **kwargs: object) -> PackageResolver:
    return PackageResolver.create(
        path,
        use_environment=False,
        use_example_robot_data=False,
        **kwargs,  # type: ignore[arg-type]
    )


def expand(path: Path, args: dict[str, str] | None = None, **kwargs: object) -> bytes:
    return process_xacro(path, resolver_for(path, **kwargs), args)


def write(path: Path, body: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f'<?xml version="1.0"?>\n<robot name="r" {NS}>\n{body}\n</robot>\n')
    return path


def names(xml: bytes) -> tuple[list[str | None], list[str | None]]:
    root = parse_xml_bytes(xml, "out.urdf")
    return [e.get("name") for e in root.findall("link")], [
        e.get("name") for e in root.findall("joint")
    ]


# --- the fixture package tree -------------------------------------------------------------------


def test_fixture_expands_with_args_includes_find_and_yaml() -> None:
    out = expand(ROBOT_XACRO, {"prefix": "left_"})
    links, joints = names(out)
    assert links == ["left_base", "left_arm", "left_flange"]
    assert joints == ["left_arm_joint", "left_flange_joint"]
    root = parse_xml_bytes(out, "out.urdf")
    assert root.find("joint/origin").get("xyz") == "0 0 0.25"  # from params.yaml via load_yaml
    assert root.find("link/visual/geometry/mesh").get("filename") == (
        "package://beta_meshes/meshes/box.stl"
    )
    assert out.startswith(b'<?xml version="1.0" ?>')


def test_default_args_apply_and_caller_args_are_not_mutated() -> None:
    args: dict[str, str] = {}
    links, _ = names(expand(ROBOT_XACRO, args))
    assert links == ["base", "arm", "flange"]
    assert args == {}


def test_hooks_are_restored(tmp_path: Path) -> None:
    import xacro
    import xacro.substitution_args as subst

    find, safe_eval = subst._eval_find, xacro.safe_eval
    python_vars = xacro._global_symbols["python"]["vars"]
    expand(ROBOT_XACRO)
    bad = write(tmp_path / "bad.xacro", '<link name="$(find no_such_pkg)"/>')
    with pytest.raises(PackageNotFoundError):
        expand(bad)
    assert subst._eval_find is find
    assert subst._eval_dict["find"] is find
    assert xacro.safe_eval is safe_eval
    assert xacro._global_symbols["python"]["vars"] is python_vars
    assert "open" not in vars(xacro)
    assert "eval" not in vars(subst)
    assert xacro.substitution_args_context["arg"] == {}


def test_concurrent_expansions_agree() -> None:
    results: list[bytes] = []
    errors: list[BaseException] = []

    def run(prefix: str) -> None:
        try:
            results.append(expand(ROBOT_XACRO, {"prefix": prefix}))
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=run, args=(f"p{i}_",)) for i in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert sorted(names(r)[0][0] or "" for r in results) == [f"p{i}_base" for i in range(6)]


# --- errors -------------------------------------------------------------------------------------


def test_missing_arg_names_it(tmp_path: Path) -> None:
    path = write(tmp_path / "r.xacro", '<link name="a"/>\n<link name="$(arg wheel)"/>')
    with pytest.raises(DescriptionError) as info:
        expand(path)
    err = info.value
    assert err.message == "xacro argument 'wheel' is not set; pass it as xacro_args"
    assert (err.file, err.line, err.name) == (str(path), 4, "wheel")
    assert names(expand(path, {"wheel": "w"}))[0] == ["a", "w"]


def test_unknown_package_in_find(tmp_path: Path) -> None:
    path = write(tmp_path / "r.xacro", '<xacro:include filename="$(find no_such_pkg)/x.xacro"/>')
    with pytest.raises(PackageNotFoundError) as info:
        expand(path)
    assert info.value.message.startswith("package 'no_such_pkg' not found; searched: ")
    assert info.value.file == str(path)


def test_malformed_include_reports_its_file_and_line(tmp_path: Path) -> None:
    inc = tmp_path / "inc.xacro"
    inc.write_text(f'<robot {NS}>\n  <link name="a">\n</robot>\n')
    path = write(tmp_path / "r.xacro", '<xacro:include filename="inc.xacro"/>')
    with pytest.raises(DescriptionError) as info:
        expand(path)
    assert info.value.message == "malformed XML: mismatched tag"
    assert (info.value.file, info.value.line) == (str(inc), 3)


def test_missing_include(tmp_path: Path) -> None:
    path = write(tmp_path / "r.xacro", '<xacro:include filename="nope.xacro"/>')
    with pytest.raises(DescriptionError) as info:
        expand(path)
    assert info.value.message == (
        f"xacro cannot read '{tmp_path / 'nope.xacro'}': No such file or directory"
    )
    assert info.value.file == str(path)
    optional = write(
        tmp_path / "o.xacro",
        '<xacro:include filename="nope.xacro" optional="true"/><link name="a"/>',
    )
    assert names(expand(optional))[0] == ["a"]


def test_bad_expression_is_a_description_error_with_line(tmp_path: Path) -> None:
    path = write(tmp_path / "r.xacro", '<link name="a"/>\n<link name="${1/0}"/>')
    with pytest.raises(DescriptionError) as info:
        expand(path)
    assert info.value.message.startswith("xacro failed: division by zero")
    assert "when evaluating expression '1/0'" in info.value.message
    assert (info.value.file, info.value.line) == (str(path), 4)


def test_xacro_noise_does_not_leak(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    # Direct sorted() is deprecated in xacro 2.x: it prints a warning to stderr.
    path = write(tmp_path / "r.xacro", "<link name=\"${sorted(['b', 'a'])[0]}\"/>")
    assert names(expand(path))[0] == ["a"]
    captured = capfd.readouterr()
    assert (captured.out, captured.err) == ("", "")


# --- security -----------------------------------------------------------------------------------


def test_include_outside_roots_is_refused(tmp_path: Path) -> None:
    write(tmp_path / "outside" / "evil.xacro", '<link name="evil"/>')
    path = write(
        tmp_path / "robot" / "r.xacro", '<xacro:include filename="../outside/evil.xacro"/>'
    )
    with pytest.raises(PathOutsideRootsError) as info:
        expand(path)
    assert info.value.message == (
        f"xacro file '{tmp_path / 'robot' / '../outside/evil.xacro'}' resolves to "
        f"{tmp_path / 'outside' / 'evil.xacro'}, outside the allowed folders ({tmp_path / 'robot'})"
    )
    assert info.value.file == str(path)
    # An explicitly allowed folder may be included.
    ok = expand(path, extra_allowed_roots=[tmp_path / "outside"])
    assert names(ok)[0] == ["evil"]


def test_include_of_system_file_and_symlink_refused(tmp_path: Path) -> None:
    (tmp_path / "outside").mkdir()
    (tmp_path / "outside" / "real.xacro").write_text(f'<robot {NS}><link name="x"/></robot>')
    (tmp_path / "robot").mkdir()
    (tmp_path / "robot" / "link.xacro").symlink_to(tmp_path / "outside" / "real.xacro")
    for target in ("/etc/passwd", "link.xacro"):
        path = write(tmp_path / "robot" / "r.xacro", f'<xacro:include filename="{target}"/>')
        with pytest.raises(PathOutsideRootsError, match="outside the allowed folders"):
            expand(path)


def test_load_yaml_outside_roots_is_refused(tmp_path: Path) -> None:
    (tmp_path / "outside").mkdir()
    (tmp_path / "outside" / "p.yaml").write_text("a: 1\n")
    body = '<xacro:property name="p" value="${xacro.load_yaml(\'../outside/p.yaml\')}"/>'
    path = write(tmp_path / "robot" / "r.xacro", body + '\n<link name="${p.a}"/>')
    with pytest.raises(PathOutsideRootsError, match=r"p\.yaml' resolves to .*outside the allowed"):
        expand(path)


@pytest.mark.parametrize("where", ["top", "include"])
def test_entities_are_refused(tmp_path: Path, where: str) -> None:
    evil = (
        '<?xml version="1.0"?>\n<!DOCTYPE robot [\n  <!ENTITY lol "lol">\n]>\n'
        f'<robot name="r" {NS}><link name="&lol;"/></robot>\n'
    )
    target = tmp_path / ("r.xacro" if where == "top" else "inc.xacro")
    target.write_text(evil)
    path = (
        target
        if where == "top"
        else write(tmp_path / "r.xacro", '<xacro:include filename="inc.xacro"/>')
    )
    with pytest.raises(DescriptionError) as info:
        expand(path)
    assert info.value.message == "XML entity declarations are not allowed (found 'lol')"
    assert (info.value.file, info.value.line) == (str(target), 3)


def test_import_in_expression_is_refused_and_not_run(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path / "r.xacro", "<link name=\"${__import__('os').system('echo pwned')}\"/>")
    with pytest.raises(DescriptionError) as info:
        expand(path)
    assert "__import__" in info.value.message
    assert "pwned" not in capfd.readouterr().out


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        # xacro 2.1.1 checks dunders only in the outer expression: comprehensions escape it.
        (
            '<link name="${[x.__class__.__base__.__subclasses__() for x in [0]]}"/>',
            "xacro expression uses __base__, __class__, __subclasses__",
        ),
        # String keys reach dunders through vars()/type(), which are disabled.
        (
            "<link name=\"${python.vars(python.type(0))['_' + '_doc_' + '_']}\"/>",
            "python.type() is disabled by robotspec",
        ),
        ('<link name="${python.vars(0)}"/>', "python.vars() is disabled by robotspec"),
        # $(eval) runs with Python's full builtins in xacro 2.1.1 (open, exec).
        (
            '<xacro:property name="e" value="open(\'/etc/hostname\').read()"/>'
            '<link name="$(eval ${e})"/>',
            "name 'open' is not defined",
        ),
    ],
)
def test_sandbox_escapes_are_refused(tmp_path: Path, body: str, needle: str) -> None:
    path = write(tmp_path / "r.xacro", body)
    with pytest.raises(DescriptionError) as info:
        expand(path)
    assert needle in info.value.message


# --- real robots --------------------------------------------------------------------------------


def _without_banner(xml: bytes) -> list[str]:
    """Output lines minus xacro's banner line naming the input path (the one difference)."""
    return [ln for ln in xml.decode().splitlines() if "autogenerated by xacro from" not in ln]


@pytest.mark.parametrize(
    ("xacro_file", "urdf_file", "n_links"),
    [
        ("robots/hsrb/hsrb_description/robots/hsrb4s.urdf.xacro", "robots/hsrb/hsrb4s.urdf", 48),
        ("robots/pr2/pr2_description/robots/pr2.urdf.xacro", "robots/pr2/pr2.urdf", 88),
        ("robots/ur5e/ur_description/urdf/ur5e.xacro", "robots/ur5e/ur5e.urdf", 11),
    ],
)
def test_shared_xacros_match_shipped_urdfs(xacro_file: str, urdf_file: str, n_links: int) -> None:
    source = shared_path(xacro_file)
    shipped = shared_path(urdf_file).read_bytes()
    out = process_xacro(source, PackageResolver.create(source, use_environment=False), {})
    assert names(out) == names(shipped)
    assert len(names(out)[0]) == n_links
    # Byte-identical except the banner comment, which names the input path as given.
    assert _without_banner(out) == _without_banner(shipped)


def test_generic_ur_xacro_with_args_matches_ur5e() -> None:
    source = shared_path("robots/ur5e/ur_description/urdf/ur.xacro")
    config = source.parents[1] / "config" / "ur5e"
    args = {
        "robot_model": "ur5e",
        "joint_limit_params": str(config / "joint_limits.yaml"),
        "kinematics_params": str(config / "default_kinematics.yaml"),
        "physical_params": str(config / "physical_parameters.yaml"),
        "visual_params": str(config / "visual_parameters.yaml"),
    }
    resolver = PackageResolver.create(source, use_environment=False)
    out = process_xacro(source, resolver, args)
    assert names(out) == names(shared_path("robots/ur5e/ur5e.urdf").read_bytes())
    with pytest.raises(DescriptionError) as info:
        process_xacro(source, resolver, {})
    assert info.value.message == "xacro argument 'robot_model' is not set; pass it as xacro_args"
    assert (info.value.file, info.value.line) == (str(source), 2)
