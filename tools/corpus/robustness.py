"""How the drafter holds up when a robot's files change in ways another maker's would (issue 30).

Why: fixes made by looking at robots one by one do not carry over to robots nobody tuned for
(round 7: the tune half right, the held-out half where it was). A rule that decides from a
word of a name, from where the root link's origin happens to be, or from mesh extents is a rule
another maker's files break. So each robot of the blind corpus's *tune* half is drafted as it
comes and under perturbations that leave what the robot is unchanged, and every draft is scored
against the same truth (``tools/draft_score.py``'s counting)::

    python -m tools.corpus.robustness                # every perturbation, category rows
    python -m tools.corpus.robustness --only blind --robots arx5/x5 --wrong

The perturbations (``--only NAME``, repeatable):

* ``as-is``: the files as they come (the reference row; the same decisions as
  ``tools.corpus.measure``, scored in-process and without ``validate``);
* ``blind``: the drafter's name vocabulary blinded: the words of a name keep only sides
  (left, right, l, r) and digits, and no name counts as holding a limb word;
* ``renamed``: every link and joint renamed to a neutral id in document order (``n0``,
  ``n1``... for links, ``q0``... for joints; not ``l0``, whose ``l`` reads as "left"), in
  the URDF (``<gazebo reference>``, transmissions, ``ros2_control``, mimic tags, plugin frame
  names) and in the SRDF alike; the truth is mapped through the same renaming;
* ``root-moved``: the root link's frame placed elsewhere (its children's joints and its own
  geometry moved by a fixed offset, 30 cm forward, 20 cm aside, 45 cm down: a maker whose
  ``base_link`` sits at the wheel axle or the hip); the robot itself does not change, nor
  does which way it faces (no rotation: a truth's ``forward`` is in the root's frame);
* ``no-meshes``: every ``<visual>`` and ``<collision>`` whose geometry is a mesh removed (as
  when a mesh package is missing); primitive shapes stay.

Each row counts right/counted per category over the robots, like ``measure``'s totals; a
perturbation that breaks loading counts the robot as missed. ``--wrong`` lists each wrong
item per robot and perturbation (tune half only).

Protocol: the tune half only, never the held-out half. ``--blind-round 9a`` (repeatable) also
skips the robots a manifest lists after a ``# round 9a`` comment: a round's new robots, kept
blind to whoever changes the drafter until the lead has measured them at first sight.
"""

from __future__ import annotations

import argparse
import copy
import importlib
import pkgutil
import re
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # ``python tools/corpus/robustness.py`` as well as ``-m``
    sys.path.insert(0, str(REPO))

from lxml import etree  # noqa: E402

from tools.corpus.measure import BLIND_TRUTH, CorpusRobot, corpus_robots  # noqa: E402
from tools.draft_score import CATEGORIES, RobotScore, Truth, load_truths, score_draft  # noqa: E402

__all__ = ["PERTURBATIONS", "blind_ids", "main", "rename_map", "score_robot"]

#: The offset of ``root-moved``: where the root link's old origin lies in its new frame (m).
ROOT_OFFSET = (0.3, -0.2, -0.45)
#: The words a blinded name keeps.
SIDE_WORDS = frozenset({"left", "right", "l", "r"})
_ID = re.compile(r"^\s*-?\s*id:\s*(\S+)")


def blind_ids(manifests: Sequence[Path], rounds: Sequence[str]) -> frozenset[str]:
    """Robot ids a manifest lists after a ``# round R`` comment, for R in ``rounds`` (kept blind).

    A block runs to the next ``# round`` comment.
    """
    out: set[str] = set()
    if not rounds:
        return frozenset()
    marker = re.compile(r"^\s*#\s*round\s+([^\s:(]+)", re.IGNORECASE)
    wanted = {r.lower() for r in rounds}
    for path in manifests:
        blind = False
        for line in path.read_text(encoding="utf-8").splitlines():
            if m := marker.match(line):
                blind = m.group(1).lower() in wanted
            elif blind and (m := _ID.match(line)):
                out.add(m.group(1))
    return frozenset(out)


@contextmanager
def blinded() -> Iterator[None]:
    """The drafter with its name vocabulary blinded (restored on exit)."""
    import robotspec.spec.draft as pkg
    from robotspec.spec.draft import tree

    orig = tree.words

    def words(name: str) -> set[str]:
        return {w for w in orig(name) if w in SIDE_WORDS or w.isdigit()}

    def is_named(name: str, vocabulary: frozenset[str]) -> bool:
        return False

    saved: list[tuple[Any, str, Any]] = []
    for m in pkgutil.iter_modules(pkg.__path__):
        mod: Any = importlib.import_module(f"robotspec.spec.draft.{m.name}")
        if getattr(mod, "words", None) is orig:
            saved.append((mod, "words", orig))
            mod.words = words
        if hasattr(mod, "is_named"):
            saved.append((mod, "is_named", mod.is_named))
            mod.is_named = is_named
    try:
        yield
    finally:
        for mod, attr, value in saved:
            setattr(mod, attr, value)


@dataclass(frozen=True)
class Renaming:
    """Old -> neutral names, links and joints apart (a link and a joint may share a name)."""

    links: dict[str, str]
    joints: dict[str, str]

    def any(self, name: str, joint_first: bool = False) -> str:
        first, second = (self.joints, self.links) if joint_first else (self.links, self.joints)
        return first.get(name, second.get(name, name))


def rename_map(root: etree._Element) -> Renaming:
    """The neutral ids of ``root``'s links and joints, in document order."""
    links = [e.get("name", "") for e in root.iter("link")]
    joints = [e.get("name", "") for e in root.iter("joint") if e.getparent() is root]
    return Renaming(
        {n: f"n{i}" for i, n in enumerate(dict.fromkeys(links))},
        {n: f"q{i}" for i, n in enumerate(dict.fromkeys(joints))},
    )


_LINK_ATTRS = ("link", "link1", "link2", "parent_link", "child_link", "reference", "base_link")


def _rename_tree(root: etree._Element, ren: Renaming) -> None:
    """Every link or joint name in ``root`` (attributes and bare element text) renamed."""
    for e in root.iter():
        if not isinstance(e.tag, str):
            continue
        tag = etree.QName(e).localname
        joint_ctx = "joint" in tag
        for attr, raw in list(e.attrib.items()):
            value = str(raw)
            if attr == "name" and tag == "link":
                e.set(attr, ren.links.get(value, value))
            elif attr == "name" and tag in ("joint", "passive_joint"):
                e.set(attr, ren.joints.get(value, value))
            elif attr in _LINK_ATTRS:
                e.set(attr, ren.any(value))
            elif attr == "joint":
                e.set(attr, ren.any(value, joint_first=True))
        if e.text is not None and len(e) == 0 and tag not in ("link", "joint"):
            text = e.text.strip()
            new = ren.any(text, joint_first=joint_ctx)
            if new != text:
                e.text = new


def _truth_renamed(truth: Truth, ren: Renaming) -> Truth:
    """``truth`` with every link and joint name it holds renamed (keys and kinds kept)."""

    def walk(v: Any, key: str = "") -> Any:
        if isinstance(v, dict):
            return {k: walk(x, k) for k, x in v.items()}
        if isinstance(v, list):
            return [walk(x, key) for x in v]
        if isinstance(v, str) and key not in ("kind", "type", "robot"):
            return ren.any(v, joint_first="joint" in key)
        return v

    data = {k: (v if k == "robot" else walk(v, k)) for k, v in truth.data.items()}
    return Truth(truth.file, truth.robot, data)


def _moved_root(root: etree._Element) -> None:
    """The root link's frame moved by ``ROOT_OFFSET`` (its geometry and child joints with it)."""
    children = {c.get("link") for c in root.findall("joint/child")}
    roots = [e for e in root.findall("link") if e.get("name") not in children]
    if len(roots) != 1:
        return
    name = roots[0].get("name")
    places = [o for part in roots[0] for o in part.findall("origin")]
    for j in root.findall("joint"):
        parent = j.find("parent")
        if parent is not None and parent.get("link") == name:
            origin = j.find("origin")
            if origin is None:
                origin = etree.SubElement(j, "origin")
            places.append(origin)
    for part in roots[0]:
        if part.tag in ("visual", "collision", "inertial") and part.find("origin") is None:
            places.append(etree.SubElement(part, "origin"))
    for o in places:
        xyz = [float(v) for v in (o.get("xyz") or "0 0 0").split()]
        o.set("xyz", " ".join(repr(a + b) for a, b in zip(xyz, ROOT_OFFSET, strict=True)))


def _no_meshes(root: etree._Element) -> None:
    """Every visual and collision whose geometry is a mesh removed."""
    for link in root.findall("link"):
        for part in [*link.findall("visual"), *link.findall("collision")]:
            if part.find("geometry/mesh") is not None:
                link.remove(part)


Perturb = Callable[[etree._Element], None]
PERTURBATIONS: dict[str, Perturb | None] = {
    "as-is": None,
    "blind": None,
    "renamed": None,
    "root-moved": _moved_root,
    "no-meshes": _no_meshes,
}


def score_robot(robot: CorpusRobot, truth: Truth, kind: str, tmp: Path) -> RobotScore:
    """``robot`` drafted under perturbation ``kind`` and scored against ``truth``."""
    from robotspec.description.load import load_description
    from robotspec.description.srdf_names import map_prefixed_names
    from robotspec.description.srdf_reader import load_srdf
    from robotspec.description.urdf import world_from_urdf_xml
    from robotspec.spec.draft.build import draft_spec
    from robotspec.spec.draft.facts import read_facts

    desc = load_description(
        str(robot.urdf),
        srdf=None if robot.srdf is None else str(robot.srdf),
        package_paths=[str(p) for p in robot.package_paths],
        xacro_args=robot.xacro_args,
        meshes="keep",
        base_folder=tmp,
    )
    assert desc.urdf_xml is not None
    root = copy.deepcopy(desc.urdf_xml)
    srdf = desc.srdf
    if kind == "renamed":
        ren = rename_map(root)
        _rename_tree(root, ren)
        truth = _truth_renamed(truth, ren)
        if robot.srdf is not None:
            sx = etree.parse(
                str(robot.srdf), etree.XMLParser(resolve_entities=False, no_network=True)
            )
            _rename_tree(sx.getroot(), ren)
            path = tmp / "renamed.srdf"
            sx.write(str(path))
            srdf = load_srdf(path, strict=False)
    elif (perturb := PERTURBATIONS[kind]) is not None:
        perturb(root)
    world = world_from_urdf_xml(root, str(desc.urdf_file), resolver=desc.resolver, meshes="keep")
    if srdf is not None and kind == "renamed":
        srdf = map_prefixed_names(srdf, world.body_names, world.connection_names).srdf
    ref = None if robot.srdf is None else "robot.srdf"

    def draft() -> object:
        return draft_spec(
            world, urdf_ref="robot.urdf", srdf=srdf, srdf_ref=ref, name=world.name,
            facts=read_facts(root),
        )  # fmt: skip

    if kind == "blind":
        with blinded():
            d = draft()
    else:
        d = draft()
    return score_draft(truth, d, world, True)


def out(line: str) -> None:
    """One line of the report (flushed: a run takes minutes)."""
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def main(argv: Sequence[str] | None = None) -> int:
    """Score the tune half under each perturbation; print one row per perturbation."""
    from robotspec.errors import RobotSpecError
    from tools.corpus import extract_github, fetch

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0] if __doc__ else None)
    ap.add_argument("--only", action="append", choices=list(PERTURBATIONS))
    ap.add_argument("--robots", nargs="*", default=None, help="tune-half robot ids")
    ap.add_argument("--wrong", action="store_true", help="list the wrong items per robot")
    ap.add_argument(
        "--blind-round", action="append", default=[], help="skip a round's robots (e.g. 9a)"
    )
    args = ap.parse_args(argv)
    kinds = args.only or list(PERTURBATIONS)
    hidden = blind_ids([fetch.MANIFEST, extract_github.MANIFEST], args.blind_round)
    robots, skipped = corpus_robots()
    tune = [r for r in robots if r.half == "tune" and r.id not in hidden]
    if args.robots is not None:
        tune = [r for r in tune if r.id in args.robots]
    truths = {t.robot: t for t in load_truths(BLIND_TRUTH)}
    for note in skipped:
        out("skipped: " + note)
    totals = {k: {c: [0, 0] for c in CATEGORIES} for k in kinds}
    with tempfile.TemporaryDirectory() as tmp:
        for i, r in enumerate(tune):
            truth = truths.get(r.id)
            if truth is None:
                continue
            for kind in kinds:
                folder = Path(tmp) / f"{i}-{kind}"
                folder.mkdir()
                try:
                    score = score_robot(r, truth, kind, folder)
                except (RobotSpecError, OSError, ValueError) as exc:
                    out(f"{r.id} [{kind}]: not drafted ({type(exc).__name__}: {exc})"[:200])
                    continue
                for c in CATEGORIES:
                    got, of = score.counts.get(c, (0, 0))
                    totals[kind][c][0] += got
                    totals[kind][c][1] += of
                if args.wrong:
                    for w in score.wrong:
                        out(f"{r.id} [{kind}] WRONG {w}")
    out(f"{len(tune)} tune robots")
    out("| perturbation | " + " | ".join(CATEGORIES) + " |")
    out("| --- " * (len(CATEGORIES) + 1) + "|")
    for kind in kinds:
        cells = [f"{g}/{o}" for g, o in (totals[kind][c] for c in CATEGORIES)]
        out(f"| {kind} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
