"""``robotspec init``: a first spec drafted from a robot's URDF (and SRDF, when there is one).

Why a draft and not a guess presented as fact: which links form an arm, where a tool frame is and
what a camera sees are decisions a person makes once. The draft takes everything the files say
(SRDF groups in every form, end effectors, group states, the virtual joint), reads the rest from
the kinematic tree (arms, legs, parallel grippers, tool frames, cameras, neck, torso, drive), marks
each guess with a ``# DECIDE:`` comment and its reason, and is valid as written, so ``robotspec
validate`` works from the start.

What an expert would sign: arms end at the wrist whatever the hand's shape (the hand gets its
own manipulator, with its fingers), a hand or gripper alone is drafted as one, base joints are
the drive (``drive.joints``) and pan/tilt heads with cameras necks, never arms; sides follow the
way the robot faces (``forward:`` drafted when its limbs or cameras say it is not +x). How close
the drafts come is measured against hand-written ground truth by ``tools/draft_score.py``.

One module per job: ``tree`` (segments and the default pose), ``limbs`` (arms, legs), ``hands``
(grippers), ``fingers`` (hands of three or more fingers), ``tool_frames``, ``manipulators`` (what
hangs at a chain's end), ``lone_hand`` (a hand without an arm), ``sensors`` (cameras, neck),
``parts`` (cameras and the neck placed on the chains, named states), ``torso_drive`` (torso,
drive), ``srdf_groups`` (what the SRDF says), ``confidence`` (when a part carries a DECIDE mark:
only where no file states it), ``build`` (joining them), ``render`` (YAML that survives any
name), ``paths`` (portable file references).
"""

from __future__ import annotations

from robotspec.spec.draft.build import draft_spec
from robotspec.spec.draft.model import (
    Draft,
    DraftCamera,
    DraftChain,
    DraftDrive,
    DraftFinger,
    DraftFrame,
    DraftManipulator,
)
from robotspec.spec.draft.paths import portable_ref, relative_path
from robotspec.spec.draft.render import SCHEMA_FILE, render_draft

__all__ = [
    "SCHEMA_FILE",
    "Draft",
    "DraftCamera",
    "DraftChain",
    "DraftDrive",
    "DraftFinger",
    "DraftFrame",
    "DraftManipulator",
    "draft_spec",
    "portable_ref",
    "relative_path",
    "render_draft",
]
