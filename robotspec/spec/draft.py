"""``robotspec init``: a first spec drafted from a robot's URDF (and SRDF, when there is one).

Why a draft and not a guess presented as fact: which links form an arm, where a tool frame is and
what a camera sees are decisions a person makes once. The draft takes everything the files already
say (SRDF groups, end effectors, the virtual joint, optical frames), marks each guess with a
``# DECIDE:`` comment, and is valid as written, so ``robotspec validate`` works from the start.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from robotspec.description.srdf import Srdf
from robotspec.model.world import Body, World

__all__ = ["Draft", "draft_spec", "render_draft"]

#: Link-name endings that usually mark a tool frame, best first.
TOOL_FRAME_HINTS = ("tool_frame", "tcp", "grasping_frame", "tool0", "end_effector", "ee_link")
#: Fewest actuated joints for a serial path to be proposed as a chain without an SRDF.
MIN_CHAIN_JOINTS = 3
#: A placeholder field of view that validates; every camera carrying it is marked DECIDE.
PLACEHOLDER_FOV = (1.0, 0.75)


@dataclass
class DraftChain:
    """A chain the draft proposes, with where it came from (for the comment)."""

    name: str
    root: str
    tip: str
    source: str
    group: str | None = None
    manipulator: str | None = None
    sensors: list[str] = field(default_factory=list)


@dataclass
class DraftManipulator:
    """An end effector turned into a generic manipulator."""

    name: str
    root: str
    tool_frame: str
    source: str
    tool_frame_guessed: bool


@dataclass
class DraftCamera:
    """An optical frame turned into a camera candidate."""

    name: str
    body: str


@dataclass
class Draft:
    """Everything ``render_draft`` writes; kept separate so tests can look at the decisions."""

    name: str
    urdf: str
    srdf: str | None
    root: str
    drive: tuple[str, str, str] | None  # (type, joint, parent_frame)
    chains: list[DraftChain]
    manipulators: list[DraftManipulator]
    cameras: list[DraftCamera]
    import_states: bool
    notes: list[str]
    package_paths: list[str] = field(default_factory=list)


def _actuated_between(world: World, root: Body, tip: Body) -> int:
    return sum(1 for c in world.compute_chain_of_connections(root, tip) if c.is_active)


def _top_link(world: World, links: Sequence[str]) -> Body | None:
    """The group link that no other group link is above (an end effector's root)."""
    bodies = [world.get_body_by_name(n) for n in links if world.has_body(n)]
    tops = [b for b in bodies if not any(o is not b and world.is_ancestor(o, b) for o in bodies)]
    return min(tops, key=lambda b: world.depth(b)) if tops else None


def _tool_frame(world: World, root: Body) -> tuple[Body, bool]:
    """A named tool frame below ``root`` if the URDF has one; else the root itself (guessed)."""
    below = world.subtree(root)
    for hint in TOOL_FRAME_HINTS:
        for b in below:
            if b.name.endswith(hint):
                return b, False
    return root, True


def _chains_from_srdf(world: World, srdf: Srdf) -> list[DraftChain]:
    out: list[DraftChain] = []
    for g in srdf.groups:
        if len(g.chains) != 1 or g.joints or g.links or g.subgroups:
            continue
        c = g.chains[0]
        if not (world.has_body(c.base_link) and world.has_body(c.tip_link)):
            continue
        base, tip = world.get_body_by_name(c.base_link), world.get_body_by_name(c.tip_link)
        if base is tip or not world.is_ancestor(base, tip):
            continue
        out.append(DraftChain(g.name, base.name, tip.name, f"SRDF group '{g.name}'", g.name))
    return out


def _chains_from_tree(world: World, root: Body) -> list[DraftChain]:
    """Serial paths of actuated joints ending in a leaf, each from its last branching body."""
    out: list[DraftChain] = []
    seen: set[tuple[str, str]] = set()
    inside = world.subtree(root)
    for leaf in inside:
        if world.child_bodies(leaf):
            continue
        # The tip: the child of the last actuated joint on the way up from the leaf.
        tip: Body | None = None
        body = leaf
        while body is not root:
            c = world.parent_connection(body)
            if c is None:
                break
            if c.is_active:
                tip = body
                break
            body = world.bodies[c.parent]
        if tip is None:
            continue
        # The root: walk up until a body with several children (a branch) or the robot root.
        start = tip
        while start is not root:
            c = world.parent_connection(start)
            if c is None:
                break
            parent = world.bodies[c.parent]
            start = parent
            if len(world.child_bodies(parent)) > 1:
                break
        if _actuated_between(world, start, tip) < MIN_CHAIN_JOINTS:
            continue
        key = (start.name, tip.name)
        if key not in seen:
            seen.add(key)
            out.append(DraftChain(f"chain_{len(out) + 1}", start.name, tip.name, "the URDF tree"))
    return out


def draft_spec(
    world: World, *, urdf_ref: str, srdf: Srdf | None, srdf_ref: str | None, name: str
) -> Draft:
    """Decide what the files say and what a person must; see the module docstring."""
    notes: list[str] = []
    root = world.root
    drive: tuple[str, str, str] | None = None
    if srdf is not None:
        vj = next((v for v in srdf.virtual_joints if world.has_body(v.child_link)), None)
        if vj is not None:
            root = world.get_body_by_name(vj.child_link)
            kind = {"planar": "omni", "floating": "floating"}.get(vj.type)
            if kind is not None:
                drive = (kind, vj.name, vj.parent_frame)
    chains = _chains_from_srdf(world, srdf) if srdf is not None else []
    if not chains:
        chains = _chains_from_tree(world, root)
        if chains:
            notes.append("chains were guessed from the URDF tree; rename and check them")
    manipulators: list[DraftManipulator] = []
    if srdf is not None:
        groups = {g.name: g for g in srdf.groups}
        for ee in srdf.end_effectors:
            group = groups.get(ee.group)
            if group is None:
                continue
            links = list(group.links)
            for gc in group.chains:
                links.extend(
                    b.name
                    for b in world.compute_chain_of_kinematic_structure_entities(
                        gc.base_link, gc.tip_link
                    )
                    if world.has_body(gc.base_link) and world.has_body(gc.tip_link)
                )
            top = _top_link(world, links)
            if world.has_body(ee.parent_link):
                parent = world.get_body_by_name(ee.parent_link)
                if top is None or (top is not parent and world.is_ancestor(top, parent)):
                    # The group is the limb itself (Talos' feet: group 'r_leg'), so its top is
                    # the limb's root; the effector starts at its parent link.
                    top = parent
            if top is None:
                continue
            tool, guessed = _tool_frame(world, top)
            m = DraftManipulator(ee.name, top.name, tool.name, "SRDF end effector", guessed)
            manipulators.append(m)
            owner = next(
                (c for c in chains if c.group is not None and c.group == ee.parent_group), None
            )
            if owner is None and world.has_body(ee.parent_link):
                owner = next(
                    (c for c in chains if c.tip == ee.parent_link and c.manipulator is None), None
                )
            if owner is not None and owner.manipulator is None:
                if world.is_ancestor(world.get_body_by_name(owner.tip), top):
                    owner.manipulator = m.name
    if srdf is None or not srdf.end_effectors:
        # No SRDF end effectors: a chain with a named tool frame below its tip gets a
        # manipulator there (UR's tool0, Panda's hand_tcp).
        for c in chains:
            if c.manipulator is not None:
                continue
            tip = world.get_body_by_name(c.tip)
            tool, guessed = _tool_frame(world, tip)
            if guessed:
                continue
            m = DraftManipulator(f"{c.name}_tool", tip.name, tool.name, "tool frame name", False)
            manipulators.append(m)
            c.manipulator = m.name
    cameras = [
        DraftCamera(b.name.removesuffix("_optical_frame") or b.name, b.name)
        for b in world.subtree(root)
        if b.name.endswith("_optical_frame")
    ]
    names: set[str] = set()
    for cam in cameras:
        base = cam.name
        i = 2
        while cam.name in names:
            cam.name = f"{base}_{i}"
            i += 1
        names.add(cam.name)
    # A camera rides on the chain whose tip it sits below (the deepest such chain).
    for cam in cameras:
        body = world.get_body_by_name(cam.body)
        carriers = [c for c in chains if world.is_ancestor(c.tip, body) or c.tip == cam.body]
        if carriers:
            best = max(carriers, key=lambda c: world.depth(c.tip))
            best.sensors.append(cam.name)
    import_states = srdf is not None and bool(srdf.group_states)
    return Draft(
        name=name,
        urdf=urdf_ref,
        srdf=srdf_ref,
        root=root.name,
        drive=drive,
        chains=chains,
        manipulators=manipulators,
        cameras=cameras,
        import_states=import_states,
        notes=notes,
    )


def _q(text: str) -> str:
    """A YAML scalar: plain when safe, else double-quoted."""
    safe = text and all(ch.isalnum() or ch in "_-./:" for ch in text) and not text[0].isdigit()
    return text if safe else '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def render_draft(d: Draft, *, schema_hint: str | None) -> str:
    """The draft as commented YAML, in the order a reader meets a robot."""
    out: list[str] = []
    if schema_hint:
        out.append(f"# yaml-language-server: $schema={schema_hint}")
    out.append(
        f"# Drafted by `robotspec init` from {d.urdf}" + (f" and {d.srdf}" if d.srdf else "")
    )
    out.append("# Lines marked DECIDE are guesses: check them, then delete the mark.")
    for note in d.notes:
        out.append(f"# Note: {note}.")
    out += ["robotspec: 1", f"name: {_q(d.name)}", "description:", f"  urdf: {_q(d.urdf)}"]
    if d.srdf:
        out.append(f"  srdf: {_q(d.srdf)}")
    if d.package_paths:
        out.append("  # Folders holding the packages named above (relative to this file).")
        out.append("  package_paths: [" + ", ".join(_q(p) for p in d.package_paths) + "]")
    out.append(f"root: {_q(d.root)}")
    if d.drive is not None:
        kind, joint, parent = d.drive
        out.append("# From the SRDF's virtual joint.")
        out.append(f"drive: {{type: {kind}, joint: {_q(joint)}, parent_frame: {_q(parent)}}}")
    if d.chains:
        out.append("chains:")
        for c in d.chains:
            out.append(f"  {_q(c.name)}:  # from {c.source}")
            if c.group is not None:
                out.append(f"    group: {_q(c.group)}  # {c.root} -> {c.tip}")
            else:
                out.append(f"    root: {_q(c.root)}  # DECIDE: where the chain starts")
                out.append(f"    tip: {_q(c.tip)}")
            if c.manipulator is None and not c.sensors:
                out.append("    kind: chain  # DECIDE: an arm? give it a manipulator")
            if c.manipulator is not None:
                out.append(f"    manipulator: {_q(c.manipulator)}")
            if c.sensors:
                out.append("    sensors: [" + ", ".join(_q(s) for s in c.sensors) + "]")
    else:
        out.append("chains: {}  # DECIDE: no chain found; add root/tip pairs")
    if d.manipulators:
        out.append("manipulators:")
        for m in d.manipulators:
            out.append(f"  {_q(m.name)}:  # from the {m.source}")
            out.append("    type: generic  # DECIDE: parallel_gripper, with finger and thumb?")
            out.append(f"    root: {_q(m.root)}")
            mark = "  # DECIDE: no tool frame link found; add one under frames:" * (
                m.tool_frame_guessed
            )
            out.append(f"    tool_frame: {_q(m.tool_frame)}{mark}")
            out.append("    front_facing_orientation: [0, 0, 0, 1]  # DECIDE: x forward?")
    if d.cameras:
        out.append("sensors:")
        h, v = PLACEHOLDER_FOV
        for cam in d.cameras:
            out.append(f"  {_q(cam.name)}:")
            out.append("    type: camera")
            out.append(f"    body: {_q(cam.body)}  # an optical frame: looks along +z")
            out.append(
                f"    field_of_view: {{horizontal: {h}, vertical: {v}}}  "
                "# DECIDE: or a preset (robotspec templates)"
            )
    if d.import_states:
        out.append("# The SRDF's group states become named joint states.")
        out.append("import_srdf_group_states: true")
    return "\n".join(out) + "\n"


def portable_ref(
    path: Path, spec_folder: Path, packages: Mapping[str, Path]
) -> tuple[str, Path | None]:
    """A path as the spec should write it, and the package folder the URI relies on.

    Why: a ``package://`` URI works on another machine, a relative path only in this checkout;
    so a file inside a known package is written as a URI (the caller makes sure the spec can
    find that package).
    """
    real = path.resolve()
    best: tuple[int, str, Path] | None = None
    for name, folder in packages.items():
        root = folder.resolve()
        if real.is_relative_to(root):
            depth = len(root.parts)
            if best is None or depth > best[0]:
                best = (depth, f"package://{name}/{real.relative_to(root).as_posix()}", root)
    if best is not None:
        return best[1], best[2]
    return relative_path(real, spec_folder), None


def relative_path(path: Path, spec_folder: Path) -> str:
    """``path`` relative to the spec's folder (absolute when on another drive)."""
    try:
        return Path(os.path.relpath(path.resolve(), spec_folder.resolve())).as_posix()
    except ValueError:  # another drive (Windows)
        return path.resolve().as_posix()
