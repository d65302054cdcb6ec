"""Meshes bounded by triangles, not only bytes, and mesh scales bounded to sane sizes.

Why: the byte cap did not bound memory (a 50 MB binary STL of 10^6 triangles peaked at 2.26 GB;
5 * 10^6 triangles were a MemoryError), and ``scale="1e308 1 1"`` or ``"1e-300"`` was accepted.
A mesh over ``ROBOTSPEC_MAX_MESH_TRIANGLES`` is refused from what it declares, before it is
parsed, and a scale factor outside [1e-6, 1e6] (in size) is an error at its URDF line.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.errors import CollisionError, DescriptionError
from robotspec.files.limits import limits
from robotspec.files.meshes import declared_triangles, read_triangles


def _binary_stl(path: Path, n: int) -> Path:
    tri = np.zeros(n, dtype=[("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    tri["v"][:, 1, 0] = 0.1
    tri["v"][:, 2, 1] = 0.1
    tri["v"][:, :, 2] = np.arange(n, dtype=np.float32)[:, None] * 0.01
    path.write_bytes(b"\0" * 80 + struct.pack("<I", n) + tri.tobytes())
    return path


def _ascii_stl(path: Path, n: int) -> Path:
    facet = (
        "facet normal 0 0 1\n outer loop\n  vertex 0 0 {z}\n  vertex 1 0 {z}\n  vertex 0 1 {z}\n"
        " endloop\nendfacet\n"
    )
    path.write_text("solid s\n" + "".join(facet.format(z=i) for i in range(n)) + "endsolid s\n")
    return path


def _obj(path: Path, faces: int, corners: int = 3) -> Path:
    verts = "".join(f"v {i} {i % 2} {i % 3}\n" for i in range(corners + 1))
    face = "f " + " ".join(str(i + 1) for i in range(corners)) + "\n"
    path.write_text(verts + face * faces)
    return path


def _ply(path: Path, faces: int) -> Path:
    head = (
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        f"property float z\nelement face {faces}\nproperty list uchar int vertex_indices\n"
        "end_header\n"
    )
    path.write_text(head + "0 0 0\n1 0 0\n0 1 0\n" + "3 0 1 2\n" * faces)
    return path


def test_default_cap_and_its_variable() -> None:
    assert limits({}).max_mesh_triangles == 1_000_000
    assert limits({"ROBOTSPEC_MAX_MESH_TRIANGLES": "2e6"}).max_mesh_triangles == 2_000_000
    assert limits({"ROBOTSPEC_MAX_MESH_TRIANGLES": "-5"}).max_mesh_triangles == 1_000_000


def test_declared_counts(tmp_path: Path) -> None:
    binary = _binary_stl(tmp_path / "b.stl", 7).read_bytes()
    assert declared_triangles(binary, "stl") == 7
    # A header that disagrees with the file's size is not trusted: counted as ASCII (none).
    assert declared_triangles(binary[:80] + struct.pack("<I", 10**9) + binary[84:], "stl") == 0
    assert declared_triangles(_ascii_stl(tmp_path / "a.stl", 4).read_bytes(), "stl") == 4
    assert declared_triangles(_obj(tmp_path / "o.obj", 5).read_bytes(), "obj") == 5
    assert declared_triangles(b"f 1 2 3\nf\t1 2 3\n", "obj") == 2
    assert declared_triangles(_ply(tmp_path / "p.ply", 6).read_bytes(), "ply") == 6
    assert declared_triangles(b"<COLLADA/>", "dae") is None


@pytest.mark.parametrize(
    ("name", "make", "count"),
    [
        ("big.stl", lambda p: _binary_stl(p, 11), 11),
        ("big_ascii.stl", lambda p: _ascii_stl(p, 11), 11),
        ("big.obj", lambda p: _obj(p, 11), 11),
        ("big.ply", lambda p: _ply(p, 11), 11),
    ],
)
def test_declared_triangles_over_the_cap_are_refused_before_parsing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str, make: object, count: int
) -> None:
    import trimesh

    path = make(tmp_path / name)  # type: ignore[operator]
    monkeypatch.setenv("ROBOTSPEC_MAX_MESH_TRIANGLES", "10")

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("the mesh was parsed")

    monkeypatch.setattr(trimesh, "load", never)
    with pytest.raises(CollisionError) as info:
        read_triangles(str(path), CollisionError)
    assert info.value.message == (
        f"mesh declares {count} triangles, more than 10 (the cap on one mesh; "
        "set ROBOTSPEC_MAX_MESH_TRIANGLES to raise it)"
    )
    assert info.value.file == str(path)


def test_parsed_triangles_over_the_cap_are_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Three quads: three face lines declared, six triangles once parsed.
    path = _obj(tmp_path / "quads.obj", 3, corners=4)
    monkeypatch.setenv("ROBOTSPEC_MAX_MESH_TRIANGLES", "5")
    with pytest.raises(DescriptionError, match="mesh has 6 triangles, more than 5"):
        read_triangles(str(path), DescriptionError)
    monkeypatch.setenv("ROBOTSPEC_MAX_MESH_TRIANGLES", "6")
    assert len(read_triangles(str(path), DescriptionError)[1]) == 6


def _robot(tmp_path: Path, mesh: str, scale: str | None = None) -> Path:
    attr = "" if scale is None else f' scale="{scale}"'
    (tmp_path / "r.urdf").write_text(
        '<robot name="r">\n'
        f'<link name="a"><collision><geometry><mesh filename="{mesh}"{attr}/></geometry>'
        f'</collision><visual><geometry><mesh filename="{mesh}"/></geometry></visual></link>\n'
        '<link name="b"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
        "</link>\n"
        '<link name="c"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
        "</link>\n"
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<origin xyz="3 0 0"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
        '<joint name="k" type="revolute"><parent link="b"/><child link="c"/>'
        '<origin xyz="0 0 3"/><axis xyz="0 1 0"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
        "</robot>\n"
    )
    spec = tmp_path / "r.yaml"
    spec.write_text(
        "robotspec: 1\nname: r\ndescription:\n  urdf: r.urdf\nroot: a\n"
        "chains:\n  arm: {root: a, tip: c, kind: chain}\n"
    )
    return spec


@pytest.mark.parametrize(
    ("command", "options"), [(["collisions", "check"], []), (["render"], ["-o", "x.png"])]
)
def test_cli_names_the_mesh_over_the_cap(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    command: list[str],
    options: list[str],
) -> None:
    _binary_stl(tmp_path / "m.stl", 50)
    spec = _robot(tmp_path, "m.stl")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("ROBOTSPEC_MAX_MESH_TRIANGLES", "49")
    code = run_app(app, [*command, str(spec), *options])
    err = capsys.readouterr().err
    assert code == 1, err
    assert f"{tmp_path / 'm.stl'}: error: link 'a': mesh declares 50 triangles, more than 49" in err
    assert "ROBOTSPEC_MAX_MESH_TRIANGLES" in err
    assert "internal error" not in err
    monkeypatch.setenv("ROBOTSPEC_MAX_MESH_TRIANGLES", "50")
    assert run_app(app, ["collisions", "check", str(spec)]) == 0


@pytest.mark.parametrize("scale", ["1e308 1 1", "1e-300", "0 1 1", "1 1 -1e7", "1e-7 1 1"])
def test_absurd_mesh_scales_are_located_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], scale: str
) -> None:
    _binary_stl(tmp_path / "m.stl", 2)
    spec = _robot(tmp_path, "m.stl", scale)
    code = run_app(app, ["validate", str(spec)])
    out = capsys.readouterr()
    assert code == 1
    assert (
        f"{tmp_path / 'r.urdf'}:2: error: link 'a' collision: mesh scale '{scale}' is out of "
        "range (each factor's size must be between 1e-06 and 1e+06)"
    ) in out.out + out.err


@pytest.mark.parametrize("scale", ["1e6 -1e-6 1", "0.001 -0.001 0.001", "1 -1 1", "2"])
def test_sane_mesh_scales_are_kept(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], scale: str
) -> None:
    _binary_stl(tmp_path / "m.stl", 2)
    spec = _robot(tmp_path, "m.stl", scale)
    assert run_app(app, ["validate", str(spec)]) == 0, capsys.readouterr()


def test_five_million_declared_triangles_are_refused_under_a_memory_fence(tmp_path: Path) -> None:
    # The reported crash: a binary STL of 5 * 10^6 triangles was a MemoryError (parsing costs
    # about 500 bytes per triangle). A sparse file of that size, run under the hostile runner's
    # address-space limit, is refused from its header with the file named.
    from tests.test_hostile import run_cli

    (tmp_path / "work").mkdir()
    n = 5_000_000
    with (tmp_path / "m.stl").open("wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", n))
        f.truncate(84 + 50 * n)
    spec = _robot(tmp_path, "m.stl")
    r = run_cli(tmp_path, "collisions", "check", str(spec))
    assert r.code == 1, r.err
    assert r.err.startswith(
        f"{tmp_path / 'm.stl'}: error: link 'a': mesh declares 5,000,000 triangles, more than "
        "1,000,000 (the cap on one mesh; set ROBOTSPEC_MAX_MESH_TRIANGLES to raise it)"
    )
