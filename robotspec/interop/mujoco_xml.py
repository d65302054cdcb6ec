"""The added elements written into the user's own MJCF text, and nothing else of it touched.

Why not MuJoCo's ``MjSpec.to_xml``: it rewrites the whole model with six significant digits
(Menagerie's ``0.9238795`` becomes ``0.92388``), expands what defaults and includes held, and
drops comments, so the user's tuned file would change everywhere. Here their file is parsed with
robotspec's safe parser (no entities, no network), each site, camera, keyframe and exclude is
appended where it belongs with full-precision numbers, and the text is serialized back with
their comments, order and numbers as they were. Relative asset paths are re-pointed only when
the output goes to another folder (and a note says so).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from lxml import etree

from robotspec.errors import RobotSpecError
from robotspec.export.mjcf_bodies import num, nums
from robotspec.files.xmlsafe import parse_xml_file

__all__ = ["Edit", "write_edits"]


@dataclass(frozen=True)
class Edit:
    """One element to add: ``tag`` (site, camera, key, exclude), where, and its attributes."""

    tag: str
    body: str | None
    attrib: tuple[tuple[str, str], ...]


def _clean(values: object) -> str:
    rounded = np.round(np.asarray(values, dtype=np.float64), 12) + 0.0  # + 0.0: no "-0"
    return nums([float(v) for v in rounded])


def site_edit(tag: str, body: str, name: str, pos: object, quat: object, **extra: float) -> Edit:
    """A site or camera in ``body`` at ``pos``/``quat`` (full precision), with ``extra``."""
    # Rounded at 1e-12 (m, or of a unit quaternion): FK's last-bit noise is no information.
    attrib = [("name", name), ("pos", _clean(pos)), ("quat", _clean(quat))]
    attrib += [(k, num(v)) for k, v in extra.items()]
    return Edit(tag, body, tuple(attrib))


def _body(root: etree._Element, name: str, shown: str) -> etree._Element:
    if name == "world":
        found = root.find("worldbody")
    else:
        found = next((b for b in root.iter("body") if b.get("name") == name), None)
    if found is None:
        raise RobotSpecError(
            f"body '{name}' is not written in this file (it comes from an <include> or an "
            "attached model): annotate the file that defines it",
            file=shown,
            kind="body",
            name=name,
        )
    return found


def _section(root: etree._Element, tag: str) -> etree._Element:
    found = root.find(tag)
    if found is None:
        found = _append(root, tag, {})
    return found


def _repoint(root: etree._Element, here: Path, there: Path, notes: list[str]) -> None:
    """Relative asset folders and includes made relative to ``there`` instead of ``here``."""

    def rel(value: str) -> str:
        return os.path.relpath(here / value, there)

    compilers = root.findall("compiler")
    compiler = compilers[0] if compilers else etree.Element("compiler")
    if not compilers:
        root.insert(0, compiler)
    assetdir = compiler.get("assetdir")
    for attr in ("meshdir", "texturedir"):
        value = compiler.get(attr) or assetdir or ""
        if not os.path.isabs(value):
            compiler.set(attr, rel(value))
    if assetdir is not None and not os.path.isabs(assetdir):
        compiler.set("assetdir", rel(assetdir))
    for inc in root.iter("include", "model"):
        file = inc.get("file")
        if file and not os.path.isabs(file):
            inc.set("file", rel(file))
    notes.append(
        f"the output is in another folder than the model: asset folders and includes are "
        f"re-pointed to {os.path.relpath(here, there)}"
    )


def _indent_of(el: etree._Element) -> str:
    """A line break and the indentation ``el`` itself sits at."""
    prev, up = el.getprevious(), el.getparent()
    space = prev.tail if prev is not None else (up.text if up is not None else None)
    return "\n" + (space or "\n").rsplit("\n", 1)[-1]


def _append(parent: etree._Element, tag: str, attrib: dict[str, str]) -> etree._Element:
    """``<tag>`` as the last child of ``parent``, indented like its siblings."""
    el = etree.Element(tag, attrib)
    if len(parent):
        last = parent[-1]
        el.tail, last.tail = last.tail, parent.text
    else:
        outer = _indent_of(parent)
        parent.text = outer + "  "
        el.tail = outer
    parent.append(el)
    return el


def write_edits(path: Path, edits: list[Edit], output: Path | None, notes: list[str]) -> str:
    """Their file's text with ``edits`` appended, re-pointed for ``output``'s folder."""
    root = parse_xml_file(path, what="an MJCF file")
    if root.tag != "mujoco":
        raise RobotSpecError(
            f"the root element is <{root.tag}>, not <mujoco>: annotate an MJCF file",
            file=str(path),
            kind="model",
        )
    for e in edits:
        if e.tag in ("site", "camera"):
            assert e.body is not None
            parent = _body(root, e.body, str(path))
        elif e.tag == "key":
            parent = _section(root, "keyframe")
        else:
            parent = _section(root, "contact")
        _append(parent, e.tag, dict(e.attrib))
    here = path.resolve().parent
    if output is not None and output.resolve().parent != here:
        _repoint(root, here, output.resolve().parent, notes)
    return etree.tostring(root, encoding="unicode") + "\n"
