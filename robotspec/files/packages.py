"""Find ROS packages and resolve description URIs without ROS, inside a fenced set of folders.

Why: URDF, xacro and SRDF files name other files as ``package://PKG/...``, ``$(find PKG)``,
``file://...`` or plain paths. Users rarely have a sourced ROS workspace, so robotspec keeps its
own package search path, built from explicit folders, the ROS environment variables, the folders
around the description file and the ``example-robot-data`` wheel. The same object also fences
reads: robot files come from anywhere, and a description must not be able to make robotspec read
``/etc/passwd`` through ``package://pkg/../../..`` or a symlink, so every resolved path (symlinks
followed) must lie inside the allowed roots.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import unquote

from robotspec.errors import (
    DescriptionError,
    PackageNotFoundError,
    PathOutsideRootsError,
    closest_names,
    did_you_mean,
)
from robotspec.files.fences import hidden_part, inside, marked_project, system_folder
from robotspec.files.package_search import (
    PACKAGE_NAME,
    description_root,
    enclosing_packages,
    example_robot_data_folders,
    folder_packages,
    user_roots,
    walk_up,
)

__all__ = ["PackageResolver"]

#: A URI scheme (``package://``, ``file://``, ``model://``).
_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.\-]*)://")


def _has_dotdot(path: str) -> bool:
    """Whether a path has a '..' component (as ``".." in Path(path).parts``, without pathlib)."""
    return ".." in path.split(os.sep)


def _as_given(folder: Path, real_project: Path | None) -> list[Path]:
    """The real ``real_project`` spelled as ``folder``'s ancestors are (links in between kept).

    Why: ``folder`` is absolute but not symlink-resolved, the project real; comparing the two
    would miss a project reached through a link (``/tmp`` on macOS).
    """
    if real_project is None:
        return []
    real = Path(os.path.realpath(folder))
    for up, up_real in zip((folder, *folder.parents), (real, *real.parents), strict=False):
        if up_real == real_project:
            return [up]
    return [real_project]


def _unique(paths: Iterable[Path]) -> tuple[Path, ...]:
    return tuple(dict.fromkeys(paths))


@dataclass(frozen=True, slots=True)
class PackageResolver:
    """One package search path and the folders reads are confined to.

    Build it with :meth:`create`. The package index is crawled lazily on the first lookup and
    kept in the instance (never in module state), so two resolvers never share results.

    Attributes:
        search_folders: Folders searched for packages, highest priority first.
        roots: Folders (absolute, not symlink-resolved) every resolved path must lie in.
        description: The description file the resolver was made for, if any.
        bare_name_folders: Search folders whose children count as packages even without a
            ``package.xml`` (the explicit, environment and example-robot-data folders; not the
            description's surroundings, where ``meshes/`` or ``inc/`` are no packages).
    """

    search_folders: tuple[Path, ...]
    roots: tuple[Path, ...]
    description: Path | None = None
    bare_name_folders: tuple[Path, ...] = ()
    #: Folders whose children are packages and are not crawled into (example-robot-data's).
    flat_folders: tuple[Path, ...] = ()
    #: Folders the caller asked to search that do not exist (listed in "searched:").
    missing_folders: tuple[Path, ...] = ()
    #: Roots the *input* opened (the description's folder, its package, the folder above
    #: ``urdf/``), not the user: below them no hidden file or folder and nothing in a system
    #: folder is readable (:mod:`robotspec.files.fences`). Packages crawled on the search path
    #: are held to the same rule unless a user root holds them.
    strict_roots: tuple[Path, ...] = ()
    #: The packages holding the description, nearest first (:func:`enclosing_packages`): they
    #: rank above every search folder, so the file's own package wins over one of its name on
    #: the user's path or installed.
    own_packages: tuple[tuple[str, Path], ...] = ()
    _index: dict[str, Path] = field(default_factory=dict, compare=False, repr=False)
    #: Crawled folders (folder, bare, flat) -> packages; shared by resolvers of one compilation.
    _crawls: dict[tuple[Path, bool, bool], dict[str, Path]] = field(
        default_factory=dict, compare=False, repr=False
    )
    _real_roots: list[Path] = field(default_factory=list, compare=False, repr=False)
    #: Folder -> its real path; shared like ``_crawls`` (a composed robot's resolvers see the
    #: same package folders, and resolving each again was a third of composing).
    _real_dirs: dict[str, str] = field(default_factory=dict, compare=False, repr=False)
    #: (root, root + separator) of each resolved root, for prefix tests on path strings.
    _root_prefixes: list[tuple[str, str, bool]] = field(
        default_factory=list, compare=False, repr=False
    )
    _resolved: dict[tuple[str, str], Path] = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def create(
        cls,
        description: str | Path | None,
        *,
        extra_paths: Sequence[str | Path] = (),
        use_environment: bool = True,
        use_example_robot_data: bool = True,
        extra_allowed_roots: Sequence[str | Path] = (),
        environ: Mapping[str, str] | None = None,
        share_crawls_with: PackageResolver | None = None,
    ) -> PackageResolver:
        """A resolver for ``description`` (a URDF/xacro/SRDF path, or ``None``).

        Search folders, highest priority first: ``extra_paths``; ``ROS_PACKAGE_PATH``;
        ``AMENT_PREFIX_PATH`` entries' ``share`` folders; the description's folder and the
        parents of packages enclosing it; ``example-robot-data``'s robots and share folders.
        Folders that do not exist are dropped quietly (environment variables often list stale
        entries).

        Args:
            description: The file whose references are resolved; its folder is always allowed.
            extra_paths: Folders that are packages or contain packages, searched first.
            use_environment: Read ``ROS_PACKAGE_PATH`` and ``AMENT_PREFIX_PATH``.
            use_example_robot_data: Search the installed ``example-robot-data`` wheel.
            extra_allowed_roots: More folders reads may reach (e.g. a symlink-install's
                source tree) without being searched for packages.
            environ: The environment to read instead of ``os.environ`` (tests, servers).
            share_crawls_with: A resolver of the same compilation whose folder crawls this
                one reuses (and adds to): parts of a composed robot search the same folders.
        """
        env = os.environ if environ is None else environ
        given = [Path(os.path.normpath(Path(p).absolute())) for p in extra_paths]
        missing = tuple(p for p in given if not p.is_dir())
        folders: list[Path] = list(given)
        if use_environment:
            folders += user_roots(environ=env, use_example_robot_data=False)
        bare = list(folders)
        desc: Path | None = None
        roots: list[Path] = list(folders)
        strict: list[Path] = []
        own: list[tuple[str, Path]] = []
        if description is not None:
            desc = Path(description).absolute()
            here = Path(os.path.normpath(desc.parent))
            near, package_roots = walk_up(here)
            folders += near
            bare.append(here)  # a folder beside the robot file is found by its name
            strict += [here, *package_roots]
            if not package_roots:
                strict += description_root(desc)
            project = marked_project(here)
            if project is not None:  # the repository or package holding it (docs/security.md)
                strict.append(project)
            own = enclosing_packages(here, [*strict[1:], *_as_given(here, project)])
            roots += strict
        flat: list[Path] = []
        if use_example_robot_data:
            erd = example_robot_data_folders()
            flat += erd
            folders += erd
            bare += erd
            roots += erd
        search = _unique(Path(os.path.normpath(f)) for f in folders if f.is_dir())
        roots += [Path(p).absolute() for p in extra_allowed_roots]
        all_roots = _unique(Path(os.path.normpath(r)) for r in roots)
        return cls(
            search_folders=search,
            roots=all_roots,
            description=desc,
            bare_name_folders=_unique(Path(os.path.normpath(f)) for f in bare if f.is_dir()),
            flat_folders=_unique(Path(os.path.normpath(f)) for f in flat if f.is_dir()),
            missing_folders=missing,
            strict_roots=_unique(Path(os.path.normpath(r)) for r in strict),
            own_packages=tuple(own),
            _crawls={} if share_crawls_with is None else share_crawls_with._crawls,
            _real_dirs={} if share_crawls_with is None else share_crawls_with._real_dirs,
        )

    @property
    def allowed_roots(self) -> tuple[Path, ...]:
        """The folders (as given, and symlink-resolved) every resolved path must lie in.

        These are :attr:`roots` and the packages found on the search path, each on its own.
        """
        packages = (self._real_folder(f) for f in self._packages().values())
        return _unique([*self.roots, *self._resolved_roots(), *packages])

    def _resolved_roots(self) -> list[Path]:
        if not self._real_roots:
            self._real_roots.extend(_unique(self._real_folder(r) for r in self.roots))
        return self._real_roots

    def packages(self) -> dict[str, Path]:
        """Every package the search folders provide, name to folder (first found wins).

        Within one search folder, ``package.xml`` names rank above folder names (a package
        folder's own name, or a child folder without a manifest); across folders, the search
        order decides.
        """
        return dict(self._packages())

    def _packages(self) -> dict[str, Path]:
        """The index itself (not a copy): lookups run once per mesh."""
        if not self._index:
            index: dict[str, Path] = {}
            for name, path in self.own_packages:
                index.setdefault(name, path)
            for folder in self.search_folders:
                key = (folder, folder in self.bare_name_folders, folder in self.flat_folders)
                found = self._crawls.get(key)
                if found is None:
                    found = folder_packages(folder, bare=key[1], flat=key[2])
                    self._crawls[key] = found
                for name, path in found.items():
                    index.setdefault(name, path)
            self._index.update(index)
        return self._index

    @classmethod
    def joined(cls, resolvers: Sequence[PackageResolver]) -> PackageResolver:
        """One resolver for files that came from several descriptions (a composed robot).

        Search folders and allowed roots are the union, in order. Its package index is the
        union of the resolvers' indexes (first wins), so it is not crawled again; a caller that
        needs a reference resolved as its own description's resolver does compares the two.
        """

        def union(attr: str) -> tuple[Path, ...]:
            out: dict[Path, None] = {}
            for r in resolvers:
                out.update(dict.fromkeys(getattr(r, attr)))
            return tuple(out)

        out = cls(
            search_folders=union("search_folders"),
            roots=union("allowed_roots"),
            description=None,
            bare_name_folders=union("bare_name_folders"),
            flat_folders=union("flat_folders"),
            strict_roots=_unique(r for res in resolvers for r in res.strict_allowed_roots()),
            _real_dirs=resolvers[0]._real_dirs if resolvers else {},
        )
        index: dict[str, Path] = {}
        for r in resolvers:
            for name, path in r._packages().items():
                index.setdefault(name, path)
        out._index.update(index)
        return out

    def find_package(self, name: str, *, file: str | None = None, line: int | None = None) -> Path:
        """The folder of package ``name``; unknown names suggest the closest known ones."""
        index = self._packages()
        found = index.get(name) if PACKAGE_NAME.match(name) else None
        if found is not None:
            return found
        # One suggestion per package folder: its declared name, not also its folder alias.
        by_folder: dict[Path, str] = {}
        for known, folder in index.items():
            by_folder.setdefault(folder, known)
        suggestions = closest_names(name, by_folder.values())
        searched = (
            ", ".join(
                [
                    *(str(f) for f in self.search_folders),
                    *(f"{f} (does not exist)" for f in self.missing_folders),
                ]
            )
            or "(no folders)"
        )
        raise PackageNotFoundError(
            f"package '{name}' not found; searched: {searched}{did_you_mean(suggestions)}",
            file=file,
            line=line,
            kind="package",
            name=name,
            suggestions=suggestions,
        )

    def _realpath(self, path: str | Path) -> Path:
        """``os.path.realpath``, with each folder resolved once per resolver.

        Why: a robot names dozens of meshes in a few folders; resolving every component of every
        path again costs more than parsing the URDF. Only the last component is checked per file
        (a symlinked mesh is still followed).
        """
        raw = os.fspath(path)
        text = os.path.abspath(raw)  # abspath normalizes '..' lexically: check the raw path
        if _has_dotdot(raw):
            return Path(os.path.realpath(raw))  # the OS follows a symlink before '..'
        parent, name = os.path.split(text)
        if not name or os.path.islink(text):
            return Path(os.path.realpath(text))
        return Path(self._real_folder(parent), name)

    def _real_folder(self, folder: str | Path) -> Path:
        """``os.path.realpath`` of a folder, resolved once per compilation (see ``_real_dirs``)."""
        key = os.fspath(folder)
        real = self._real_dirs.get(key)
        if real is None:
            real = self._real_dirs[key] = os.path.realpath(key)
        return Path(real)

    def _inside(self, real: Path) -> bool:
        """Inside an allowed root, or inside a package found on the search path.

        Why packages too: a search folder that is not a root (the parent of the package around
        the description) provides its packages, each readable on its own, but not the files
        beside them. Roots the input opened (``strict``) admit no hidden file or folder below
        them and nothing in a system folder; roots the user gave admit everything below them.
        """
        text = str(real)
        if not self._root_prefixes:
            self._root_prefixes.extend(self._prefixes())
        for root, prefix, strict in self._root_prefixes:
            if text == root or text.startswith(prefix):
                if not strict or (hidden_part(text, root) is None and not system_folder(text)):
                    return True
        return False

    def strict_allowed_roots(self) -> list[Path]:
        """The real roots and package folders held to the input's rule (see ``strict_roots``)."""
        if not self._root_prefixes:
            self._root_prefixes.extend(self._prefixes())
        return [Path(root) for root, _, strict in self._root_prefixes if strict]

    def _prefixes(self) -> list[tuple[str, str, bool]]:
        """(root, root + separator, strict) of every real root and package folder."""
        strict_given = {os.path.normpath(r) for r in self.strict_roots}
        user = [
            str(self._real_folder(r)) for r in self.roots if os.path.normpath(r) not in strict_given
        ]
        out: dict[str, bool] = {}
        for r in self.roots:
            real = str(self._real_folder(r))
            is_strict = os.path.normpath(r) in strict_given
            out[real] = out.get(real, True) and is_strict
        for f in self._packages().values():
            real = str(self._real_folder(f))
            if real not in out:
                out[real] = not any(inside(real, u) for u in user)
        return [(root, root.rstrip(os.sep) + os.sep, s) for root, s in out.items()]

    def is_allowed(self, path: str | Path) -> bool:
        """Whether ``path``, symlinks followed, lies inside one of the allowed roots."""
        return self._inside(self._realpath(path))

    def check_allowed(
        self,
        path: str | Path,
        *,
        uri: str | None = None,
        file: str | None = None,
        line: int | None = None,
    ) -> Path:
        """The real path of ``path`` if it is allowed, else :class:`PathOutsideRootsError`."""
        real = self._realpath(path)
        if not self._inside(real):
            shown = ", ".join(str(r) for r in self.roots) or "none"
            raise PathOutsideRootsError(
                f"'{uri if uri is not None else path}' resolves to {real}, "
                f"outside the allowed folders ({shown})",
                file=file,
                line=line,
                kind="path",
                name=str(uri if uri is not None else path),
            )
        return real

    def resolve(
        self,
        uri: str,
        *,
        relative_to: Path | None = None,
        file: str | None = None,
        line: int | None = None,
    ) -> Path:
        """The real path ``uri`` names: ``package://``, ``file://``, absolute or relative.

        The file need not exist (callers report missing meshes their own way), but the path,
        symlinks followed, must lie inside :attr:`allowed_roots`.

        Args:
            uri: The reference as written in the description.
            relative_to: The folder relative paths (and ``file://relative``) start from;
                the current folder when ``None``.
            file: The file the reference appears in, for error positions.
            line: The line of the reference in ``file``.
        """
        text = uri.strip()
        if not text:
            raise DescriptionError("empty file reference", file=file, line=line, kind="path")
        base = relative_to if relative_to is not None else Path.cwd()
        key = (text, str(base))
        cached = self._resolved.get(key)
        if cached is not None:  # robots name the same mesh many times (left and right arms)
            return cached
        found = self._resolve_uncached(uri, text, base, file, line)
        self._resolved[key] = found
        return found

    def _resolve_uncached(
        self, uri: str, text: str, base: Path, file: str | None, line: int | None
    ) -> Path:
        match = _SCHEME.match(text)
        if match is None:
            candidate = Path(text) if os.path.isabs(text) else base / text
        else:
            scheme = match.group(1).lower()
            rest = text[match.end() :]
            if scheme in ("package", "model"):
                name, _, inner = rest.partition("/")
                if not name and inner.strip("/"):
                    candidate = self._from_package_root(inner, uri, file, line)
                else:
                    root = self.find_package(name, file=file, line=line)
                    # Joined as text: an absolute-looking rest must not replace the package root.
                    candidate = Path(f"{root}/{inner}") if inner else root
            elif scheme == "file":
                path = unquote(rest)
                if path.startswith("localhost/"):
                    path = path[len("localhost") :]
                candidate = Path(path) if path.startswith("/") else base / path
            else:
                raise DescriptionError(
                    f"unsupported URI scheme '{match.group(1)}' in '{uri}'; "
                    "robotspec reads only package://, model://, file:// and paths",
                    file=file,
                    line=line,
                    kind="uri",
                    name=uri,
                )
        return self.check_allowed(candidate, uri=uri, file=file, line=line)

    def _from_package_root(self, inner: str, uri: str, file: str | None, line: int | None) -> Path:
        """``package:///PKG/path`` (an empty package name): a path that starts at a package root.

        Why: pinocchio joins everything after ``package://`` to each of its package folders, so
        Talos's ``package:///example-robot-data/robots/...`` names ``<folder>/example-robot-data
        /robots/...``. robotspec tries its search folders the same way (first existing file
        wins), then reads the first segment as a package name, as ROS tools would; when neither
        finds the file, the error names that first segment as the missing package.
        """
        rel = inner.lstrip("/")
        for folder in self.search_folders:
            candidate = Path(f"{folder}/{rel}")
            # Fenced before it is probed: nothing outside the roots is even looked at.
            if self.is_allowed(candidate) and candidate.exists():
                return candidate
        first, _, below = rel.partition("/")
        try:
            root = self.find_package(first, file=file, line=line)
        except PackageNotFoundError as exc:
            raise PackageNotFoundError(
                f"package '{first}' not found (a package:/// path starts at a package root); "
                f"{exc.message.partition('; ')[2]}",
                file=file,
                line=line,
                kind="package",
                name=first,
                suggestions=exc.suggestions,
            ) from None
        return Path(f"{root}/{below}") if below else root
