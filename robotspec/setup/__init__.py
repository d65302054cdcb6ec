"""``robotspec setup``: turning a draft into a valid spec by pointing and choosing.

Why a package of its own, apart from the page: what the assistant edits (a draft's parts,
states, drive), what it asks (the draft's DECIDE marks as questions), how it validates (the
compiler, on the text that would be saved, from memory) and how it saves (a URDF's draft with the
draft's own writer; a spec as its own text with the changes made in it) are plain Python, tested
without a browser. The viser page (``page``) only shows a :class:`SetupSession` and calls its
methods.

Modules: ``source`` (open a URDF or a spec as a draft), ``from_spec`` (a spec read into a
draft), ``round_trip`` (a spec's text with the draft's changes), ``text_edit`` (those changes
made in the text, line by line), ``questions`` (DECIDE marks), ``validation`` (the compiler on
the text, problems mapped to parts), ``save`` (the text and the file), ``session`` (the editable
state, one lock, states delivered in order), ``tree`` (the kinematic tree a user picks in).
"""

from __future__ import annotations

from robotspec.setup.questions import Question, questions_of
from robotspec.setup.session import SetupSession
from robotspec.setup.source import Source, open_source
from robotspec.setup.validation import Problem, Validation, validate_text

__all__ = [
    "Problem",
    "Question",
    "SetupSession",
    "Source",
    "Validation",
    "open_source",
    "questions_of",
    "validate_text",
]
