"""A robot as files other tools load: one URDF, and a bundle of URDF + SRDF + flat spec.

Why: a robot robotspec composed from parts exists as one description only inside robotspec;
MoveIt, pinocchio and simulators need it as a single URDF (and SRDF). The bundle's spec names the
exported files and holds the composed semantics, so the bundle compiles to the same robot without
the parts' files.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lxml import etree

from robotspec.compiler import CompileResult
from robotspec.model.geometry import Mesh
from robotspec.spec.load import LoadedSpec, check_package_paths, load_spec

__all__ = ["Bundle", "bundle", "joined_urdf", "urdf_text"]


def joined_urdf(loaded: LoadedSpec, *, package_paths: Sequence[str | Path] = ()) -> etree._Element:
    """The robot's URDF tree: the parts joined, or the flat spec's file with its frames added.

    Relative mesh paths are made absolute (the file is written elsewhere); ``package://`` URIs
    stay as written.
    """
    from robotspec.compose import compose, description_tree

    check_package_paths(loaded, package_paths)
    if loaded.spec.parts:
        return compose(loaded, package_paths=package_paths).urdf
    return description_tree(loaded.spec.files, loaded.folder, package_paths)[0]


def urdf_text(tree: etree._Element, *, comment: str) -> str:
    """The tree as an indented URDF document with a leading comment (a copy is indented)."""
    out = copy.deepcopy(tree)
    for el in out.iter():
        if isinstance(el.tag, str):
            el.text = None if el.text is None or not el.text.strip() else el.text
            el.tail = None
    etree.indent(out, space="  ")
    out.insert(0, etree.Comment(f" {comment} "))
    body = etree.tostring(out, encoding="unicode")
    return f'<?xml version="1.0"?>\n{body}\n'


@dataclass(frozen=True)
class Bundle:
    """The three texts of an exported robot, and the mesh files it carries along.

    ``meshes`` maps a path relative to the bundle's folder to the file it copies: the meshes
    the description named by a path of the user's machine (``../meshes/base.stl``), which the
    bundle names relative to itself so that it works wherever it is copied. ``package://``
    meshes stay as they are: the package is the way other tools find them too.
    """

    urdf: str
    srdf: str
    spec: str
    meshes: tuple[tuple[str, Path], ...] = ()


def _carry_meshes(
    tree: etree._Element, folder: str, allowed: set[Path]
) -> tuple[tuple[str, Path], ...]:
    """Point the tree's file-path meshes into ``folder`` (relative); what to copy where.

    Only files the compiled robot resolved (inside the allowed folders, ``allowed``) are
    carried: a description naming ``/home/me/.ssh/id_rsa`` as a mesh was warned about when the
    robot was read and must not ride along into a bundle. One copy per source file; two
    sources with one name get numbered names.
    """
    copies: dict[Path, str] = {}
    taken: set[str] = set()
    for el in tree.iter("mesh"):
        given = el.get("filename")
        if not given or "://" in given and not given.startswith("file://"):
            continue
        source = Path(given.removeprefix("file://")).resolve()
        if source not in allowed:
            continue
        if source not in copies:
            stem, suffix = source.stem, source.suffix
            name, n = f"{stem}{suffix}", 1
            while name.lower() in taken:
                n += 1
                name = f"{stem}_{n}{suffix}"
            taken.add(name.lower())
            copies[source] = f"{folder}/{name}"
        el.set("filename", copies[source])
    return tuple((target, source) for source, target in copies.items())


def _flat_spec_data(result: CompileResult, urdf_name: str, srdf_name: str) -> dict[str, Any]:
    robot = result.robot
    assert robot is not None
    data = result.loaded.spec.model_dump(mode="json", exclude_unset=True)
    data.pop("extends", None)
    data.pop("parts", None)
    data["description"] = {"urdf": urdf_name, "srdf": srdf_name}
    data["root"] = robot.root.name
    # SRDF groups of the sources are not in the exported SRDF: name chains by their links.
    for name, chain in data.get("chains", {}).items():
        if chain.get("group") is not None:
            c = robot.get_chain(name)
            chain.pop("group")
            chain["root"], chain["tip"] = c.root.name, c.tip.name
    # The exported SRDF has the original disabled pairs (and drive); frames are URDF links now.
    return data


def bundle(
    result: CompileResult,
    *,
    name: str,
    package_paths: Sequence[str | Path] = (),
) -> Bundle:
    """URDF, SRDF and spec texts that compile to the same robot as ``result``'s spec.

    ``name`` is the files' stem: ``name.urdf``, ``name.srdf``, ``name.yaml`` in one folder.
    """
    import yaml

    from robotspec.export.srdf import srdf_from_robot, write_srdf

    robot = result.robot
    assert robot is not None
    source = result.loaded.file
    # result.loaded is the flat spec (parts already joined); the tree comes from the source.
    tree = joined_urdf(load_spec(source, allowed=package_paths), package_paths=package_paths)
    resolved = {
        Path(shape.geometry.path).resolve()
        for body in robot.world.bodies
        for shape in (*body.visuals, *body.collisions)
        if isinstance(shape.geometry, Mesh) and shape.geometry.path is not None
    }
    meshes = _carry_meshes(tree, f"{name}_meshes", resolved)
    urdf = urdf_text(tree, comment=f"{robot.name}: exported by robotspec from {source.name}")
    srdf = write_srdf(srdf_from_robot(robot))
    data = _flat_spec_data(result, f"{name}.urdf", f"{name}.srdf")
    head = (
        f"# {robot.name}, exported by robotspec from {source.name}: this spec, {name}.urdf and "
        f"{name}.srdf\n# compile to the same robot without the source files.\n"
    )
    spec = head + yaml.safe_dump(
        data, sort_keys=False, allow_unicode=True, width=100, default_flow_style=None
    )
    return Bundle(urdf=urdf, srdf=srdf, spec=spec, meshes=meshes)
