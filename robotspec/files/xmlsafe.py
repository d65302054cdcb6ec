"""Safe XML parsing for robot descriptions (URDF, xacro output, SRDF, package.xml).

Why: robot files come from anywhere. The parser never expands entities, never touches the
network, never loads a DTD, refuses huge trees, and never "recovers" from broken XML (yourdfpy's
recovering parser silently drops elements). Errors carry the file and lxml's line number.
"""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from robotspec.errors import DescriptionError, RobotSpecError
from robotspec.files.limits import env_name, limits
from robotspec.files.reading import read_bounded, refuse_entities

__all__ = ["parse_xml_bytes", "parse_xml_file", "safe_parser"]


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
    try:
        root: etree._Element | None = etree.fromstring(data, parser=safe_parser())
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
