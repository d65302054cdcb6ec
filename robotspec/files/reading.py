"""The one way robotspec reads a file: regular files only, up to a cap, errors located.

Why one reader: YAML, URDF, SRDF, xacro includes and meshes all come from untrusted places.
``Path.read_bytes`` on ``/dev/zero`` reads until memory runs out, and on a FIFO it blocks
forever. Here the file is opened without blocking, checked to be a regular file on the open
descriptor (no race with a swapped path), and read up to its cap plus one byte, so an oversized
file is refused without being read whole. Every failure is an error of the caller's type naming
the file. The XML entity guard lives here too, because both the XML parser and xacro need it.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from robotspec.errors import RobotSpecError, missing_file
from robotspec.files.limits import env_name

__all__ = ["read_bounded", "read_head", "refuse_entities"]


def read_bounded(
    path: str | Path,
    *,
    cap: int,
    cap_name: str,
    what: str,
    error_type: type[RobotSpecError] = RobotSpecError,
) -> bytes:
    """The bytes of the regular file ``path``, at most ``cap`` of them.

    Args:
        path: The file to read.
        cap: Largest accepted size in bytes.
        cap_name: The :class:`~robotspec.files.limits.Limits` field of the cap, named in the
            message so the user knows which variable raises it.
        what: What the file should be ("a YAML file"), for the not-a-file message.
        error_type: The error class the caller's users expect.
    """
    shown = str(path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise missing_file(path, error_type) from None
    except IsADirectoryError:
        raise error_type(f"is a directory, not {what}", file=shown, kind="file") from None
    except OSError as exc:
        raise error_type(_reason(exc), file=shown, kind="file") from None
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise error_type(f"is a directory, not {what}", file=shown, kind="file")
        if not stat.S_ISREG(info.st_mode):
            raise error_type(
                f"is not a regular file (a device, FIFO or socket), not {what}",
                file=shown,
                kind="file",
            )
        if info.st_size > cap:
            raise _too_large(shown, cap, cap_name, error_type)
        chunks: list[bytes] = []
        total = 0
        while True:
            chunk = os.read(fd, min(1 << 20, cap + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > cap:  # the file grew while it was read
                raise _too_large(shown, cap, cap_name, error_type)
        return b"".join(chunks)
    except OSError as exc:
        raise error_type(_reason(exc), file=shown, kind="file") from None
    finally:
        os.close(fd)


def read_head(path: str | Path, size: int) -> bytes | None:
    """The first ``size`` bytes of a regular file, or ``None`` if it cannot be read as one.

    For peeking (a ``package.xml``'s name, a line number for a message), where a missing or
    odd file is not an error of its own.
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(path, flags)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        return os.read(fd, size)
    except OSError:
        return None
    finally:
        os.close(fd)


def _reason(exc: OSError) -> str:
    if exc.errno == errno.ELOOP:
        return "cannot read file: too many levels of symbolic links"
    return f"cannot read file: {exc.strerror or type(exc).__name__}"


def _too_large(file: str, cap: int, cap_name: str, error_type: type[RobotSpecError]) -> Exception:
    return error_type(
        f"file larger than {cap} bytes (the cap for this kind of file; "
        f"set {env_name(cap_name)} to raise it)",
        file=file,
        kind="size",
    )


def _decoded_head(data: bytes) -> bytes:
    """The document as ASCII-compatible bytes, whatever its declared encoding.

    Why: an included xacro starting with a UTF-8 BOM, or written in UTF-16, hid its
    ``<!ENTITY`` from a byte search.
    """
    if data.startswith(b"\xef\xbb\xbf"):
        return data[3:]
    if data[:2] in (b"\xff\xfe", b"\xfe\xff") or (len(data) > 1 and (data[0] == 0 or data[1] == 0)):
        for codec in ("utf-16", "utf-16-le", "utf-16-be"):
            try:
                return data.decode(codec).encode("utf-8", "replace")
            except UnicodeDecodeError:
                continue
    if data[:4] in (b"\x00\x00\xfe\xff", b"\xff\xfe\x00\x00"):
        try:
            return data.decode("utf-32").encode("utf-8", "replace")
        except UnicodeDecodeError:
            pass
    return data


def refuse_entities(
    data: bytes, file: str, error_type: type[RobotSpecError] = RobotSpecError
) -> None:
    """Refuse an XML document that declares entities (billion laughs, external entities).

    Why before parsing: libxml2 expands internal entities inside attribute values whatever the
    parser options say, and xacro's minidom (expat) expands them too.
    """
    text = _decoded_head(data)
    doctype = text.find(b"<!DOCTYPE")
    if doctype < 0:
        return
    entity = text.find(b"<!ENTITY", doctype)
    if entity < 0:
        return
    name = text[entity + 8 : entity + 80].split()[:1]
    shown = name[0].decode("utf-8", "replace") if name else "?"
    raise error_type(
        f"XML entity declarations are not allowed (found '{shown}')",
        file=file,
        line=text.count(b"\n", 0, entity) + 1,
        kind="entity",
        name=shown,
    )
