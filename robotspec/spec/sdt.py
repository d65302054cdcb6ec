"""The spec's ``sdt:`` field: which of the semantic digital twin's robot classes a robot is.

Why a spec names it: PyCRAM/coraplex pick robot-specific behaviour by the robot's *class*
(``AlternativeMotion.check_for_alternative`` compares ``original_class() ==
robot.__class__``: a Stretch drives differentially, an HSR-B navigates through Nav2). A robot
``to_sdt`` builds from this spec is then an instance of that very SDT class (its parts still
robotspec's). Why a static list: a spec is validated without SDT installed (a 3.6 GB extra),
and a file must never name a module to import; the list is SDT 26.7's robot classes, checked
against the real package by the SDT tests.
"""

from __future__ import annotations

from pydantic import Field, field_validator

from robotspec.errors import closest_names, did_you_mean
from robotspec.spec.base import SpecModel

__all__ = ["SDT_ROBOT_CLASSES", "SdtSpec"]

#: SDT 26.7's concrete robot classes: class name -> module of ``semantic_digital_twin.robots``.
SDT_ROBOT_CLASSES: dict[str, str] = {
    "Armar7": "armar7",
    "Garmi": "garmi",
    "HSRB": "hsrb",
    "ICub3": "icub3",
    "Justin": "justin",
    "MMPDresden": "mmp_dresden",
    "MinimalRobot": "minimal_robot",
    "PR2": "pr2",
    "Stretch": "stretch",
    "Tiago": "tiago",
    "TiagoMujoco": "tiago",
    "Tracy": "tracy",
    "UnitreeG1": "unitree_g1",
}


class SdtSpec(SpecModel):
    """How the robot appears in the semantic digital twin (``to_sdt``)."""

    class_: str = Field(
        alias="class",
        description="the SDT robot class the robot is an instance of in SDT (its parts stay "
        "robotspec's), so PyCRAM/coraplex apply that robot's own motions; one of "
        + ", ".join(SDT_ROBOT_CLASSES),
        examples=["Stretch"],
    )

    @field_validator("class_")
    @classmethod
    def _known(cls, value: str) -> str:
        if value not in SDT_ROBOT_CLASSES:
            raise ValueError(
                f"the semantic digital twin 26.7 has no robot class '{value}'"
                f"{did_you_mean(closest_names(value, SDT_ROBOT_CLASSES))} (it has "
                f"{', '.join(SDT_ROBOT_CLASSES)}; a class of your own: "
                "to_sdt(robot, sdt_class=...))"
            )
        return value
