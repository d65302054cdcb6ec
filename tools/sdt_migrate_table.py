"""Every robot class SDT ships through ``migrate sdt`` and ``validate``: docs/sdt.md's table.

Why a tool: the table in docs/sdt.md ("Every class SDT 26.7 ships") must be reproducible. For
each of SDT 26.7's 13 robot classes it finds the robot's URDF where this machine has one
(example-robot-data, the shared robot files, the ``hello-robot-stretch-urdf`` 0.1.2 and
``pycram-robotics`` 1.0.4 wheels unpacked where ``tools/corpus`` keeps wheels, the IAI fork
of ``hsr_description`` extracted from the search tool's mirror as the blind corpus's GitHub
robots are), migrates the class, validates the written spec and sorts each error by whose
fault it is. Run it in the SDT environment::

    .venv-sdt/bin/python -m tools.sdt_migrate_table            # every class
    .venv-sdt/bin/python -m tools.sdt_migrate_table Stretch   # one
    .venv-sdt/bin/python -m tools.sdt_migrate_table HSRB=path/to/hsrb4s.urdf  # other files

A class whose files are not found, or that SDT cannot build on them, is a row saying so.
"""

from __future__ import annotations

import re
import sys
import tempfile
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

from tools.corpus.fetch import cache_root

ROOT = Path(__file__).resolve().parents[1]
PYCRAM = "pypi/pycram-robotics==1.0.4/pycram_robotics-1.0.4.data/data/lib/python3.10/"
PYCRAM += "site-packages/pycram/resources/robots"
#: Hello Robot's own Stretch URDFs (Clear BSD): the RE2 with the dex wrist has every frame
#: SDT's ``Stretch`` names; preferred to pycram-robotics' copy where a vendor's package has it.
STRETCH = "pypi/hello-robot-stretch-urdf==0.1.2/stretch_urdf/RE2V0/"
STRETCH += "stretch_description_RE2V0_tool_stretch_dex_wrist.urdf"

#: SDT's HSRB class names ``hand_gripper_tool_frame``, which only the IAI fork's URDF has (the
#: shared HSR-B is hsr-project's and TRI's). Pinned like the blind corpus's robots: the tree is
#: extracted once into the corpus cache (``tools.corpus.extract_github``), never committed. Its
#: meshes are ``package://hsr_meshes``, found in the shared HSR-B's folder.
HSRB_FORK = ("code-iai/hsr_description", "ec886faaf19e4c81ebef22f54cb1ad6fb65b22b2")

#: Whose fault each kind of validate error is, by its message.
FAULTS = (
    ("SDT: a state outside the joint's limits", r"states\.\S+: \S+ is outside the limits of"),
    ("SDT: camera heights FK never reaches", r"minimal_height: FK puts"),
    ("SDT: a state on another part's joint", r"joint '\S+' does not move chain"),
    ("SDT: two default cameras", r"are both the default camera"),
)


def _erd() -> Path | None:
    import importlib.metadata as md

    try:
        dist = md.distribution("example-robot-data")
    except md.PackageNotFoundError:
        return None
    return Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data")))


def hsrb_fork() -> Path | None:
    """The IAI fork's tree at :data:`HSRB_FORK`, extracted from its mirror if need be, or None."""
    from tools.corpus.extract_github import extract, mirror_of

    repo, commit = HSRB_FORK
    dest = cache_root() / "github" / f"{repo.replace('/', '+')}@{commit}"
    if not dest.is_dir():
        if mirror_of(repo) is None:
            return None
        extract(repo, commit, dest)
    return dest


def sources() -> dict[str, tuple[Path | None, Path | None, list[Path]]]:
    """Class name -> (URDF, SRDF, package paths) as found on this machine (None: absent)."""
    erd, wheel = _erd(), cache_root() / PYCRAM
    shared = ROOT.parent / "shared" / "robots"
    out: dict[str, tuple[Path | None, Path | None, list[Path]]] = {}
    if erd is not None:
        pr2 = erd / "robots/pr2_description"
        out["PR2"] = (pr2 / "urdf/pr2.urdf", pr2 / "srdf/pr2.srdf", [erd.parent])
        g1 = erd / "robots/g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf"
        out["UnitreeG1"] = (g1, None, [erd.parent])
    hsrb, fork = shared / "hsrb", hsrb_fork()
    out["HSRB"] = (  # without the fork, no URDF: the shared one lacks the class's frame
        None if fork is None else fork / "robots/hsrb4s.urdf",
        hsrb / "hsrb_moveit_config/config/hsrb.srdf",
        [hsrb],
    )
    out["Stretch"] = (cache_root() / STRETCH, None, [])
    for name, file in (  # no package but PyCRAM's has these (docs/sdt.md says why)
        ("ICub3", "iCub3.urdf"),
        ("Justin", "rollin_justin.urdf"),
        ("Tiago", "tiago_dual.urdf"),
        ("TiagoMujoco", "tiago_dual.urdf"),
    ):
        out[name] = (wheel / file, None, [])
    return out


def fault_of(message: str) -> str:
    """Whose fault a validate error is: one of :data:`FAULTS`, else migrate's (a bug)."""
    for name, pattern in FAULTS:
        if re.search(pattern, message):
            return name
    return f"migrate: {message}"


def row(target: str, urdf: Path, srdf: Path | None, paths: list[Path]) -> str:
    """One markdown table row: the class, migrated or why not, validate's errors by fault."""
    from robotspec.compiler import check_spec
    from robotspec.errors import RobotSpecError
    from robotspec.interop.sdt.migrate import migrate_files, render

    name = target.rpartition(":")[2]
    with tempfile.TemporaryDirectory() as tmp:
        try:
            migration = migrate_files(
                target,
                str(urdf),
                srdf=None if srdf is None else str(srdf),
                folder=Path(tmp),
                package_paths=paths,
            )
        except RobotSpecError as exc:
            why = str(exc).splitlines()[0].removeprefix("error: ")
            return f"| {name} | no: {why} | | |"
        spec = Path(tmp) / f"{name}.yaml"
        spec.write_text(render(migration, source=target), encoding="utf-8")
        try:
            near = [urdf.parent, *([] if srdf is None else [srdf.parent])]
            check_spec(spec, package_paths=[*paths, *near])
            errors: list[str] = []
        except RobotSpecError as exc:
            errors = [d.message for d in exc.details]
    counts = Counter(fault_of(e) for e in errors)
    faults = "; ".join(f"{k} ({v})" for k, v in sorted(counts.items())) or "none"
    notes = len(migration.notes)
    return f"| {name} | yes ({notes} notes) | {len(errors)} | {faults} |"


def _out(line: str) -> None:
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def main(argv: Sequence[str] | None = None) -> int:
    """Print the table (every class, or those named; ``CLASS=URDF[,SRDF]`` for other files)."""
    import pytest

    from robotspec.spec.sdt import SDT_ROBOT_CLASSES

    sys.path.append(str(ROOT / "tests" / "sdt_stand_ins"))  # giskardpy's one helper
    from tests.sdt_support import stand_in_cylinder

    found = sources()
    wanted: list[str] = []
    for arg in argv if argv is not None else sys.argv[1:]:
        cls, _, files = arg.partition("=")
        if files:
            urdf_text, _, srdf_text = files.partition(",")
            urdf_file = Path(urdf_text)
            found[cls] = (urdf_file, Path(srdf_text) if srdf_text else None, [urdf_file.parent])
        wanted.append(cls)
    _out("| class | migrated | validate errors | each, whose fault |")
    _out("| --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp, pytest.MonkeyPatch.context() as mp:
        stand_in_cylinder(Path(tmp), mp)
        for cls in wanted or list(SDT_ROBOT_CLASSES):
            target = f"semantic_digital_twin.robots.{SDT_ROBOT_CLASSES[cls]}:{cls}"
            urdf, srdf, paths = found.get(cls, (None, None, []))
            if urdf is None or not urdf.is_file():
                _out(f"| {cls} | no: its URDF is not found here | | |")
                continue
            _out(row(target, urdf, srdf, paths))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
