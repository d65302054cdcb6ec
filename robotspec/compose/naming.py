"""How one part's names become the composed robot's names.

Why one object: the same link name appears in the URDF, the SRDF, the part's spec and the spec's
located YAML marks; renaming each of them with its own rule is how composed robots end up with a
group naming a link that no longer exists. Every name of a part passes through :class:`PartNames`.

The rule: names that are global in the robot (links, joints, SRDF groups, end effectors, chains,
manipulators, sensors, robot-level states) get the part's prefix. Names scoped under an owner that
is already prefixed (a chain's states, an SRDF group's states) keep their own name. A replaced root
link (``attach.replace_root``) becomes the link it is welded to.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

__all__ = ["PartNames"]


@dataclass(frozen=True)
class PartNames:
    """The renaming of one part: a prefix and the links that merge into another part's link."""

    part: str
    prefix: str = ""
    merged_links: Mapping[str, str] = field(default_factory=dict)

    def link(self, name: str) -> str:
        """A link of the part, as the composed robot calls it."""
        merged = self.merged_links.get(name)
        return merged if merged is not None else self.prefix + name

    def joint(self, name: str) -> str:
        """A joint of the part."""
        return self.prefix + name

    def name(self, name: str) -> str:
        """A semantic name: SRDF group or end effector, chain, manipulator, sensor, state."""
        return self.prefix + name

    def links(self, names: Iterable[str]) -> list[str]:
        """Several links."""
        return [self.link(n) for n in names]

    def joints(self, names: Iterable[str]) -> list[str]:
        """Several joints."""
        return [self.joint(n) for n in names]

    def joint_values(self, values: Mapping[str, float]) -> dict[str, float]:
        """A joint state's values with the joints renamed."""
        return {self.joint(j): v for j, v in values.items()}

    def states(self, states: Mapping[str, Mapping[str, float]]) -> dict[str, dict[str, float]]:
        """States owned by a part (chain, torso, ...): state names kept, joints renamed."""
        return {k: self.joint_values(v) for k, v in states.items()}
