"""Every file robotspec writes: never through a link, never over the robot's own files, never half.

Why one module: robot files and specs are downloaded from strangers and unpacked next to the
folders robotspec writes into. A link planted anywhere on the way (``out/NAME_meshes`` pointing
at ``~/.config``, ``.x.yaml.saving`` pointing at ``~/.bashrc``) must not redirect a write, and a
write must not replace the URDF, SRDF, spec or mesh it was computed from. The rules:

* the folder the user named (``under``) is theirs: it and the folders above it may be links;
  every component *below* it, down to the file, is opened without following a link (``O_NOFOLLOW``
  relative to the open parent folder, so a component swapped for a link after a check is still
  refused), and a missing folder is created one at a time the same way;
* the data goes to a temporary file created exclusively (``O_CREAT | O_EXCL | O_NOFOLLOW``) in
  the target's folder, then is renamed into place, so no reader sees half a file and nothing
  planted at the temporary name is ever opened;
* a link, a folder, a FIFO or a device at the target is refused always; an existing file needs
  ``force``; without it the target is claimed atomically (a hard link of the temporary file,
  which fails if the name exists), so two runs racing for one name cannot both win;
* a target that is one of ``inputs`` (compared by device and inode, links resolved, so a hard
  link or another spelling of the path is caught) is refused, ``force`` or not;
* a refused or failed write leaves nothing behind: no temporary file, no folder it created.

Where the system has no ``dir_fd``/``O_NOFOLLOW`` (Windows), each component is checked with
``lstat`` before use instead: the same refusals, without the protection against a link swapped
in between the check and the use.
"""

from __future__ import annotations

import errno
import os
import secrets
import stat
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from robotspec.errors import RobotSpecError

__all__ = ["check_writable", "write_file", "write_files"]

#: Use folder descriptors (``openat``, ``mkdirat``, ``linkat``, ``renameat``); tests turn it off
#: to exercise the portable path on a system that has them.
USE_DIR_FDS: bool = (
    hasattr(os, "O_NOFOLLOW")
    and hasattr(os, "O_DIRECTORY")
    and {os.open, os.mkdir, os.stat, os.link, os.rename, os.unlink, os.rmdir} <= os.supports_dir_fd
)

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_BINARY = getattr(os, "O_BINARY", 0)
#: ``link`` failures that mean "this file system has no hard links": claim the name another way.
_NO_HARD_LINKS = {errno.EPERM, errno.EMLINK, errno.ENOSYS, errno.EXDEV} | {
    getattr(errno, name) for name in ("ENOTSUP", "EOPNOTSUPP") if hasattr(errno, name)
}
_TEMP_TRIES = 16

LINK_MESSAGE = "is a symbolic link; robotspec does not write through links"
EXISTS_MESSAGE = "the file exists; pass --force to overwrite it"

Data = str | bytes


# --------------------------------------------------------------------------------- folders
class _Folder(Protocol):
    """An open folder: names inside it are used without following a link."""

    path: Path

    def open_dir(self, name: str) -> _Folder: ...
    def mkdir(self, name: str) -> None: ...
    def lstat(self, name: str) -> os.stat_result: ...
    def create(self, name: str) -> int: ...
    def link(self, src: str, dst: str) -> None: ...
    def replace(self, src: str, dst: str) -> None: ...
    def unlink(self, name: str) -> None: ...
    def rmdir(self, name: str) -> None: ...
    def close(self) -> None: ...


def _is_link(st: os.stat_result) -> bool:
    """A symbolic link, or (Windows) a junction or other reparse point."""
    return stat.S_ISLNK(st.st_mode) or bool(getattr(st, "st_reparse_tag", 0))


_CREATE = os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC | _BINARY


class _FdFolder:
    """A folder held open by descriptor.

    A name is resolved in *this* folder, whatever happens meanwhile to the path that led here.
    """

    def __init__(self, fd: int, path: Path) -> None:
        self.fd, self.path = fd, path

    @classmethod
    def open(cls, path: Path) -> _FdFolder:
        # The user's own folder: links in it are their choice, so this open follows them.
        return cls(os.open(path, os.O_RDONLY | os.O_DIRECTORY | _CLOEXEC), path)

    def open_dir(self, name: str) -> _FdFolder:
        flags = os.O_RDONLY | os.O_DIRECTORY | _NOFOLLOW | _CLOEXEC
        return _FdFolder(os.open(name, flags, dir_fd=self.fd), self.path / name)

    def mkdir(self, name: str) -> None:
        os.mkdir(name, 0o777, dir_fd=self.fd)

    def lstat(self, name: str) -> os.stat_result:
        return os.stat(name, dir_fd=self.fd, follow_symlinks=False)

    def create(self, name: str) -> int:
        return os.open(name, _CREATE, 0o666, dir_fd=self.fd)

    def link(self, src: str, dst: str) -> None:
        os.link(src, dst, src_dir_fd=self.fd, dst_dir_fd=self.fd, follow_symlinks=False)

    def replace(self, src: str, dst: str) -> None:
        os.rename(src, dst, src_dir_fd=self.fd, dst_dir_fd=self.fd)  # POSIX rename replaces

    def unlink(self, name: str) -> None:
        os.unlink(name, dir_fd=self.fd)

    def rmdir(self, name: str) -> None:
        os.rmdir(name, dir_fd=self.fd)

    def close(self) -> None:
        os.close(self.fd)


class _PathFolder:
    """The portable stand-in: paths, each component checked with ``lstat`` before use."""

    def __init__(self, path: Path) -> None:
        self.path = path

    @classmethod
    def open(cls, path: Path) -> _PathFolder:
        if not path.is_dir():
            raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR), str(path))
        return cls(path)

    def open_dir(self, name: str) -> _PathFolder:
        st = os.lstat(self.path / name)
        if _is_link(st) or not stat.S_ISDIR(st.st_mode):
            raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR), name)
        return _PathFolder(self.path / name)

    def mkdir(self, name: str) -> None:
        os.mkdir(self.path / name, 0o777)

    def lstat(self, name: str) -> os.stat_result:
        return os.lstat(self.path / name)

    def create(self, name: str) -> int:
        return os.open(self.path / name, _CREATE, 0o666)

    def link(self, src: str, dst: str) -> None:
        os.link(self.path / src, self.path / dst)

    def replace(self, src: str, dst: str) -> None:
        os.replace(self.path / src, self.path / dst)

    def unlink(self, name: str) -> None:
        os.unlink(self.path / name)

    def rmdir(self, name: str) -> None:
        os.rmdir(self.path / name)

    def close(self) -> None:
        pass


def _open_folder(path: Path) -> _Folder:
    return _FdFolder.open(path) if USE_DIR_FDS else _PathFolder.open(path)


# --------------------------------------------------------------------------------- targets
@dataclass(frozen=True)
class _Target:
    """Where one file goes: an existing folder to start from, the folders below it, the name."""

    shown: str  # the path as the user wrote it, for messages
    start: Path  # the nearest existing folder at or above ``under`` (opened following links)
    below: tuple[str, ...]  # folders from ``start`` down to the file's folder
    name: str

    def folder_path(self, depth: int) -> Path:
        """The path of the ``depth``-th folder below ``start`` (1-based), for messages."""
        return self.start.joinpath(*self.below[:depth])


def _target(path: Path, under: Path | None) -> _Target:
    """Split ``path`` at the folder the user named; refuse a path that leaves it."""
    shown = str(path)
    full = Path(path).absolute()
    base = Path(under).absolute() if under is not None else full.parent
    n = len(base.parts)
    if full.parts[:n] == base.parts:
        rel = full.parts[n:]
    else:  # another spelling of the same folder (``out/./x``, ``a/../out``): compare normalized
        full_n, base_n = Path(os.path.normpath(full)), Path(os.path.normpath(base))
        if not full_n.is_relative_to(base_n):
            raise RobotSpecError(
                f"lies outside the folder it must be written in ({under}); robotspec writes only "
                "inside the folder named",
                file=shown,
                kind="output",
            )
        base, rel = base_n, full_n.relative_to(base_n).parts
    if not rel or any(part in ("..", ".") for part in rel):
        raise RobotSpecError(
            f"is not a file inside {base}; name a file, not a folder or '..'",
            file=shown,
            kind="output",
        )
    # The user's folder may not exist yet: start at its nearest existing ancestor; what is
    # missing is created (and refused if a link appears there meanwhile).
    start, missing = base, []
    while not os.path.lexists(start) and start.parent != start:
        missing.append(start.name)
        start = start.parent
    return _Target(shown, start, (*reversed(missing), *rel[:-1]), rel[-1])


# --------------------------------------------------------------------------------- inputs
class _Inputs:
    """The robot's own files, by device and inode (links resolved), with what each is."""

    def __init__(self, inputs: Iterable[Path]) -> None:
        roles: Mapping[Path, str] = inputs if isinstance(inputs, Mapping) else {}
        self.roles: dict[tuple[int, int], str | None] = {}
        for p in inputs:
            try:
                st = os.stat(p)
            except (OSError, ValueError):
                continue  # a missing input cannot be overwritten
            self.roles[(st.st_dev, st.st_ino)] = roles.get(p)

    def refuse(self, st: os.stat_result, shown: str) -> None:
        key = (st.st_dev, st.st_ino)
        if key in self.roles:
            role = self.roles[key]
            what = f" ({role})" if role else ""
            raise RobotSpecError(
                f"is an input of the robot{what}; robotspec never writes over a robot's own "
                "files; name another file",
                file=shown,
                kind="output",
            )


# --------------------------------------------------------------------------------- checks
def _link_error(shown: str, folder: Path | None = None) -> RobotSpecError:
    if folder is None:
        return RobotSpecError(
            f"{LINK_MESSAGE} (remove it or name another file)", file=shown, kind="output"
        )
    return RobotSpecError(
        f"its folder {folder} {LINK_MESSAGE} (remove it or name another folder)",
        file=shown,
        kind="output",
    )


def _os_error(shown: str, exc: OSError) -> RobotSpecError:
    return RobotSpecError(f"cannot write file: {exc.strerror or exc}", file=shown, kind="file")


def _enter(folder: _Folder, t: _Target, depth: int, *, create: bool) -> tuple[_Folder | None, bool]:
    """Open the ``depth``-th folder below ``t.start``, no link followed, and whether it was made.

    A missing folder is created when ``create`` (else the answer is None: nothing below it
    exists). A link there, made before or raced in after a check, is refused.
    """
    name = t.below[depth - 1]
    try:
        return folder.open_dir(name), False
    except FileNotFoundError:
        if not create:
            return None, False
    except OSError as exc:
        raise _folder_error(folder, t, depth, exc) from None
    made = True
    try:
        folder.mkdir(name)
    except FileExistsError:
        made = False  # made meanwhile by someone else: open it, refusing a link
    try:
        return folder.open_dir(name), made
    except OSError as exc:
        raise _folder_error(folder, t, depth, exc) from None


def _folder_error(folder: _Folder, t: _Target, depth: int, exc: OSError) -> Exception:
    """Why a folder on the way could not be opened: a link, a file, or the system's reason."""
    try:
        st = folder.lstat(t.below[depth - 1])
    except OSError:
        return exc
    if _is_link(st):
        return _link_error(t.shown, t.folder_path(depth))
    if not stat.S_ISDIR(st.st_mode):
        return RobotSpecError(
            f"cannot write file: {t.folder_path(depth)} is not a folder",
            file=t.shown,
            kind="file",
        )
    return exc


def _check_target(
    folder: _Folder, t: _Target, force: bool, inputs: _Inputs
) -> os.stat_result | None:
    """Refuse what may not be replaced; the existing file's status, or None if there is none."""
    try:
        st = folder.lstat(t.name)
    except FileNotFoundError:
        return None
    if _is_link(st):
        raise _link_error(t.shown)
    if not stat.S_ISREG(st.st_mode):
        raise RobotSpecError(
            "is not a regular file (a folder, device, FIFO or socket); robotspec writes only files",
            file=t.shown,
            kind="output",
        )
    inputs.refuse(st, t.shown)
    if not force:
        raise RobotSpecError(EXISTS_MESSAGE, file=t.shown, kind="output")
    return st


def _check(t: _Target, force: bool, inputs: _Inputs) -> None:
    """Every refusal :func:`_write` would make, found without creating anything."""
    opened: list[_Folder] = []
    try:
        folder = _open_folder(t.start)
        opened.append(folder)
        for depth in range(1, len(t.below) + 1):
            child, _ = _enter(folder, t, depth, create=False)
            if child is None:
                return  # a folder is missing: nothing below it exists to refuse
            opened.append(child)
            folder = child
        _check_target(folder, t, force, inputs)
    except OSError as exc:
        raise _os_error(t.shown, exc) from None
    finally:
        for f in reversed(opened):
            f.close()


# --------------------------------------------------------------------------------- writing
def _temp_name(name: str) -> str:
    # Random, so nothing can be planted at it in advance; short, so a long name still fits.
    return f".{name[:120]}.{secrets.token_hex(6)}.tmp"


def _create_temp(folder: _Folder, name: str) -> tuple[str, int]:
    for _ in range(_TEMP_TRIES):
        temp = _temp_name(name)
        try:
            return temp, folder.create(temp)
        except FileExistsError:
            continue  # taken (or a planted link): never opened, try another name
    raise FileExistsError(errno.EEXIST, "no free temporary file name", name)


def _fill(fd: int, data: bytes, mode: int | None) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]
    if mode is not None and hasattr(os, "fchmod"):
        os.fchmod(fd, mode)  # an overwritten file keeps its permissions
    os.fsync(fd)  # on disk before the rename makes it the file: a crash leaves old or new


def _claim(folder: _Folder, temp: str, t: _Target, force: bool, inputs: _Inputs) -> None:
    """Put the temporary file at the target's name: replace with ``force``, else only if free."""
    if force:
        folder.replace(temp, t.name)  # a link raced in at the name is replaced, not followed
        return
    try:
        folder.link(temp, t.name)  # atomic: fails if the name exists, whatever it is
    except FileExistsError:
        _check_target(folder, t, False, inputs)  # raises the reason (link, file, ...)
        raise RobotSpecError(EXISTS_MESSAGE, file=t.shown, kind="output") from None
    except OSError as exc:
        if exc.errno not in _NO_HARD_LINKS:
            raise
        try:  # no hard links here: claim the name with an exclusive empty file, then replace it
            os.close(folder.create(t.name))
        except FileExistsError:
            _check_target(folder, t, False, inputs)
            raise RobotSpecError(EXISTS_MESSAGE, file=t.shown, kind="output") from None
        folder.replace(temp, t.name)
        return
    folder.unlink(temp)


def _write(t: _Target, data: bytes, force: bool, inputs: _Inputs) -> None:
    opened: list[_Folder] = []
    created: list[tuple[_Folder, str]] = []
    temp: tuple[_Folder, str] | None = None
    try:
        folder = _open_folder(t.start)
        opened.append(folder)
        for depth in range(1, len(t.below) + 1):
            child, made = _enter(folder, t, depth, create=True)
            assert child is not None  # create=True never answers None
            if made:
                created.append((folder, t.below[depth - 1]))
            opened.append(child)
            folder = child
        old = _check_target(folder, t, force, inputs)
        name, fd = _create_temp(folder, t.name)
        temp = (folder, name)
        try:
            _fill(fd, data, None if old is None else stat.S_IMODE(old.st_mode))
        finally:
            os.close(fd)
        _claim(folder, name, t, force, inputs)
        temp = None
        created.clear()  # written: the folders stay
    except OSError as exc:
        raise _os_error(t.shown, exc) from None
    finally:
        if temp is not None:
            try:
                temp[0].unlink(temp[1])
            except OSError:
                pass
        for parent, name in reversed(created):  # a refused write leaves no folder behind
            try:
                parent.rmdir(name)
            except OSError:
                pass
        for f in reversed(opened):
            f.close()


# --------------------------------------------------------------------------------- public
def _bytes(data: Data) -> bytes:
    return data.encode("utf-8") if isinstance(data, str) else bytes(data)


def check_writable(
    path: Path,
    *,
    under: Path | None = None,
    force: bool = False,
    inputs: Iterable[Path] = (),
) -> None:
    """Raise what :func:`write_file` would refuse for ``path``, creating nothing.

    Why: a command that computes for a while (a collision matrix, a bundle) checks its outputs
    first, so the user hears about a planted link or an existing file before waiting.
    """
    _check(_target(path, under), force, _Inputs(inputs))


def write_file(
    path: Path,
    data: str | bytes,
    *,
    under: Path | None = None,
    force: bool = False,
    inputs: Iterable[Path] = (),
) -> Path:
    """Write ``data`` (text as UTF-8) to ``path`` as the module docstring says; return ``path``.

    Args:
        path: The file to write.
        data: Its contents; text is written as UTF-8.
        under: The folder the user named (default: ``path``'s folder). It and the folders above
            it may be links; no folder below it, nor the file, may be.
        force: Replace an existing regular file (never a link, a folder or an input).
        inputs: The robot's own files, never replaced. A mapping of path to what it is
            (``"its SRDF"``) makes the refusal say so.

    Raises:
        RobotSpecError: ``kind="output"`` for a refusal, ``kind="file"`` for a failure of the
            system, both with ``file`` the path as given.
    """
    _write(_target(path, under), _bytes(data), force, _Inputs(inputs))
    return Path(path)


def write_files(
    files: Sequence[tuple[Path, Data | Callable[[], Data]]],
    *,
    under: Path,
    force: bool = False,
    inputs: Iterable[Path] = (),
) -> list[Path]:
    """Write several files of one output (a bundle) into the folder ``under``.

    Every file is checked before any is written, so a refusal leaves no half bundle. The data
    may be a function returning it, called only when its file is written (mesh copies are read
    one at a time, not all held at once). Returns the paths written, in order.
    """
    guard = _Inputs(inputs)
    targets = [_target(path, under) for path, _ in files]
    seen: set[tuple[str, ...]] = set()
    for t in targets:
        key = (*t.below, t.name)
        if key in seen:
            raise RobotSpecError("is named twice in one output", file=t.shown, kind="output")
        seen.add(key)
        _check(t, force, guard)
    for t, (_, data) in zip(targets, files, strict=True):
        _write(t, _bytes(data() if callable(data) else data), force, guard)
    return [Path(path) for path, _ in files]
