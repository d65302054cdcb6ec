"""A draft as commented YAML, in the order a reader meets a robot.

Names come from the robot's files, which anyone may have written: a link name may hold a newline,
a quote, a ``#`` or a control character. Every name is therefore written as a plain scalar only
when YAML reads it back as the same string, and double-quoted with escapes otherwise; text in
comments is escaped the same way, so no name can end a comment and start a key.
"""

from __future__ import annotations

import functools
import math
import re
import unicodedata

import yaml

from robotspec.spec.draft.model import Draft, DraftCamera, DraftChain, DraftManipulator, JointState

__all__ = ["SCHEMA_FILE", "camera_presets", "comment", "render_draft", "scalar"]

#: The schema's file name next to the spec (``robotspec schema -o robotspec.schema.json``).
SCHEMA_FILE = "robotspec.schema.json"
#: A placeholder field of view that validates; every camera carrying it is marked DECIDE.
PLACEHOLDER_FOV = (1.0, 0.75)
_PLAIN = re.compile(r"[A-Za-z_][A-Za-z0-9_\-./:]*")
#: Unicode categories YAML must not see raw: controls, formats, surrogates, private, unassigned,
#: and the line/paragraph separators (YAML line breaks).
_ESCAPE_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"})


def _escape_char(ch: str) -> str:
    if ch == "\\":
        return "\\\\"
    if ch == '"':
        return '\\"'
    if unicodedata.category(ch) not in _ESCAPE_CATEGORIES:
        return ch
    code = ord(ch)
    if code <= 0xFF:
        return f"\\x{code:02x}"
    if code <= 0xFFFF:
        return f"\\u{code:04x}"
    return f"\\U{code:08x}"


def scalar(text: str) -> str:
    """``text`` as a YAML scalar that reads back as exactly ``text``."""
    if _PLAIN.fullmatch(text) and len(text) <= 200:
        try:
            if yaml.safe_load(text) == text:
                return text
        except yaml.YAMLError:  # pragma: no cover - a plain word never fails to parse
            pass
    return '"' + "".join(_escape_char(ch) for ch in text) + '"'


def comment(text: str) -> str:
    """Text safe inside a ``#`` comment: one line, no control characters."""
    if text.isascii() and text.isprintable():
        return text  # nothing to escape (the common case; a draft may carry 10^5 notes)
    return "".join(_escape_char(ch) if ch not in '\\"' else ch for ch in text.replace("\n", "\\n"))


@functools.cache
def camera_presets() -> tuple[str, ...]:
    """Names of the camera models a spec's ``preset:`` may name (``templates/cameras.yaml``).

    Read here rather than through the compiler, whose import would double ``init``'s start-up.
    """
    from robotspec.files.yamlio import load_yaml
    from robotspec.shipped import package_data

    data = load_yaml(package_data("templates", "cameras.yaml")).data
    return tuple(str(k) for k in data) if isinstance(data, dict) else ()


def _num(v: float) -> str:
    if not math.isfinite(v):  # never written: states are checked finite before they get here
        raise ValueError(f"not a finite number: {v}")
    if v == int(v) and abs(v) < 1e15:
        return str(int(v))
    return repr(float(v))  # the shortest text that reads back as the same number


def _flow(values: JointState) -> str:
    return "{" + ", ".join(f"{scalar(j)}: {_num(v)}" for j, v in values.items()) + "}"


def _decide(reasons: list[str]) -> str:
    return "  # DECIDE: " + comment("; ".join(reasons)) if reasons else ""


def _states(out: list[str], states: dict[str, JointState], indent: str) -> None:
    if states:
        out.append(f"{indent}states:")
        for name, values in states.items():
            out.append(f"{indent}  {scalar(name)}: {_flow(values)}")


def _chain_body(out: list[str], c: DraftChain, indent: str) -> None:
    if c.group is not None:
        out.append(f"{indent}group: {scalar(c.group)}  # {comment(c.root)} -> {comment(c.tip)}")
    else:
        out.append(f"{indent}root: {scalar(c.root)}")
        out.append(f"{indent}tip: {scalar(c.tip)}")
    if c.role == "leg":
        out.append(f"{indent}kind: leg")
    elif c.role == "chain":
        out.append(f"{indent}kind: chain  # no hand found")
    if c.side is not None:
        out.append(f"{indent}side: {c.side}")
    if c.yaw_body is not None:
        out.append(f"{indent}yaw_body: {scalar(c.yaw_body)}")
    if c.pitch_body is not None:
        out.append(f"{indent}pitch_body: {scalar(c.pitch_body)}")
    if c.manipulator is not None:
        out.append(f"{indent}manipulator: {scalar(c.manipulator)}")
    if c.sensors:
        out.append(f"{indent}sensors: [" + ", ".join(scalar(s) for s in c.sensors) + "]")
    _states(out, c.states, indent)


def _manipulator(out: list[str], m: DraftManipulator) -> None:
    out.append(f"  {scalar(m.name)}:  # from {comment(m.source)}{_decide(m.decide)}")
    kind = "parallel_gripper" if m.is_gripper else "hand" if m.is_hand else "generic"
    out.append(f"    type: {kind}")
    out.append(f"    root: {scalar(m.root)}")
    out.append(f"    tool_frame: {scalar(m.tool_frame)}")
    q = ", ".join(_num(v) for v in m.front_facing)
    why = f"  # {comment(m.facing)}" if m.facing else ""
    out.append(f"    front_facing_orientation: [{q}]{why}")
    for role, f in (("thumb", m.thumb), ("finger", m.finger)):
        if f is not None and (m.is_gripper or m.is_hand):
            out.append(f"    {role}: {{root: {scalar(f.root)}, tip: {scalar(f.tip)}}}")
    if m.is_hand:
        out.append("    fingers:")
        for name, f in m.fingers.items():
            out.append(f"      {scalar(name)}: {{root: {scalar(f.root)}, tip: {scalar(f.tip)}}}")
    _states(out, m.states, "    ")


def _questions(out: list[str], d: Draft, section: str, *, written: bool) -> None:
    """The draft's questions of ``section`` as comments (after the section's entries).

    ``written``: whether the section has entries; otherwise a comment names it first.
    """
    asked = [q for q in d.questions if q.section == section]
    if not asked:
        return
    if not written:
        out.append(f"# {section}: none drafted")
    out += [f"  # DECIDE: {comment(q.text)}" for q in asked]


def render_draft(d: Draft, *, presets: tuple[str, ...] = ()) -> str:
    """The draft as commented YAML; it validates as written (warnings allowed)."""
    out: list[str] = [
        f"# yaml-language-server: $schema={SCHEMA_FILE}",
        f"# (write the schema beside this file: robotspec schema -o {SCHEMA_FILE})",
        f"# Drafted by `robotspec init` from {comment(d.urdf)}"
        + (f" and {comment(d.srdf)}" if d.srdf else ""),
        "# Lines marked DECIDE are guesses: check them, then delete the mark.",
    ]
    out += [f"# Note: {comment(n)}." for n in d.notes]
    out += ["robotspec: 1", f"name: {scalar(d.name)}", "description:"]
    _description(out, d)
    out.append(f"root: {scalar(d.root)}")
    _base(out, d)
    if d.chains:
        out.append("chains:")
        for c in d.chains:
            out.append(f"  {scalar(c.name)}:  # from {comment(c.source)}{_decide(c.decide)}")
            _chain_body(out, c, "    ")
    elif d.lone_hand is not None:
        out.append(f"chains: {{}}  # a hand alone: {comment(d.lone_hand)} is on no chain")
    else:
        out.append("chains: {}  # DECIDE: no arm or leg found; add root/tip pairs")
    _questions(out, d, "chains", written=True)
    if d.manipulators:
        out.append("manipulators:")
        for m in d.manipulators:
            _manipulator(out, m)
    _questions(out, d, "manipulators", written=bool(d.manipulators))
    if d.cameras:
        out.append("sensors:")
        # A preset replaces the whole line (``preset: NAME``); it is not a field_of_view value.
        offer = (
            f"; or replace this line with 'preset: NAME' ({', '.join(presets)})"
            if presets
            else "; or replace this line with 'preset: NAME'"
        )
        for cam in d.cameras:
            _camera(out, cam, offer)
    _questions(out, d, "sensors", written=bool(d.cameras))
    if d.states:
        out.append("states:")
        for name, values in d.states.items():
            out.append(f"  {scalar(name)}: {_flow(values)}")
    if d.lone_hand is not None:
        out.append("accept_warnings:")
        out.append(f"  - at: {scalar('manipulators.' + d.lone_hand)}")
        out.append("    says: is on no chain")
        out.append("    because: a hand alone; the arm it is mounted on carries it")
    return "\n".join(out) + "\n"


def _description(out: list[str], d: Draft) -> None:
    """The ``description:`` block's fields: the files, their packages, the proposed frames."""
    out.append(f"  urdf: {scalar(d.urdf)}")
    if d.srdf:
        out.append(f"  srdf: {scalar(d.srdf)}")
    if d.xacro_args:
        args = ", ".join(f"{scalar(k)}: {scalar(v)}" for k, v in d.xacro_args.items())
        out.append(f"  xacro_args: {{{args}}}")
    if d.package_paths:
        out.append("  # Folders holding the packages named above (relative to this file).")
        out.append("  package_paths: [" + ", ".join(scalar(p) for p in d.package_paths) + "]")
    if d.frames:
        out.append("  frames:")
        for f in d.frames:
            xyz = ", ".join(_num(v) for v in f.xyz)
            out.append(
                f"    {scalar(f.name)}: {{parent: {scalar(f.parent)}, xyz: [{xyz}]}}"
                + (f"  # DECIDE: {comment(f.reason)}" if f.reason else "")
            )


def _base(out: list[str], d: Draft) -> None:
    """The facing, the drive, the torso and the neck."""
    if d.forward is not None:
        fwd = ", ".join(_num(v) for v in d.forward)
        # forward_decide "" is a facing a person decided (robotspec setup): no mark.
        why = "" if d.forward_decide == "" else _decide([d.forward_decide or "the robot's facing"])
        out.append(f"forward: [{fwd}]" + why)
    if d.drive is not None:
        dr = d.drive
        parts = [f"type: {dr.type}"]
        if dr.joint is not None:
            parts.append(f"joint: {scalar(dr.joint)}")
        if dr.parent_frame is not None:
            parts.append(f"parent_frame: {scalar(dr.parent_frame)}")
        if dr.joints is not None:
            parts.append("joints: [" + ", ".join(scalar(j) for j in dr.joints) + "]")
        why = _decide([dr.decide]) if dr.decide else f"  # from {comment(dr.source)}"
        out.append("drive: {" + ", ".join(parts) + "}" + why)
    for key, part in (("torso", d.torso), ("neck", d.neck)):
        if part is not None:
            out.append(f"{key}:  # from {comment(part.source)}{_decide(part.decide)}")
            _chain_body(out, part, "  ")


def _camera(out: list[str], cam: DraftCamera, offer: str) -> None:
    """One camera's entry under ``sensors:`` (``offer``: the presets a user may name)."""
    source = f"  # from {comment(cam.source)}" if cam.source else ""
    out.append(f"  {scalar(cam.name)}:{source}{_decide(cam.decide)}")
    out.append("    type: camera")
    if cam.optical:
        out.append(f"    body: {scalar(cam.body)}  # an optical frame: looks along +z")
    elif cam.axis is not None:
        out.append(f"    body: {scalar(cam.body)}")
        axis = ", ".join(_num(a) for a in cam.axis)
        out.append(f"    forward_facing_axis: [{axis}]  # the view axis the URDF states")
    elif cam.looks_along_z:
        out.append(f"    body: {scalar(cam.body)}")
        out.append("    forward_facing_axis: [0, 0, 1]  # a body frame looking along +z")
    else:
        out.append(f"    body: {scalar(cam.body)}")
        out.append("    forward_facing_axis: [1, 0, 0]  # a body frame: looks along +x")
    if cam.preset is not None:
        out.append(f"    preset: {scalar(cam.preset)}")
    elif cam.field_of_view is not None:
        fh, fv = (_num(a) for a in cam.field_of_view)
        out.append(f"    field_of_view: {{horizontal: {fh}, vertical: {fv}}}")
    else:
        h, v = PLACEHOLDER_FOV
        out.append(
            f"    field_of_view: {{horizontal: {h}, vertical: {v}}}"
            f"  # DECIDE: the camera's angles{offer}"
        )
    if cam.minimal_height is not None:
        out.append(f"    minimal_height: {_num(cam.minimal_height)}")
    if cam.maximal_height is not None:
        out.append(f"    maximal_height: {_num(cam.maximal_height)}")
    if cam.default:
        out.append("    default: true")
