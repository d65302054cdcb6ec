"""A generated part's robot, found by a plain scan instead of one of krrood's entity queries.

Why: SDT's ``AbstractRobotPart._robot`` asks krrood's query language which robot of the world
holds the part. The first such query in a process imports krrood's query backends (pandas,
pyarrow, probabilistic models: about a second on an idle machine, most of SDT's own first
``from_world``), and each later one costs milliseconds; SDT asks it for every joint state a
part adds and for every part ``validate()`` checks. The question is a membership test, so the
generated parts answer it directly, with the same answer: the robots among the world's semantic
annotations whose parts hold this one (``in``, as krrood's ``contains``), None for none, SDT's
own ``DuplicateRobotAssignmentsError`` for two. A program that runs entity queries of its own
still imports the backends then, at its first query.
"""

from __future__ import annotations

from typing import Any

__all__ = ["robot_of"]


def robot_of(part: Any) -> Any:
    """The SDT robot whose parts include ``part``, or None (SDT's ``_robot``, without a query)."""
    from robotspec.interop.sdt import sdt_api

    sdt = sdt_api()
    robots = [
        a
        for a in part._world.semantic_annotations
        if isinstance(a, sdt.parts.AbstractRobot) and part in a._robot_parts
    ]
    if len(robots) > 1:
        raise sdt.DuplicateRobotAssignmentsError(robot_part=part, robots=robots)
    return robots[0] if robots else None
