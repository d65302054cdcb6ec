"""Where each value of a YAML document was written, through aliases and merge keys.

Why links instead of one mark per expanded value: an alias is one shared value in the data (the
anchored list or mapping, not a copy), so a document of a few kilobytes that names a big anchor
many times costs memory in proportion to its text, not to its expansion. A path that runs
through an alias (``chains.left.tip`` where ``left: *arm``) is answered by following the link to
the anchor (``arm.tip``), and a key a mapping took from a merge key (``<<: *arm``) by following
it to the mapping it came from. So an error inside an alias or a merged key points at the line
where the value is written.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from typing import Any

__all__ = ["Loc", "Marks", "pack", "unpack"]

Loc = tuple[str | int, ...]

#: A place is kept as one integer, ``line * _COLUMNS + column`` (a third of a tuple's memory,
#: one entry per value of the document).
_COLUMNS = 1 << 32


def pack(line: int, column: int) -> int:
    """``(line, column)`` as the one integer a :class:`Marks` table keeps."""
    return line * _COLUMNS + column


def unpack(place: int) -> tuple[int, int]:
    """The ``(line, column)`` of a place :func:`pack` made."""
    line, column = divmod(place, _COLUMNS)
    return line, column


#: Rewrites one path may take before the search gives up: each rewrite moves to a value written
#: earlier in the document, so real documents need a handful; this only bounds a broken table.
_MAX_REWRITES = 100_000


class Marks(Mapping[Loc, tuple[int, int]]):
    """``(line, column)`` by path: the paths written in the document, and those reached.

    A path is reached through an alias or a merge key. Iterating gives only the paths written
    literally (what copying into another table keeps; the linked ones then answer with the
    alias's own place).
    """

    __slots__ = ("_aliases", "_marks", "_merges", "_written")

    def __init__(
        self,
        marks: dict[Loc, int],
        written: Mapping[Loc, object],
        aliases: Mapping[Loc, Loc],
        merges: Mapping[Loc, Sequence[tuple[Loc, Mapping[str, Any]]]],
    ) -> None:
        """Hold the table and the links it is searched through.

        ``marks``: this table's own entries, each place made by :func:`pack`; ``written``:
        every literal node's path (a mapping's explicit keys shadow its merged ones);
        ``aliases``: the path of an alias -> the path of its anchor; ``merges``: a mapping's
        path -> its merge sources in priority order, each with the mapping it contributed (to
        tell which source a key came from).
        """
        self._marks = marks
        self._written = written
        self._aliases = aliases
        self._merges = merges

    def __getitem__(self, loc: Loc) -> tuple[int, int]:
        path = self.resolve(loc)
        if path is None:
            raise KeyError(loc)
        return unpack(self._marks[path])

    def __contains__(self, loc: object) -> bool:
        return isinstance(loc, tuple) and self.resolve(loc) is not None

    def __iter__(self) -> Iterator[Loc]:
        return iter(self._marks)

    def __len__(self) -> int:
        return len(self._marks)

    def resolve(self, loc: Sequence[str | int]) -> Loc | None:
        """The literal path whose mark answers for ``loc``, or None where the document has none.

        Walks from the longest prefix down: an alias on the way continues at its anchor; a
        written mapping that holds the next key itself ends the search there; one that got the
        key from a merge continues in the source that supplied it.
        """
        path = tuple(loc)
        for _ in range(_MAX_REWRITES):
            if path in self._marks:
                return path
            rewritten = self._rewrite(path)
            if rewritten is None:
                return None
            path = rewritten
        return None

    def _rewrite(self, path: Loc) -> Loc | None:
        for cut in range(len(path) - 1, -1, -1):
            head = path[:cut]
            target = self._aliases.get(head)
            if target is not None:
                return target + path[cut:]
            if head not in self._written:
                continue
            if (*head, path[cut]) in self._written:
                return None  # written literally down to here: nothing more to follow
            for source_path, source in self._merges.get(head, ()):
                if path[cut] in source:
                    return source_path + path[cut:]
            return None
        return None
