"""Joining URDF element trees: renaming a part's elements and welding it onto the robot.

Why on the element tree and not on the world model: the composed robot is exported as one URDF
that MoveIt, pinocchio and simulators load, and that file must keep everything the parts' files
say (inertias, visuals, transmissions, materials, sensors' ``<gazebo>`` blocks), not only what the
world model keeps. The world is then built from the joined tree like from any URDF.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from lxml import etree

from robotspec.compose.naming import PartNames
from robotspec.description.urdf_walk import parse_floats
from robotspec.model.geometry import Matrix, pose_from_xyz_rpy
from robotspec.model.rotations import matrix_to_rpy

__all__ = [
    "TreeFacts",
    "absolute_mesh_paths",
    "add_fixed_frames",
    "origin_pose",
    "rename_tree",
    "set_origin",
    "tree_facts",
    "weld",
]


@dataclass(frozen=True)
class TreeFacts:
    """What composition needs to know of one part's tree, in the part's own names."""

    links: tuple[str, ...]
    joints: tuple[str, ...]
    roots: tuple[str, ...]
    parent_of: dict[str, str]  # child link -> parent link
    driven_joints: tuple[str, ...]  # actuated, not mimic: what a controller commands
    velocity_limits: dict[str, float]  # joint -> the URDF's velocity limit, where given


def tree_facts(root: etree._Element) -> TreeFacts:
    """Links, joints, root links and parent links of a checked URDF tree."""
    links = tuple(el.get("name", "") for el in root.iterfind("link"))
    joints = tuple(el.get("name", "") for el in root.iterfind("joint"))
    parent_of: dict[str, str] = {}
    driven: list[str] = []
    velocity: dict[str, float] = {}
    for el in root.iterfind("joint"):
        limit = el.find("limit")
        if limit is not None and limit.get("velocity"):
            velocity[el.get("name", "")] = float(limit.get("velocity", "0"))
        child, parent = el.find("child"), el.find("parent")
        if child is not None and parent is not None:
            parent_of[child.get("link", "")] = parent.get("link", "")
        if el.get("type") not in ("fixed", None) and el.find("mimic") is None:
            driven.append(el.get("name", ""))
    roots = tuple(n for n in links if n not in parent_of)
    return TreeFacts(links, joints, roots, parent_of, tuple(driven), velocity)


def origin_pose(el: etree._Element | None) -> Matrix:
    """The 4x4 pose of an element's ``<origin>`` (identity when absent)."""
    origin = None if el is None else el.find("origin")
    if origin is None:
        return np.eye(4)
    # The tree was checked (check_urdf_tree) before composition, so these parse.
    xyz = parse_floats(origin.get("xyz") or "0 0 0", 3, "origin xyz", origin, "")
    rpy = parse_floats(origin.get("rpy") or "0 0 0", 3, "origin rpy", origin, "")
    return np.array(pose_from_xyz_rpy((xyz[0], xyz[1], xyz[2]), (rpy[0], rpy[1], rpy[2])))


def _fmt(values: Iterable[float]) -> str:
    return " ".join(repr(0.0 if abs(v) < 1e-15 else float(v)) for v in values)


def set_origin(el: etree._Element, pose: Matrix) -> None:
    """Write ``pose`` as the element's ``<origin>`` (replacing any), first child like URDFs do."""
    old = el.find("origin")
    if old is not None:
        el.remove(old)
    origin = etree.Element("origin")
    origin.set("xyz", _fmt(pose[:3, 3]))
    origin.set("rpy", _fmt(matrix_to_rpy(pose[:3, :3])))
    el.insert(0, origin)


def rename_tree(root: etree._Element, names: PartNames, materials: dict[str, str]) -> None:
    """Rename every link, joint and material reference of a part's tree in place.

    ``materials`` maps the part's material names to composed ones (chosen by the caller, who
    knows which names other parts already use).
    """
    for el in root.iter("link"):
        el.set("name", names.link(el.get("name", "")))
    for el in root.iter("joint"):
        if el.getparent() is root:
            el.set("name", names.joint(el.get("name", "")))
            for tag in ("parent", "child"):
                ref = el.find(tag)
                if ref is not None:
                    ref.set("link", names.link(ref.get("link", "")))
            mimic = el.find("mimic")
            if mimic is not None:
                mimic.set("joint", names.joint(mimic.get("joint", "")))
    for tr in root.iterfind("transmission"):
        tr.set("name", names.name(tr.get("name", "")))
        for el in tr.iterfind("joint"):
            el.set("name", names.joint(el.get("name", "")))
        for el in tr.iterfind("actuator"):
            el.set("name", names.name(el.get("name", "")))
    for rc in root.iterfind("ros2_control"):
        rc.set("name", names.name(rc.get("name", "")))
        for el in rc.iterfind("joint"):
            el.set("name", names.joint(el.get("name", "")))
    for gz in root.iterfind("gazebo"):
        link_ref = gz.get("reference")
        if link_ref:
            gz.set("reference", names.link(link_ref))
    for el in root.iter("material"):
        name = el.get("name")
        if name and name in materials:
            el.set("name", materials[name])


def absolute_mesh_paths(root: etree._Element, folder: Path) -> None:
    """Make relative mesh paths absolute: the joined file lives elsewhere than the part's.

    ``package://`` URIs stay as written (the composed robot's resolver searches every part's
    package folders); paths and ``file://`` URIs are resolved against the part's own folder.
    """
    for mesh in root.iter("mesh"):
        uri = (mesh.get("filename") or "").strip()
        if not uri or uri.startswith("package://"):
            continue
        path = uri[len("file://") :] if uri.startswith("file://") else uri
        if "://" in path:
            continue  # an unsupported scheme: the world builder reports it
        if not path.startswith("/"):
            mesh.set("filename", str((folder / path).absolute()))


def add_fixed_frames(root: etree._Element, frames: Iterable[tuple[str, str, Matrix]]) -> None:
    """Add frames a spec declares (``description.frames``) as links on fixed joints."""
    for name, parent, pose in frames:
        link = etree.SubElement(root, "link")
        link.set("name", name)
        joint = etree.SubElement(root, "joint")
        joint.set("name", f"{name}_joint")
        joint.set("type", "fixed")
        set_origin(joint, pose)
        etree.SubElement(joint, "parent").set("link", parent)
        etree.SubElement(joint, "child").set("link", name)


def _inertial(el: etree._Element) -> tuple[float, Matrix, Matrix] | None:
    """Mass, centre of mass pose and inertia tensor (in the inertial frame) of a link."""
    inertial = el.find("inertial")
    if inertial is None:
        return None
    mass_el = inertial.find("mass")
    mass = float(mass_el.get("value", "0")) if mass_el is not None else 0.0
    pose = origin_pose(inertial)
    i = inertial.find("inertia")
    t = np.zeros((3, 3))
    if i is not None:
        v = {k: float(i.get(k, "0")) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        t = np.array(
            [
                [v["ixx"], v["ixy"], v["ixz"]],
                [v["ixy"], v["iyy"], v["iyz"]],
                [v["ixz"], v["iyz"], v["izz"]],
            ]
        )
    return mass, pose, t


def _combined_inertial(
    a: tuple[float, Matrix, Matrix], b: tuple[float, Matrix, Matrix], b_in_a: Matrix
) -> etree._Element:
    """One ``<inertial>`` for two rigidly joined bodies (parallel-axis theorem), in a's frame."""
    (ma, pa, ia), (mb, pb, ib) = a, b
    pb = b_in_a @ pb
    m = ma + mb
    ca, cb = pa[:3, 3], pb[:3, 3]
    c = (ma * ca + mb * cb) / m if m > 0 else ca
    total = np.zeros((3, 3))
    for mass, pose, tensor, com in ((ma, pa, ia, ca), (mb, pb, ib, cb)):
        r = pose[:3, :3]
        d = com - c
        total += r @ tensor @ r.T + mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
    out = etree.Element("inertial")
    origin = np.eye(4)
    origin[:3, 3] = c
    set_origin(out, origin)
    etree.SubElement(out, "mass").set("value", f"{m:.12g}")
    inertia = etree.SubElement(out, "inertia")
    for key, (i, j) in {
        "ixx": (0, 0),
        "ixy": (0, 1),
        "ixz": (0, 2),
        "iyy": (1, 1),
        "iyz": (1, 2),
        "izz": (2, 2),
    }.items():
        inertia.set(key, f"{total[i, j]:.12g}")
    return out


def weld(
    robot: etree._Element,
    part: etree._Element,
    *,
    parent_link: str,
    part_root: str,
    pose: Matrix,
    joint_name: str,
    replace_root: bool,
) -> None:
    """Move a (renamed) part's elements into ``robot``, welded to ``parent_link`` at ``pose``.

    With ``replace_root`` the part's root link disappears: its child joints start at
    ``parent_link`` (their origins composed with ``pose``) and its visuals, collisions and mass
    move onto ``parent_link``, so the robot's dynamics do not change.
    """
    links = {el.get("name"): el for el in robot.iterfind("link")}
    target = links[parent_link]
    if replace_root:
        root_el = next(el for el in part.iterfind("link") if el.get("name") == part_root)
        for tag in ("visual", "collision"):
            for el in root_el.iterfind(tag):
                moved = copy.deepcopy(el)
                set_origin(moved, pose @ origin_pose(el))
                target.append(moved)
        mine, theirs = _inertial(target), _inertial(root_el)
        if theirs is not None and theirs[0] > 0:
            old = target.find("inertial")
            if mine is None:
                moved_inertial = copy.deepcopy(root_el.find("inertial"))
                assert moved_inertial is not None
                set_origin(moved_inertial, pose @ theirs[1])
                target.append(moved_inertial)
            else:
                if old is not None:
                    target.remove(old)
                target.append(_combined_inertial(mine, theirs, pose))
        part.remove(root_el)
        for el in part.iterfind("joint"):
            ref = el.find("parent")
            if ref is not None and ref.get("link") == part_root:
                ref.set("link", parent_link)
                set_origin(el, pose @ origin_pose(el))
    else:
        joint = etree.Element("joint")
        joint.set("name", joint_name)
        joint.set("type", "fixed")
        set_origin(joint, pose)
        etree.SubElement(joint, "parent").set("link", parent_link)
        etree.SubElement(joint, "child").set("link", part_root)
        robot.append(joint)
    for el in list(part):
        if isinstance(el.tag, str):  # comments and processing instructions stay behind
            robot.append(el)
