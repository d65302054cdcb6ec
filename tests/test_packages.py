"""Package search and URI resolution without ROS: priorities, exact messages and the read fence."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from robotspec.errors import DescriptionError, PackageNotFoundError, PathOutsideRootsError
from robotspec.files.packages import PackageResolver

from .conftest import DATA, erd_robots

PKGS = DATA / "packages"
ALPHA = PKGS / "alpha_dir"
BETA = PKGS / "beta_dir"
ROBOT_XACRO = ALPHA / "urdf" / "robot.urdf.xacro"


def isolated(description: Path | None = ROBOT_XACRO, **kwargs: object) -> PackageResolver:
    """A resolver that ignores the process environment and the installed example-robot-data."""
    return PackageResolver.create(
        description,
        use_environment=False,
        use_example_robot_data=False,
        **kwargs,  # type: ignore[arg-type]
    )


def make_package(folder: Path, name: str | None = None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    if name is not None:
        (folder / "package.xml").write_text(f"<package><name>{name}</name></package>")
    return folder


# --- finding packages ---------------------------------------------------------------------------


def test_declared_names_win_over_folder_names_and_siblings_are_found() -> None:
    r = isolated()
    assert r.find_package("alpha_description") == ALPHA
    # beta_meshes is a sibling of the package enclosing the description.
    assert r.find_package("beta_meshes") == BETA
    # Folder names are aliases (pinocchio's convention, used by example-robot-data's URDFs).
    assert r.find_package("beta_dir") == BETA
    assert r.search_folders == (ALPHA / "urdf", PKGS)
    # Beside a description, a folder is a package by its name alone (docs/own-robot-files.md:
    # "found by package.xml name or folder name"), ranked below the search path's manifests.
    assert r.find_package("inc") == ALPHA / "urdf" / "inc"
    assert "gamma_plain" not in r.packages()


def test_explicit_folder_children_without_manifest_are_packages() -> None:
    r = isolated(None, extra_paths=[PKGS])
    assert r.find_package("gamma_plain") == PKGS / "gamma_plain"
    assert r.resolve("package://gamma_plain/meshes/plain.stl").is_file()


def test_unknown_package_message_is_exact() -> None:
    r = isolated()
    with pytest.raises(PackageNotFoundError) as info:
        r.find_package("alpha_descriptoin", file="robot.urdf", line=7)
    err = info.value
    assert err.message == (
        f"package 'alpha_descriptoin' not found; searched: {ALPHA / 'urdf'}, {PKGS}; "
        "did you mean 'alpha_description'?"
    )
    assert (err.file, err.line, err.name) == ("robot.urdf", 7, "alpha_descriptoin")
    assert err.suggestions == ("alpha_description",)
    assert str(err).startswith("robot.urdf:7: error: package 'alpha_descriptoin' not found")


def test_no_search_folders_message() -> None:
    r = PackageResolver.create(None, use_environment=False, use_example_robot_data=False)
    with pytest.raises(PackageNotFoundError, match=r"searched: \(no folders\)$"):
        r.find_package("anything")


def test_unparsable_manifest_falls_back_to_folder_name(tmp_path: Path) -> None:
    broken = make_package(tmp_path / "ws" / "broken_pkg")
    (broken / "package.xml").write_text("<package><name>oops</package>")
    r = isolated(None, extra_paths=[tmp_path / "ws"])
    assert r.find_package("broken_pkg") == broken
    assert "oops" not in r.packages()


def test_crawl_is_bounded_and_skips_hidden_and_ignored(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    make_package(ws / "a" / "b" / "deep3", "deep3")
    make_package(ws / "a" / "b" / "c" / "deep4", "deep4")
    make_package(ws / ".hidden" / "secret", "secret")
    make_package(ws / "skipped" / "ignored_pkg", "ignored_pkg")
    (ws / "skipped" / "COLCON_IGNORE").touch()
    # Packages are not crawled into.
    make_package(ws / "outer", "outer")
    make_package(ws / "outer" / "test" / "vendored", "vendored")
    names = set(isolated(None, extra_paths=[ws]).packages())
    assert {"deep3", "outer"} <= names
    assert not {"deep4", "secret", "ignored_pkg", "vendored"} & names


def test_search_folder_that_is_a_package(tmp_path: Path) -> None:
    pkg = make_package(tmp_path / "folder_name", "declared_name")
    make_package(pkg / "inner", "inner")
    r = isolated(None, extra_paths=[pkg])
    assert r.packages() == {"declared_name": pkg, "folder_name": pkg}


def test_environment_variables_and_priority(tmp_path: Path) -> None:
    explicit = make_package(tmp_path / "explicit" / "shared_pkg", "shared_pkg").parent
    ros = make_package(tmp_path / "ros" / "shared_pkg", "shared_pkg").parent
    make_package(ros / "ros_only", "ros_only")
    prefix = tmp_path / "install"
    make_package(prefix / "share" / "shared_pkg", "shared_pkg")
    make_package(prefix / "share" / "ament_only", "ament_only")
    make_package(prefix / "share" / "ros_only", "ros_only")
    environ = {
        "ROS_PACKAGE_PATH": os.pathsep.join([str(ros), str(tmp_path / "missing")]),
        "AMENT_PREFIX_PATH": str(prefix),
    }

    def make(**kwargs: object) -> PackageResolver:
        return PackageResolver.create(
            None,
            use_example_robot_data=False,
            environ=environ,
            **kwargs,  # type: ignore[arg-type]
        )

    r = make(extra_paths=[explicit])
    assert r.search_folders == (explicit, ros, prefix / "share")  # the missing entry is dropped
    assert r.find_package("shared_pkg") == explicit / "shared_pkg"
    assert r.find_package("ros_only") == ros / "ros_only"
    assert r.find_package("ament_only") == prefix / "share" / "ament_only"
    assert make().find_package("shared_pkg") == ros / "shared_pkg"
    assert not make(use_environment=False).packages()


def test_environment_wins_over_the_description_neighbourhood(tmp_path: Path) -> None:
    env_copy = make_package(tmp_path / "env" / "beta_copy", "beta_meshes").parent
    r = PackageResolver.create(
        ROBOT_XACRO, use_example_robot_data=False, environ={"ROS_PACKAGE_PATH": str(env_copy)}
    )
    assert r.find_package("beta_meshes") == env_copy / "beta_copy"
    assert r.find_package("alpha_description") == ALPHA


def test_resolvers_do_not_share_state(tmp_path: Path) -> None:
    a = isolated(None, extra_paths=[make_package(tmp_path / "a" / "p", "only_a").parent])
    b = isolated(None, extra_paths=[make_package(tmp_path / "b" / "p", "only_b").parent])
    assert set(a.packages()) == {"only_a", "p"}
    assert set(b.packages()) == {"only_b", "p"}


# --- resolving URIs -----------------------------------------------------------------------------


def test_uri_forms() -> None:
    r = isolated()
    mesh = BETA / "meshes" / "box.stl"
    base = ALPHA / "urdf"
    assert r.resolve("package://beta_meshes/meshes/box.stl") == mesh
    assert r.resolve("package://beta_meshes") == BETA
    assert r.resolve(f"file://{mesh}") == mesh
    assert r.resolve(f"file://localhost{mesh}") == mesh
    assert r.resolve("file://../../beta_dir/meshes/box.stl", relative_to=base) == mesh
    assert r.resolve("../../beta_dir/meshes/box.stl", relative_to=base) == mesh
    assert r.resolve(str(mesh)) == mesh
    # An absolute-looking rest stays inside the package.
    assert r.resolve("package://beta_meshes//etc/passwd") == BETA / "etc" / "passwd"
    # Missing files resolve; callers decide how to report them.
    assert r.resolve("package://beta_meshes/meshes/nope.stl") == BETA / "meshes" / "nope.stl"


def test_file_uri_is_percent_decoded(tmp_path: Path) -> None:
    (tmp_path / "with space.stl").touch()
    r = isolated(None, extra_allowed_roots=[tmp_path])
    assert r.resolve(f"file://{tmp_path}/with%20space.stl") == (tmp_path / "with space.stl")


@pytest.mark.parametrize(
    "uri",
    [
        "package://beta_meshes/../../../../../../../../etc/passwd",
        "file:///etc/passwd",
        "/etc/passwd",
    ],
)
def test_paths_outside_the_roots_are_refused(uri: str) -> None:
    r = isolated()
    with pytest.raises(PathOutsideRootsError) as info:
        r.resolve(uri, file="robot.urdf", line=3)
    real = os.path.realpath("/etc/passwd")
    roots = ", ".join(str(p) for p in r.roots)
    assert info.value.message == (
        f"'{uri}' resolves to {real}, outside the allowed folders ({roots})"
    )
    assert (info.value.file, info.value.line) == ("robot.urdf", 3)


def test_symlink_escaping_the_roots_is_refused(tmp_path: Path) -> None:
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "secret.stl").write_text("secret")
    pkg = make_package(tmp_path / "ws" / "pkg", "pkg")
    (pkg / "meshes").symlink_to(outside, target_is_directory=True)
    (pkg / "link.stl").symlink_to(outside / "secret.stl")
    r = isolated(None, extra_paths=[tmp_path / "ws"])
    for uri in ("package://pkg/meshes/secret.stl", "package://pkg/link.stl"):
        with pytest.raises(PathOutsideRootsError, match="outside the allowed folders"):
            r.resolve(uri)
    assert not r.is_allowed(pkg / "link.stl")
    # Allowing the target folder explicitly makes the same link readable.
    trusting = isolated(None, extra_paths=[tmp_path / "ws"], extra_allowed_roots=[outside])
    assert trusting.resolve("package://pkg/link.stl") == outside / "secret.stl"


def test_dotdot_after_a_symlink_follows_the_link_like_the_os(tmp_path: Path) -> None:
    # 'link/../x' is opened by the OS as '<link target>/../x', not as the lexical 'x'.
    deep = tmp_path / "outside" / "deep"
    deep.mkdir(parents=True)
    (tmp_path / "outside" / "secret.stl").write_text("secret")
    pkg = make_package(tmp_path / "ws" / "pkg", "pkg")
    (pkg / "secret.stl").write_text("decoy inside the package")
    (pkg / "link").symlink_to(deep, target_is_directory=True)
    r = isolated(None, extra_paths=[tmp_path / "ws"])
    with pytest.raises(PathOutsideRootsError, match="outside the allowed folders"):
        r.resolve("package://pkg/link/../secret.stl")
    assert not r.is_allowed(pkg / "link" / ".." / "secret.stl")
    # Repeated lookups in one folder (the per-folder cache) still see a symlinked file.
    assert r.is_allowed(pkg / "secret.stl")
    (pkg / "late.stl").symlink_to(tmp_path / "outside" / "secret.stl")
    assert not r.is_allowed(pkg / "late.stl")


@pytest.mark.parametrize("scheme", ["http", "https", "ftp"])
def test_other_schemes_are_refused(scheme: str) -> None:
    uri = f"{scheme}://example.com/robot/mesh.stl"
    with pytest.raises(DescriptionError) as info:
        isolated().resolve(uri, file="robot.urdf", line=4)
    assert not isinstance(info.value, PathOutsideRootsError)
    assert info.value.message == (
        f"unsupported URI scheme '{scheme}' in '{uri}'; "
        "robotspec reads only package://, model://, file:// and paths"
    )


def test_empty_package_name_starts_at_a_package_root() -> None:
    # pinocchio joins what follows 'package://' to each package folder: Talos's
    # 'package:///example-robot-data/robots/...' is '<folder>/example-robot-data/robots/...'.
    r = isolated()
    mesh = BETA / "meshes" / "box.stl"
    assert r.resolve("package:///beta_dir/meshes/box.stl") == mesh  # a search folder's child
    assert r.resolve("package:///beta_meshes/meshes/box.stl") == mesh  # else a package name
    assert r.resolve("model://beta_meshes/meshes/box.stl") == mesh  # pinocchio's model://
    with pytest.raises(PackageNotFoundError) as info:
        r.resolve("package:///no_such_pkg/meshes/a.stl", file="robot.urdf", line=9)
    searched = ", ".join(str(f) for f in r.search_folders)
    assert info.value.message == (
        "package 'no_such_pkg' not found (a package:/// path starts at a package root); "
        f"searched: {searched}"
    )
    assert (info.value.file, info.value.line, info.value.name) == ("robot.urdf", 9, "no_such_pkg")
    # No search folder may be left: '..' is probed nowhere and is no package name.
    with pytest.raises(PackageNotFoundError, match="package '..' not found"):
        r.resolve("package:///../../../../../../etc/passwd")
    with pytest.raises(PathOutsideRootsError):
        r.resolve("package:///beta_meshes/../../../../../../../../etc/passwd")


def test_talos_full_v2_meshes_resolve_from_the_package_root() -> None:
    robots = erd_robots()
    r = PackageResolver.create(None, use_environment=False)
    uri = "package:///example-robot-data/robots/talos_data/meshes/torso/torso_2.STL"
    assert r.resolve(uri) == robots / "talos_data" / "meshes" / "torso" / "torso_2.STL"


def test_bad_package_names_and_empty_refs() -> None:
    r = isolated()
    with pytest.raises(PackageNotFoundError, match="package '..' not found"):
        r.resolve("package://../etc/passwd")
    with pytest.raises(DescriptionError, match="empty file reference"):
        r.resolve("  ")


def test_allowed_roots_include_the_description_and_its_package() -> None:
    r = isolated(extra_allowed_roots=["/opt/robot_data"])
    assert ALPHA / "urdf" in r.roots
    assert ALPHA in r.roots
    assert Path("/opt/robot_data") in r.allowed_roots
    assert r.is_allowed(ALPHA / "package.xml")
    assert not r.is_allowed("/etc/passwd")


SEGMENT = st.sampled_from(["..", ".", "meshes", "box.stl", "x", "", "..."])


@given(
    st.lists(SEGMENT, min_size=1, max_size=10),
    st.sampled_from(["package", "root", "model", "file", "plain"]),
)
def test_dotdot_never_escapes(segments: list[str], form: str) -> None:
    r = isolated()
    rel = "/".join(segments)
    base = ALPHA / "urdf"
    uri = {
        "package": f"package://beta_meshes/{rel}",
        "root": f"package:///{rel}",
        "model": f"model://beta_meshes/{rel}",
        "file": f"file://{rel}",
        "plain": rel,
    }[form]
    if not uri.strip():
        return
    try:
        path = r.resolve(uri, relative_to=base)
    except (PathOutsideRootsError, PackageNotFoundError):
        return
    real = Path(os.path.realpath(path))
    assert any(real == root or real.is_relative_to(root) for root in r.allowed_roots)


# --- real data ----------------------------------------------------------------------------------


def test_example_robot_data_meshes_resolve() -> None:
    robots = erd_robots()
    urdf = robots / "pr2_description" / "urdf" / "pr2.urdf"
    uris = re.findall(r'filename="(package://[^"]+)"', urdf.read_text())
    assert uris
    r = PackageResolver.create(urdf, use_environment=False)
    # example-robot-data's own URDFs name the share folder (pinocchio's convention).
    assert uris[0].startswith("package://example-robot-data/robots/pr2_description/meshes/")
    for uri in sorted(set(uris))[:20]:
        assert r.resolve(uri).is_file(), uri
    # The ROS form of the same mesh resolves through the robots folder.
    short = uris[0].replace("package://example-robot-data/robots/", "package://")
    assert r.resolve(short) == r.resolve(uris[0])
    # Found from anywhere, not only next to the URDF.
    anywhere = PackageResolver.create(None, use_environment=False)
    assert anywhere.find_package("pr2_description") == robots / "pr2_description"


def test_manifest_name_ignores_commented_out_names(tmp_path: Path) -> None:
    pkg = tmp_path / "ws" / "folder"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="3">\n'
        "  <!-- renamed: <name>old_name</name> -->\n  <name>new_name</name>\n</package>\n"
    )
    names = set(isolated(None, extra_paths=[tmp_path / "ws"]).packages())
    assert "new_name" in names and "old_name" not in names
