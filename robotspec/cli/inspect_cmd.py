"""``robotspec inspect``: tables of a compiled robot's chains, tree, parts, joints and SRDF."""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import typer

from robotspec.cli.notes import print_notes
from robotspec.cli.options import JsonFlag, PackagePath, SpecArg, load_robot
from robotspec.cli.table import emit_table

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


inspect_app = typer.Typer(help="Show what a spec compiles to.", no_args_is_help=True)
app.add_typer(inspect_app, name="inspect")


@inspect_app.command("chains")
def chains(spec: SpecArg, as_json: JsonFlag = False, package_path: PackagePath = None) -> None:
    """The robot's kinematic chains: kind, root, tip, joints, DOF, manipulator, sensors."""
    from robotspec.cli.chain_table import print_chains

    robot = load_robot(spec, package_path)
    print_notes(robot)
    print_chains(robot, as_json=as_json)


@inspect_app.command("manipulators")
def manipulators(
    spec: SpecArg, as_json: JsonFlag = False, package_path: PackagePath = None
) -> None:
    """Manipulators: root, tool frame, front-facing orientation and axis, fingers, states."""
    from robotspec.semantic import Hand, ParallelGripper

    robot = load_robot(spec, package_path)
    items = []
    for m in robot.manipulators:
        item: dict[str, Any] = {
            "name": m.name,
            "type": "parallel_gripper"
            if isinstance(m, ParallelGripper)
            else "hand"
            if isinstance(m, Hand)
            else "generic",
            "root": m.root.name,
            "tool_frame": m.tool_frame.name,
            "front_facing_orientation": list(m.front_facing_orientation),
            "front_facing_axis": list(m.front_facing_axis),
            "thumb": m.thumb.tip.name if isinstance(m, (ParallelGripper, Hand)) else None,
            "finger": m.finger.tip.name
            if isinstance(m, ParallelGripper)
            else ", ".join(f.tip.name for f in m.fingers.values())
            if isinstance(m, Hand)
            else None,
            "states": sorted(m.states),
        }
        items.append(item)
    rows = [
        [
            i["name"],
            i["type"],
            i["root"],
            i["tool_frame"],
            _vec(i["front_facing_orientation"]),
            _vec(i["front_facing_axis"]),
            ", ".join(i["states"]) or None,
        ]
        for i in items
    ]
    headers = [
        "manipulator",
        "type",
        "root",
        "tool frame",
        "front orientation",
        "front axis",
        "states",
    ]
    emit_table(items, headers, rows, as_json)


@inspect_app.command("sensors")
def sensors(spec: SpecArg, as_json: JsonFlag = False, package_path: PackagePath = None) -> None:
    """Sensors: body, viewing axis, field of view and height range of cameras."""
    from robotspec.semantic import Camera

    robot = load_robot(spec, package_path)
    items = []
    for s in robot.sensors:
        item: dict[str, Any] = {
            "name": s.name,
            "type": type(s).__name__.lower(),
            "body": s.root.name,
        }
        if isinstance(s, Camera):
            item |= {
                "forward_facing_axis": list(s.forward_facing_axis),
                "field_of_view": {
                    "horizontal": s.field_of_view.horizontal_angle,
                    "vertical": s.field_of_view.vertical_angle,
                },
                "minimal_height": s.minimal_height,
                "maximal_height": s.maximal_height,
                "default": s.default_camera,
            }
        items.append(item)
    rows = []
    for i in items:
        fov = i.get("field_of_view")
        rows.append(
            [
                i["name"] + (" *" if i.get("default") else ""),
                i["type"],
                i["body"],
                _vec(i["forward_facing_axis"]) if "forward_facing_axis" in i else None,
                f"{fov['horizontal']:.4g} x {fov['vertical']:.4g}" if fov else None,
                f"{i['minimal_height']:g}-{i['maximal_height']:g}" if fov else None,
            ]
        )
    emit_table(items, ["sensor", "type", "body", "axis", "fov (rad)", "height (m)"], rows, as_json)


@inspect_app.command("joints")
def joints(spec: SpecArg, as_json: JsonFlag = False, package_path: PackagePath = None) -> None:
    """The robot's moving joints with limits; velocities tightened by the spec end in '*'."""
    robot = load_robot(spec, package_path)
    print_notes(robot)
    w = robot.world
    tightened = w.loaded_velocity_limits
    items = []
    for c in robot.connections:
        if c.is_fixed:
            continue
        dof = w.degrees_of_freedom[c.dofs[0]] if c.dofs else None
        item: dict[str, Any] = {
            "name": c.name,
            "type": c.type.value,
            "mimic": None if c.mimic is None else c.mimic.leader,
            "lower": None if dof is None or c.mimic else _num(dof.lower),
            "upper": None if dof is None or c.mimic else _num(dof.upper),
            "velocity": None if dof is None or c.mimic else _num(dof.velocity),
            "tightened": bool(dof is not None and not c.mimic and dof.name in tightened),
            "controlled": c in robot.controlled_connections,
        }
        items.append(item)
    rows = [
        [
            i["name"],
            i["type"] + (f" (mimics {i['mimic']})" if i["mimic"] else ""),
            i["lower"],
            i["upper"],
            None
            if i["velocity"] is None
            else f"{i['velocity']:g}" + ("*" if i["tightened"] else ""),
        ]
        for i in items
    ]
    emit_table(items, ["joint", "type", "lower", "upper", "velocity"], rows, as_json)


@inspect_app.command("groups")
def groups(spec: SpecArg, as_json: JsonFlag = False, package_path: PackagePath = None) -> None:
    """The SRDF's groups, end effectors and group states."""
    robot = load_robot(spec, package_path)
    srdf = robot.srdf
    if srdf is None:
        sys.stdout.write("this robot has no SRDF\n")
        return
    items: dict[str, list[dict[str, Any]]] = {
        "groups": [
            {
                "name": g.name,
                "chains": [[c.base_link, c.tip_link] for c in g.chains],
                "joints": list(g.joints),
                "links": list(g.links),
                "subgroups": list(g.subgroups),
            }
            for g in srdf.groups
        ],
        "end_effectors": [
            {"name": e.name, "parent_link": e.parent_link, "group": e.group}
            for e in srdf.end_effectors
        ],
        "group_states": [{"name": s.name, "group": s.group} for s in srdf.group_states],
    }
    rows = [["group", g["name"], _group_text(g)] for g in items["groups"]]
    rows += [
        ["end_effector", e["name"], f"{e['parent_link']} (group {e['group']})"]
        for e in items["end_effectors"]
    ]
    rows += [["group_state", s["name"], f"group {s['group']}"] for s in items["group_states"]]
    emit_table(items, ["element", "name", "content"], rows, as_json)


def _group_text(g: dict[str, Any]) -> str:
    parts = [f"chain {a} -> {b}" for a, b in g["chains"]]
    if g["joints"]:
        parts.append(f"{len(g['joints'])} joints")
    if g["links"]:
        parts.append(f"{len(g['links'])} links")
    if g["subgroups"]:
        parts.append("groups " + ", ".join(g["subgroups"]))
    return "; ".join(parts) or "(empty)"


@inspect_app.command("collisions")
def collisions(spec: SpecArg, as_json: JsonFlag = False, package_path: PackagePath = None) -> None:
    """Disabled collision pairs (by SRDF reason) and disabled bodies."""
    robot = load_robot(spec, package_path)
    print_notes(robot)
    reasons: dict[str, int] = {}
    if robot.srdf is not None:
        for d in robot.srdf.disabled_collisions:
            if frozenset((d.link1, d.link2)) in robot.disabled_collision_pairs:
                reasons[d.reason or "(none)"] = reasons.get(d.reason or "(none)", 0) + 1
    items: dict[str, Any] = {
        "disabled_pairs": len(robot.disabled_collision_pairs),
        "by_reason": reasons,
        "disabled_bodies": sorted(robot.disabled_collision_bodies),
        "buffer_distance": robot.default_collision_config.buffer_zone_distance,
    }
    rows = [["reason " + k, v] for k, v in sorted(reasons.items())]
    rows.append(["disabled pairs (total)", items["disabled_pairs"]])
    rows.append(["disabled bodies", ", ".join(items["disabled_bodies"]) or None])
    rows.append(["buffer distance (m)", items["buffer_distance"]])
    emit_table(items, ["what", "value"], rows, as_json)


@inspect_app.command("tree")
def tree(spec: SpecArg, as_json: JsonFlag = False, package_path: PackagePath = None) -> None:
    """The kinematic tree with joint types, limits and semantic labels."""
    robot = load_robot(spec, package_path)
    w = robot.world
    labels: dict[str, list[str]] = {}

    def label(body: str, text: str) -> None:
        labels.setdefault(body, []).append(text)

    label(robot.root.name, "robot root")
    for chain in robot.all_chains:
        label(chain.root.name, f"{chain.name} root")
        label(chain.tip.name, f"{chain.name} tip")
    for m in robot.manipulators:
        label(m.tool_frame.name, f"{m.name} tool frame")
    for s in robot.sensors:
        label(s.root.name, f"sensor {s.name}")
    if as_json:
        nodes = []
        for b in w.bodies:
            c = w.parent_connection(b)
            nodes.append(
                {
                    "body": b.name,
                    "parent": None if c is None else w.bodies[c.parent].name,
                    "joint": None if c is None else c.name,
                    "type": None if c is None else c.type.value,
                    "labels": labels.get(b.name, []),
                }
            )
        sys.stdout.write(json.dumps(nodes, indent=2) + "\n")
        return
    sys.stdout.write(
        f"{robot.name}: {len(w.bodies)} bodies, {len(w.connections)} joints, "
        f"{len(w.degrees_of_freedom)} degrees of freedom\n"
    )
    sys.stdout.write(tree_text(w, labels) + "\n")


def tree_text(w: Any, labels: dict[str, list[str]]) -> str:
    """An indented tree drawing of a world, one body per line."""
    lines: list[str] = []

    def joint_text(b: Any) -> str:
        c = w.parent_connection(b)
        if c is None:
            return ""
        text = c.type.value
        if c.mimic is not None:
            text += f", mimics {c.mimic.leader}"
        elif c.dofs and c.type.dof_count == 1:
            d = w.degrees_of_freedom[c.dofs[0]]
            if math.isfinite(d.lower):
                text += f" [{d.lower:.4g}, {d.upper:.4g}]"
        return f"  ({c.name}: {text})"

    # An explicit stack, not recursion: a valid 2,000-joint chain is as deep as it is long.
    stack: list[tuple[Any, str, bool, bool]] = [(w.root, "", True, True)]
    while stack:
        b, prefix, last, top = stack.pop()
        tag = "" if b.name not in labels else "  <" + "; ".join(labels[b.name]) + ">"
        branch = "" if top else ("└── " if last else "├── ")
        lines.append(f"{prefix}{branch}{b.name}{joint_text(b)}{tag}")
        kids = w.child_bodies(b)
        inner = prefix if top else prefix + ("    " if last else "│   ")
        for i in reversed(range(len(kids))):
            stack.append((kids[i], inner, i == len(kids) - 1, False))
    return "\n".join(lines)


def _vec(v: list[float]) -> str:
    return "[" + ", ".join(f"{x:.4g}" for x in v) + "]"


def _num(x: float) -> float | None:
    return x if math.isfinite(x) else None


@inspect_app.command("parts")
def parts(spec: SpecArg, as_json: JsonFlag = False, package_path: PackagePath = None) -> None:
    """The parts of a composed robot: source, prefix, where each is welded, what it brings."""
    from robotspec.compiler import resolve_spec
    from robotspec.compose import compose
    from robotspec.spec.load import load_spec

    loaded = load_spec(resolve_spec(spec), allowed=package_path or ())
    if not loaded.spec.parts:
        sys.stderr.write(f"{loaded.file.name} is not composed of parts (it has no 'parts:')\n")
        raise typer.Exit(1)
    composition = compose(loaded, package_paths=package_path or ())
    data = []
    for p in composition.parts:
        ps = loaded.spec.parts[p.name]
        at = ps.attach
        data.append(
            {
                "part": p.name,
                "source": ps.spec or ps.urdf,
                "prefix": p.names.prefix,
                "attached_to": None if at is None else f"{at.part}/{at.link}",
                "weld": p.weld_joint or ("root replaced" if at is not None else None),
                "root_link": p.root_link,
                "links": len(p.links),
                "joints": len(p.joints),
            }
        )
    rows = [
        [
            d["part"],
            d["source"],
            d["prefix"] or "-",
            d["attached_to"] or "(base)",
            d["weld"] or "-",
            d["root_link"],
            d["links"],
            d["joints"],
        ]
        for d in data
    ]
    headers = ["part", "source", "prefix", "attached to", "weld", "root link", "links", "joints"]
    emit_table(data, headers, rows, as_json)
