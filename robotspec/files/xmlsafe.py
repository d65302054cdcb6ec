"""Safe XML parsing for robot descriptions (URDF, xacro output, SRDF, package.xml).

Why: robot files come from anywhere. The parser never expands entities, never touches the
network, never loads a DTD, refuses huge trees, and never "recovers" from broken XML (yourdfpy's
recovering parser silently drops elements). Errors carry the file and lxml's line number.
"""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from robotspec.errors import DescriptionError, RobotSpecError, missing_file

__all__ = ["parse_xml_bytes", "parse_xml_file", "safe_parser"]

#: Robot descriptions are at most a few MB; refuse anything far larger before parsing.
MAX_XML_BYTES = 64 * 1024 * 1024


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
    data: bytes, file: str, error_type: type[RobotSpecError] = DescriptionError
) -> etree._Element:
    """Parse ``data`` (the contents of ``file``) into an lxml element, safely."""
    if len(data) > MAX_XML_BYTES:
        raise error_type(f"XML file larger than {MAX_XML_BYTES} bytes", file=file)
    # Entities are refused before libxml2 sees them: internal entities are expanded inside
    # attribute values whatever the parser options say (billion laughs).
    doctype = data.find(b"<!DOCTYPE")
    if doctype >= 0:
        entity = data.find(b"<!ENTITY", doctype)
        if entity >= 0:
            name = data[entity + 8 : entity + 80].split()[:1]
            shown = name[0].decode("utf-8", "replace") if name else "?"
            raise error_type(
                f"XML entity declarations are not allowed (found '{shown}')",
                file=file,
                line=data.count(b"\n", 0, entity) + 1,
                kind="entity",
                name=shown,
            )
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
    path: str | Path, error_type: type[RobotSpecError] = DescriptionError
) -> etree._Element:
    """Read and parse an XML file safely; a missing or unreadable file is an error of our type."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise missing_file(path, error_type) from None
    except IsADirectoryError:
        raise error_type("is a directory, not an XML file", file=str(path)) from None
    except OSError as exc:
        raise error_type(f"cannot read file: {exc.strerror}", file=str(path)) from None
    return parse_xml_bytes(data, str(path), error_type)
