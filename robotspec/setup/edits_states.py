"""Named joint states of the assistant's parts: the joints a part's sliders move, states saved.

Why apart from the session: :class:`~robotspec.setup.session.SetupSession` owns the state (one
lock, validation, ordered delivery, undo); this module says which joints a part's states name
and what saving or removing a state does to the draft, through :meth:`SetupSession.edit`.
"""

from __future__ import annotations

import copy
import threading
from collections.abc import Callable, Mapping

from robotspec.model.world import World
from robotspec.setup.edits import SetupError, _chain, _manipulator
from robotspec.setup.tree import chain_joints, joint_range, subtree_joints
from robotspec.setup.validation import Validation
from robotspec.spec.draft.model import Draft

__all__ = ["StateEdits"]


class StateEdits:
    """Named states, for :class:`~robotspec.setup.session.SetupSession`."""

    world: World
    _lock: threading.RLock
    _draft: Draft

    def edit(self, change: Callable[[Draft], None]) -> Validation:
        """Apply ``change`` as the session's state (:meth:`SetupSession.edit`)."""
        raise NotImplementedError

    def part_joints(self, part: str) -> tuple[str, ...]:
        """The joints a part's states name: a chain's from root to tip, a hand's below its root."""
        with self._lock:
            d = self._draft
            if part == "robot":
                return tuple(
                    c.name for c in self.world.connections if c.is_active and not c.is_mimic
                )
            if part.startswith("manipulators."):
                return subtree_joints(self.world, _manipulator(d, part).root)
            c = _chain(d, part)
            if c.group is not None and not c.root:
                return ()
            return chain_joints(self.world, c.root, c.tip)

    def part_states(self, part: str) -> dict[str, dict[str, float]]:
        """A part's named states (``robot``: the spec's top-level ``states``)."""
        with self._lock:
            return copy.deepcopy(self._states_of(self._draft, part))

    def joint_range(self, joint: str) -> tuple[float, float]:
        """The range a state's slider spans (the joint's limits)."""
        return joint_range(self.world, joint)

    def _states_of(self, d: Draft, part: str) -> dict[str, dict[str, float]]:
        if part == "robot":
            return d.states
        if part.startswith("manipulators."):
            return _manipulator(d, part).states
        return _chain(d, part).states

    def set_state(self, part: str, name: str, values: Mapping[str, float]) -> Validation:
        """A named state of a part (``robot`` for the spec's own ``states``), joint by joint."""
        if not name.strip():
            raise SetupError("a state needs a name", kind="state")
        clean: dict[str, float] = {}
        for joint, value in values.items():
            if not self.world.has_connection(joint):
                raise SetupError(f"no joint '{joint}' in the robot", kind="joint", name=joint)
            clean[joint] = round(float(value), 6)

        def change(d: Draft) -> None:
            self._states_of(d, part)[name] = clean

        return self.edit(change)

    def remove_state(self, part: str, name: str) -> Validation:
        """Drop a named state."""

        def change(d: Draft) -> None:
            states = self._states_of(d, part)
            if name not in states:
                raise SetupError(f"no state '{name}' on {part}", kind="state", name=name)
            del states[name]

        return self.edit(change)
