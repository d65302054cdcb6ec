"""The flat spec of a composed robot: the parts' semantics merged, then the spec's own entries.

A welded part's one unmounted manipulator is handed over to the chain nearest above the weld
(the UR5's flange gives way to the Allegro hand), and the composed spec overrides key by key.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from lxml import etree
from pydantic import ValidationError

from robotspec.compose.naming import PartNames
from robotspec.compose.parts import Part
from robotspec.compose.semantics import NAMED_SECTIONS, remap_marks, rename_semantics
from robotspec.compose.urdf_merge import (
    tree_facts,
)
from robotspec.description.srdf import Srdf
from robotspec.diagnostics import Diagnostics, Loc
from robotspec.errors import SpecError
from robotspec.files.validation import validation_errors
from robotspec.files.yamlio import LocatedYaml
from robotspec.spec.load import LoadedSpec, merge_data
from robotspec.spec.models import RobotSpec

__all__ = ["flat_spec"]


# ---------------------------------------------------------------------------------- semantics
def _ancestors(parent_of: Mapping[str, str], link: str) -> list[str]:
    out = [link]
    while out[-1] in parent_of:
        out.append(parent_of[out[-1]])
    return out


def flat_spec(
    loaded: LoadedSpec,
    parts: Mapping[str, Part],
    order: Sequence[str],
    names_of: Mapping[str, PartNames],
    srdf: Srdf | None,
    robot: etree._Element,
    diag: Diagnostics,
) -> LoadedSpec | None:
    """The composed robot's spec: every part's semantics renamed, then the spec's own entries."""
    spec = loaded.spec
    merged = _Merged()
    for name in order:
        merged.add(name, parts[name], names_of[name], diag)
    data = _parts_data(loaded, merged, parts[order[0]], names_of[order[0]])
    own = spec.model_dump(mode="json", exclude_unset=True)
    _apply_own(data, own)
    explicit = {c for c, chain in own.get("chains", {}).items() if "manipulator" in chain}
    tips = {
        g.name: g.chains[0].tip_link for g in (srdf.groups if srdf else ()) if len(g.chains) == 1
    }
    _hand_over_manipulators(data, explicit, tips, parts, order, merged.owner, robot, names_of)
    # A part's manipulator that its own chain carried and no chain carries any more was
    # replaced (by a hand, or by the composed spec's own choice): it is not the robot's.
    carried = {c.get("manipulator") for c in data.get("chains", {}).values()}
    for m in [m for m in data.get("manipulators", {}) if m in merged.carried_before - carried]:
        if m not in own.get("manipulators", {}):
            del data["manipulators"][m]
    try:
        flat = RobotSpec.model_validate(data)
    except ValidationError as exc:
        diag.add_all(validation_errors(exc, loaded.documents[0], RobotSpec, SpecError))
        return None
    return LoadedSpec(flat, loaded.file, (*loaded.documents, *merged.documents))


@dataclass
class _Merged:
    """The parts' renamed semantics gathered part by part (a clash is an error, not a choice)."""

    sections: dict[str, Any] = field(default_factory=lambda: {s: {} for s in NAMED_SECTIONS})
    #: (section, key) -> the part it came from; ("torso", "") and ("neck", "") for those.
    owner: dict[tuple[str, str], str] = field(default_factory=dict)
    velocity: dict[str, float] = field(default_factory=dict)
    controlled: list[str] = field(default_factory=list)
    any_controlled: bool = False
    disabled: list[str] = field(default_factory=list)
    documents: list[LocatedYaml] = field(default_factory=list)
    import_states: bool = False
    #: Manipulators some part's own chain carries.
    carried_before: set[str] = field(default_factory=set)

    def add(self, name: str, part: Part, n: PartNames, diag: Diagnostics) -> None:
        """Part ``name``'s semantics, renamed; what another part has already is an error."""
        sem = rename_semantics(part.data, n, part.facts)
        loc: Loc = ("parts", name)
        self.carried_before.update(
            c["manipulator"] for c in sem.get("chains", {}).values() if c.get("manipulator")
        )
        for section in NAMED_SECTIONS:
            for key, value in sem.get(section, {}).items():
                other = self.owner.get((section, key))
                if other is not None:
                    diag.error(
                        loc,
                        f"{section[:-1]} '{key}' comes from both part '{other}' and part "
                        f"'{name}'; give part '{name}' a (different) prefix",
                        name=key,
                        kind="clash",
                    )
                    continue
                self.owner[(section, key)] = name
                self.sections[section][key] = value
        for key in ("torso", "neck"):
            if key in sem:
                if key in self.sections:
                    diag.error(
                        loc, f"both part '{self.owner[(key, '')]}' and part '{name}' have a {key}"
                    )
                    continue
                self.owner[(key, "")] = name
                self.sections[key] = sem[key]
        self.velocity.update(sem.get("velocity_limits", {}).get("joints", {}))
        if "controlled_joints" in sem:
            self.any_controlled = True
            self.controlled += sem["controlled_joints"]
        else:
            self.controlled += [n.joint(j) for j in part.facts.driven_joints]
        self.disabled += sem.get("collision", {}).get("disabled_bodies", [])
        self.import_states |= bool(sem.get("import_srdf_group_states"))
        self.documents += [remap_marks(d, n) for d in part.documents]


def _parts_data(
    loaded: LoadedSpec, merged: _Merged, base: Part, base_names: PartNames
) -> dict[str, Any]:
    """The spec the parts make together, before the composed spec's own entries."""
    spec = loaded.spec
    root = spec.root or base_names.link(base.spec_root or base.facts.roots[0])
    data: dict[str, Any] = {
        "name": spec.name,
        "description": {"urdf": str(loaded.file)},
        "root": root,
        **{k: v for k, v in merged.sections.items() if v},
    }
    if base.drive is not None:
        drive = dict(base.drive)
        if drive.get("joint"):
            drive["joint"] = base_names.joint(drive["joint"])
        data["drive"] = drive
    if merged.velocity:
        data["velocity_limits"] = {"joints": merged.velocity}
    if merged.any_controlled:
        data["controlled_joints"] = merged.controlled
    collision: dict[str, Any] = dict(base.collision)
    if merged.disabled:
        collision["disabled_bodies"] = merged.disabled
    if collision:
        data["collision"] = collision
    if merged.import_states:
        data["import_srdf_group_states"] = True
    return data


def _apply_own(data: dict[str, Any], own: Mapping[str, Any]) -> None:
    """The composed spec's own entries over the parts' (``parts`` and the like excepted)."""
    for key, value in own.items():
        if key in ("parts", "description", "robotspec", "extends"):
            continue
        if isinstance(value, dict) and isinstance(data.get(key), dict):
            # Like ``extends``: an entry the spec names changes the part's entry key by key
            # (``chains: {ur5_arm: {tip: ...}}`` keeps the part's root and states).
            data[key] = merge_data(data[key], value)
        else:
            data[key] = value


def _hand_over_manipulators(
    data: dict[str, Any],
    explicit: set[str],
    group_tips: Mapping[str, str],
    parts: Mapping[str, Part],
    order: Sequence[str],
    owner: Mapping[tuple[str, str], str],
    robot: etree._Element,
    names_of: Mapping[str, PartNames],
) -> None:
    """A welded hand's manipulator becomes the manipulator of the arm chain it is welded to.

    The chain chosen is the one whose tip is nearest above the weld link, among the parent
    part's chains and the composed spec's own (a chain given by SRDF group counts with the
    group's tip); a chain whose manipulator the composed spec names is left alone. Its previous
    manipulator (an arm's bare flange) is dropped unless another chain carries it or the composed
    spec names it: the hand's tool frame is now the chain's end.
    """
    chains: dict[str, Any] = data.get("chains", {})
    manips: dict[str, Any] = data.get("manipulators", {})
    parent_of = tree_facts(robot).parent_of
    for name in order:
        attach = parts[name].spec.attach
        if attach is None:
            continue
        carried = {c.get("manipulator") for c in chains.values()}
        free = [m for m in manips if owner.get(("manipulators", m)) == name and m not in carried]
        if len(free) != 1:
            continue
        above = _ancestors(parent_of, names_of[attach.part].link(attach.link))
        best: tuple[int, str] | None = None
        for cname, chain in chains.items():
            chain_owner = owner.get(("chains", cname))
            if cname in explicit or chain_owner not in (attach.part, None):
                continue
            tip = chain.get("tip") or group_tips.get(chain.get("group") or "")
            if tip not in above:
                continue
            depth = above.index(tip)
            if best is None or depth < best[0]:
                best = (depth, cname)
        if best is None:
            continue
        chains[best[1]]["manipulator"] = free[0]  # the one it replaces is dropped later
