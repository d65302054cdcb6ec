"""Every robot class SDT ships through ``migrate sdt`` and ``validate``: docs/sdt.md's table.

Why a tool: the table in docs/sdt.md ("Every class SDT 26.7 ships") must be reproducible. For
each of SDT 26.7's 13 robot classes it finds the robot's URDF where this machine has one
(example-robot-data, the shared robot files, the ``pycram-robotics`` 1.0.4 wheel unpacked
where ``tools/corpus`` keeps wheels), migrates the class, validates the written spec and sorts
each error by whose fault it is. Run it in the SDT environment::

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
    hsrb = shared / "hsrb"
    out["HSRB"] = (
        hsrb / "hsrb4s.urdf",
        hsrb / "hsrb_moveit_config/config/hsrb.srdf",
        [hsrb],
    )
    for name, file in (
        ("Stretch", "stretch_description.urdf"),
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
