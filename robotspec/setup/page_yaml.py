"""The setup page's live YAML: the text save would write, the lines errors cite marked.

Why shown beside the robot: validate's messages cite lines of that text ("line 42"), and a spec
kept in git is reviewed as text; the pane is what the next save writes, byte for byte, after
every change of any tab. Why a proposed tool frame is drawn: a question asks which way a tool
faces; the answer chosen in its list is drawn as axes at the tool frame before it is applied,
so the person sees the frame they are about to accept.
"""

from __future__ import annotations

import html
from collections.abc import Iterable

from robotspec.setup.validation import Problem

__all__ = ["yaml_html"]

#: Backgrounds of a line an error, a warning cites (text on them keeps 4.5:1 contrast).
_ERROR_BG = "#ffd9d9"
_WARNING_BG = "#fff1c2"


def yaml_html(text: str, problems: Iterable[Problem]) -> str:
    """``text`` as numbered lines, those the spec's problems cite marked, each with its message."""
    cited: dict[int, list[Problem]] = {}
    for p in problems:
        if p.file is None and p.line is not None:
            cited.setdefault(p.line, []).append(p)
    rows = []
    for n, line in enumerate(text.splitlines(), start=1):
        here = cited.get(n, [])
        style = ""
        note = ""
        if here:
            error = any(p.severity != "warning" for p in here)
            style = f" style='background:{_ERROR_BG if error else _WARNING_BG}'"
            said = "; ".join(f"{p.severity}: {p.message}" for p in here)
            note = f" title='{html.escape(said, quote=True)}'"
        rows.append(
            f"<div{style}{note}><span style='color:#555;user-select:none'>{n:>4} </span>"
            f"{html.escape(line) or ' '}</div>"
        )
    listed = "".join(
        f"<li>line {n}: {html.escape(p.message)}</li>"
        for n, ps in sorted(cited.items())
        for p in ps
    )
    return (
        "<div role='region' tabindex='0' aria-label='the spec as save would write it' "
        "style='font-family:monospace;font-size:0.75em;white-space:pre;overflow-x:auto;"
        "line-height:1.35'>"
        + "".join(rows)
        + "</div>"
        + (f"<ul style='font-size:0.8em'>{listed}</ul>" if listed else "")
    )
