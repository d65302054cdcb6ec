"""Safe XML parsing for robot descriptions (URDF, xacro output, SRDF, package.xml).

Why: robot files come from anywhere. The parser never expands entities, never touches the
network, never loads a DTD, refuses huge trees, and never "recovers" from broken XML (yourdfpy's
recovering parser silently drops elements). Errors carry the file and lxml's line number.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from lxml import etree

from robotspec.errors import DescriptionError, RobotSpecError
from robotspec.files.limits import env_name, limits
from robotspec.files.reading import read_bounded, refuse_entities

__all__ = [
    "UNDECLARED_NAMESPACE",
    "parse_xml_bytes",
    "parse_xml_file",
    "safe_parser",
    "undeclared_prefixes",
]

#: The namespace URI prefix given to XML prefixes a file uses without declaring them (Drake
#: writes ``drake:`` elements and attributes into URDFs without ``xmlns:drake``). urdfdom and
#: pinocchio read such files; the extension elements are unknown to URDF and ignored anyway.
UNDECLARED_NAMESPACE = "urn:robotspec:undeclared:"

#: An XML declaration naming a version libxml2 refuses (``<?xml version="0.0"?>``, written by
#: some exporters): urdfdom and pybullet read such files, so the version is read as 1.0.
_DECLARED_VERSION = re.compile(
    rb"""\A(\s*<\?xml\s+version\s*=\s*["'])(?!1\.[01]["'])[^"'<>]{0,16}(["'])"""
)
_UNDECLARED = re.compile(r"Namespace prefix ([A-Za-z_][\w.-]*) (?:for \S+ )?on \S+ is not defined")
_MAX_UNDECLARED = 64  # prefixes declared for a file; more is not a robot description


def safe_parser() -> etree.XMLParser:
    """A fresh lxml parser with entity expansion, DTD loading and network access off."""
    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        dtd_validation=False,
        huge_tree=False,
        recover=False,
        remove_comments=False,
        remove_pis=True,
    )


def line_of(el: etree._Element) -> int | None:
    """The element's source line; lxml-stubs mistype ``sourceline``, lxml gives int or None."""
    line: object = el.sourceline
    return line if isinstance(line, int) else None


def _check_no_entities(root: etree._Element, file: str) -> None:
    """Refuse documents that declare entities at all (billion laughs, external entities)."""
    tree = root.getroottree()
    docinfo = tree.docinfo
    internal = docinfo.internalDTD
    if internal is not None:
        for decl in internal.iterentities():  # type: ignore[attr-defined]
            raise DescriptionError(
                f"XML entity declarations are not allowed (found '{decl.name}')",
                file=file,
                kind="entity",
                name=decl.name,
            )
    for el in root.iter():
        if isinstance(el, etree._Entity):
            raise DescriptionError(
                f"XML entity references are not allowed (found '&{el.name};')",
                file=file,
                line=line_of(el),
                kind="entity",
                name=el.name,
            )


def parse_xml_bytes(
    data: bytes,
    file: str,
    error_type: type[RobotSpecError] = DescriptionError,
    *,
    cap: int | None = None,
    cap_name: str = "max_urdf_bytes",
) -> etree._Element:
    """Parse ``data`` (the contents of ``file``) into an lxml element, safely.

    ``cap`` (default: the URDF cap) bounds documents that did not come through
    :func:`~robotspec.files.reading.read_bounded`, such as a xacro expansion's output.
    """
    limit = getattr(limits(), cap_name) if cap is None else cap
    if len(data) > limit:
        raise error_type(
            f"XML document larger than {limit} bytes (set {env_name(cap_name)} to raise it)",
            file=file,
            kind="size",
        )
    refuse_entities(data, file, error_type)
    data = _DECLARED_VERSION.sub(rb"\g<1>1.0\g<2>", data, count=1)
    try:
        root: etree._Element | None = _parse_declaring_prefixes(data)
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if exc.lineno and exc.lineno > 0 else None
        col = exc.offset if exc.offset and exc.offset > 0 else None
        msg = str(exc.msg) if getattr(exc, "msg", None) else str(exc)
        # lxml appends "(<string>, line N)"; the position is reported separately.
        msg = msg.split(", line ")[0].rstrip(" (")
        raise error_type(f"malformed XML: {msg}", file=file, line=line, column=col) from None
    if root is None:
        raise error_type("empty XML document", file=file)
    _check_no_entities(root, file)
    return root


def _parse_declaring_prefixes(data: bytes) -> etree._Element | None:
    """Parse; where the only faults are undeclared prefixes, declare them on the root and retry.

    Why: libxml2 reports every undeclared prefix and otherwise parses on, so one retry with
    ``xmlns:PREFIX="urn:robotspec:undeclared:PREFIX"`` added to the root's start tag reads the
    file as urdfdom does. A file with any other fault is refused with that fault (the retry's).
    """
    parser = safe_parser()
    try:
        return etree.fromstring(data, parser=parser)
    except etree.XMLSyntaxError:
        prefixes: dict[str, None] = {}
        log: Any = parser.error_log  # this parse's own (the exception's may hold older ones)
        for entry in log:
            found = _UNDECLARED.fullmatch(entry.message)
            if entry.type_name == "NS_ERR_UNDEFINED_NAMESPACE" and found is not None:
                prefixes[found.group(1)] = None
        at = _root_name_end(data)
        if not prefixes or len(prefixes) > _MAX_UNDECLARED or at is None:
            raise
        declared = b"".join(
            f' xmlns:{p}="{UNDECLARED_NAMESPACE}{p}"'.encode("ascii") for p in prefixes
        )
        try:
            return etree.fromstring(data[:at] + declared + data[at:], parser=safe_parser())
        except etree.XMLSyntaxError as retry:
            # The declarations went onto the root's line: later columns there shift back.
            line = data.count(b"\n", 0, at) + 1
            column = at - data.rfind(b"\n", 0, at)
            if retry.lineno == line and retry.offset and retry.offset > column:
                retry.offset -= len(declared)
            raise


_NAME = re.compile(rb"[A-Za-z_:][\w.:-]*")


def _root_name_end(data: bytes) -> int | None:
    """The offset just past the root element's name in its start tag (ASCII-compatible text)."""
    pos = 0
    while True:
        i = data.find(b"<", pos)
        if i < 0:
            return None
        if data.startswith(b"<!--", i):
            pos = data.find(b"-->", i + 4)
            pos = -1 if pos < 0 else pos + 3
        elif data.startswith(b"<?", i):
            pos = data.find(b"?>", i + 2)
            pos = -1 if pos < 0 else pos + 2
        elif data.startswith(b"<!", i):
            pos = data.find(b">", i + 2)
            pos = -1 if pos < 0 else pos + 1
        else:
            name = _NAME.match(data, i + 1)
            return None if name is None else name.end()
        if pos < 0:
            return None


def undeclared_prefixes(root: etree._Element) -> list[str]:
    """The prefixes :func:`parse_xml_bytes` declared for ``root``'s file (empty: none)."""
    return [
        prefix
        for prefix, uri in (root.nsmap or {}).items()
        if prefix and uri and uri.startswith(UNDECLARED_NAMESPACE)
    ]


def parse_xml_file(
    path: str | Path,
    error_type: type[RobotSpecError] = DescriptionError,
    *,
    cap_name: str = "max_urdf_bytes",
    what: str = "an XML file",
) -> etree._Element:
    """Read (bounded, regular files only) and parse an XML file safely."""
    cap = getattr(limits(), cap_name)
    data = read_bounded(path, cap=cap, cap_name=cap_name, what=what, error_type=error_type)
    return parse_xml_bytes(data, str(path), error_type, cap=cap, cap_name=cap_name)
