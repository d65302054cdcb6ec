"""The page's collision-pair table: each disabled pair and why, filtered, sorted, toggled.

Why server-side filtering and sorting: viser has no table widget, and what the page shows must
be what the session holds; the table is HTML redrawn from :func:`~robotspec.setup.pairs.pair_rows`
after every change, filtered by the text typed and sorted as chosen. Two lists pick a pair of
links with collision geometry; *disable* and *check* toggle it by hand (``setup/pairs.py``).
"""

from __future__ import annotations

import html
from typing import Any

from robotspec.setup.page_base import PageBase
from robotspec.setup.pairs import SORTS, pair_rows, toggle_pair

__all__ = ["MatrixPart"]

#: Rows drawn at most (the rest are counted; the filter finds them).
_SHOWN = 300


class MatrixPart(PageBase):
    """The collision-pair table of the check & save tab."""

    def _build_matrix(self, gui: Any) -> None:
        robot = self.session.validation.robot
        links = tuple(b.name for b in robot.bodies_with_collisions) if robot else ()
        links = links or ("(no collision geometry)",)
        self._pair_filter = gui.add_text("filter pairs", "")
        self._pair_filter.on_update(self._guarded(lambda _e: self._show_pairs()))
        self._pair_sort = gui.add_dropdown("sort pairs by", SORTS)
        self._pair_sort.on_update(self._guarded(lambda _e: self._show_pairs()))
        self._pair_table = gui.add_html("")
        self._pair_a = gui.add_dropdown("pair: first link", links)
        self._pair_b = gui.add_dropdown("pair: second link", links, initial_value=links[-1])
        self._button(gui, "disable this pair (User)", lambda: self._toggle(disable=True))
        self._button(gui, "check this pair again", lambda: self._toggle(disable=False))

    def _toggle(self, *, disable: bool) -> None:
        said = toggle_pair(
            self.session, str(self._pair_a.value), str(self._pair_b.value), disable=disable
        )
        self._after(self.session.validation, html.escape(said))
        self._show_pairs()

    def _show_pairs(self) -> None:
        """The table of the SRDF's disabled pairs as filtered and sorted now."""
        rows = pair_rows(
            self.session, text=str(self._pair_filter.value), sort=str(self._pair_sort.value)
        )
        if not rows:
            robot = self.session.validation.robot
            none = (
                "no disabled pair matches the filter"
                if robot is not None and robot.srdf is not None
                else "the spec names no SRDF yet: generate the matrix"
            )
            self._pair_table.content = f"<p style='font-size:0.85em'>{none}</p>"
            return
        body = "".join(
            f"<tr><td>{html.escape(r.link1)}</td><td>{html.escape(r.link2)}</td>"
            f"<td>{html.escape(r.reason or '(none given)')}{' ✋' if r.by_hand else ''}</td></tr>"
            for r in rows[:_SHOWN]
        )
        more = (
            f"<caption style='caption-side:bottom'>{len(rows) - _SHOWN} more: filter to see "
            "them</caption>"
            if len(rows) > _SHOWN
            else ""
        )
        self._pair_table.content = (
            "<div role='region' tabindex='0' aria-label='collision pairs not checked' "
            "style='max-height:18em;overflow:auto'>"
            "<table style='font-size:0.75em;border-collapse:collapse;width:100%'>"
            f"<caption style='text-align:left'>{len(rows)} pairs not checked, and why</caption>"
            "<thead><tr><th scope='col'>link</th><th scope='col'>link</th>"
            "<th scope='col'>why</th></tr></thead>"
            f"<tbody>{body}</tbody>{more}</table></div>"
        )
