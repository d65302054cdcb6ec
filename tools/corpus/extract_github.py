"""The GitHub half of the blind corpus: extract each listed commit into the corpus cache.

Why: the drafts are measured on robots nobody tuned them for (issue 30), and the robots of
``tests/data/blind_corpus/github.yaml`` come from public repositories of robot descriptions
(ROS ``*_description`` packages, MoveIt configurations). Their files are third-party and are never
committed here: the manifest names each repository and the commit the truth was written from,
and this script recreates the files on disk. These robots are for the project's own
measurement. The repositories are brought by the search tool's ``fetch`` (a git directory
without a work tree under ``/work/.mirror/OWNER+REPO/``), which a fresh machine may not have:
fetch each repository of the manifest first, then::

    python -m tools.corpus.extract_github              # extract every listed commit
    python -m tools.corpus.extract_github --list       # where each robot's files are

Files go to ``$ROBOTSPEC_CORPUS/github/OWNER+REPO@COMMIT/`` (default
``~/.cache/robotspec-corpus``), one tree per commit; a tree already extracted is kept. A ROS 2
package whose xacro names files where its build installs them (``$(find PKG)/ros2_control/...``
for the source's ``description/ros2_control/``) is read from an install space, as a ROS 2 user's
robot is: a manifest entry's ``share: {PKG: [PATH, ...]}`` copies each PATH of the repository
into ``_share/PKG/`` of the tree (what ``colcon build`` installs into ``install/PKG/share/PKG``),
and its ``urdf`` and ``package_paths`` may name ``_share``. Blobs the
mirror lacks (snapshots leave out files of 4 MiB and more: large meshes) are skipped and
counted; the URDF, SRDF and xacro files are small and always there.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tools.corpus.fetch import cache_root

__all__ = [
    "MANIFEST",
    "GithubRobot",
    "cache_root",
    "extract",
    "install_shares",
    "load_manifest",
    "main",
    "mirror_of",
]

#: The manifest: one entry per robot, with the commit its truth was written from.
MANIFEST = Path(__file__).resolve().parents[2] / "tests" / "data" / "blind_corpus" / "github.yaml"
#: Where the search tool's ``fetch`` leaves its git directories.
MIRRORS = Path(os.environ.get("ROBOTSPEC_MIRRORS", "/work/.mirror"))


@dataclass(frozen=True)
class GithubRobot:
    """One robot of the manifest."""

    id: str
    repo: str  # "owner/name"
    commit: str
    urdf: str  # inside the repository
    srdf: str | None
    xacro_args: dict[str, str]
    package_paths: tuple[str, ...]  # folders inside the repository
    half: str
    what: str
    #: ROS 2 packages installed from the repository: package name -> paths copied into
    #: ``_share/<package>/`` of the tree (see the module docstring).
    share: dict[str, tuple[str, ...]] = field(default_factory=dict)

    @property
    def folder(self) -> Path:
        """The extracted tree of this robot's commit."""
        return cache_root() / "github" / f"{self.repo.replace('/', '+')}@{self.commit}"


def load_manifest(path: Path = MANIFEST) -> list[GithubRobot]:
    """Every robot of the manifest, in its order."""
    import yaml

    data: Any = yaml.safe_load(path.read_text(encoding="utf-8"))
    out = []
    for e in data["robots"]:
        source = str(e["source"])
        if not source.startswith("github:") or "@" not in source:
            raise ValueError(f"{e['id']}: source is not 'github:OWNER/REPO@COMMIT': {source!r}")
        repo, commit = source[len("github:") :].split("@", 1)
        out.append(
            GithubRobot(
                id=str(e["id"]),
                repo=repo,
                commit=commit,
                urdf=str(e["urdf"]),
                srdf=None if e.get("srdf") is None else str(e["srdf"]),
                xacro_args={str(k): str(v) for k, v in (e.get("xacro_args") or {}).items()},
                package_paths=tuple(str(p) for p in e.get("package_paths") or ()),
                half=str(e["half"]),
                what=str(e.get("what", "")),
                share={str(k): tuple(str(p) for p in v) for k, v in (e.get("share") or {}).items()},
            )
        )
    return out


def mirror_of(repo: str, mirrors: Path = MIRRORS) -> Path | None:
    """The git directory ``fetch`` made for ``repo``, or ``None``."""
    base = mirrors / repo.replace("/", "+") / "repo"
    for cand in (base / ".git", base):
        if (cand / "objects").is_dir():
            return cand
    return None


def extract(repo: str, commit: str, dest: Path, mirrors: Path = MIRRORS) -> tuple[int, int]:
    """Write the tree of ``repo`` at ``commit`` under ``dest``: (files written, blobs missing)."""
    git_dir = mirror_of(repo, mirrors)
    if git_dir is None:
        raise FileNotFoundError(
            f"no mirror of {repo} under {mirrors}: fetch 'github:{repo}' with the search tool first"
        )
    git = ["git", f"--git-dir={git_dir}"]
    listing = subprocess.run(
        [*git, "ls-tree", "-r", "-z", commit], check=True, capture_output=True
    ).stdout
    blobs: list[tuple[str, str, str]] = []  # (mode, sha, path)
    for item in listing.split(b"\0"):
        if not item:
            continue
        meta, raw = item.split(b"\t", 1)
        mode, kind, sha = meta.decode().split()
        if kind == "blob":
            blobs.append((mode, sha, raw.decode("utf-8", "surrogateescape")))
    tmp = dest.with_name(dest.name + ".partial")
    tmp.mkdir(parents=True, exist_ok=True)
    proc = subprocess.Popen(
        [*git, "cat-file", "--batch"], stdin=subprocess.PIPE, stdout=subprocess.PIPE
    )
    assert proc.stdin is not None and proc.stdout is not None
    written = missing = 0
    for mode, sha, path in blobs:
        proc.stdin.write(sha.encode() + b"\n")
        proc.stdin.flush()
        header = proc.stdout.readline().split()
        if len(header) < 3 or header[1] == b"missing":
            missing += 1
            continue
        body = proc.stdout.read(int(header[2]))
        proc.stdout.read(1)  # the newline after each object
        target = tmp / path
        target.parent.mkdir(parents=True, exist_ok=True)
        if mode == "120000":  # a symbolic link: keep its target as written
            target.unlink(missing_ok=True)
            target.symlink_to(body.decode("utf-8", "surrogateescape"))
        else:
            target.write_bytes(body)
        written += 1
    proc.stdin.close()
    proc.wait()
    tmp.rename(dest)
    return written, missing


def install_shares(robot: GithubRobot) -> None:
    """Copy ``robot``'s ``share`` paths into ``_share/<package>/`` of its extracted tree.

    Why: a ROS 2 xacro names its own files where ``colcon build`` installs them, which is not
    where they are in the repository; the copy is that install step, done once per tree.
    """
    for package, paths in robot.share.items():
        dest = robot.folder / "_share" / package
        if dest.is_dir():
            continue
        tmp = dest.with_name(package + ".partial")
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir(parents=True)
        root = robot.folder.resolve()
        for rel in paths:
            src = robot.folder / rel
            # The tree is a third party's: a path must stay inside it, and a link it planted is
            # copied as a link, never as the file it points at (copy2 would follow it).
            if src.is_symlink() or not src.resolve().is_relative_to(root):
                raise ValueError(f"{robot.id}: share path {rel!r} is a link or leaves the tree")
            if src.is_dir():
                shutil.copytree(src, tmp / src.name, symlinks=True)
            else:
                shutil.copy2(src, tmp / src.name, follow_symlinks=False)
        tmp.rename(dest)


def main(argv: Sequence[str] | None = None) -> int:
    """Extract every commit the manifest lists (or, with ``--list``, print where each robot is)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="print each robot's URDF path")
    parser.add_argument("--manifest", type=Path, default=MANIFEST)
    args = parser.parse_args(argv)
    robots = load_manifest(args.manifest)
    if args.list:
        for r in robots:
            sys.stdout.write(f"{r.id}\t{r.half}\t{r.folder / r.urdf}\n")
        return 0
    failed = 0
    for repo, commit in dict.fromkeys((r.repo, r.commit) for r in robots):
        dest = cache_root() / "github" / f"{repo.replace('/', '+')}@{commit}"
        if dest.is_dir():
            sys.stdout.write(f"{repo}@{commit[:12]}: already at {dest}\n")
            continue
        try:
            written, missing = extract(repo, commit, dest)
        except (FileNotFoundError, subprocess.CalledProcessError) as exc:
            sys.stderr.write(f"{repo}@{commit[:12]}: {exc}\n")
            failed += 1
            continue
        gone = f", {missing} large files missing from the mirror" if missing else ""
        sys.stdout.write(f"{repo}@{commit[:12]}: {written} files at {dest}{gone}\n")
    for r in robots:
        if r.share and r.folder.is_dir():
            install_shares(r)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
