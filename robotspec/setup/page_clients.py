"""Each browser tab of the setup page: its own pick, and who else has the page open.

Why picks per tab: the session is one truth every tab edits, but a pick is where one person is
pointing; with one shared pick, tab B's click became tab A's arm tip. So every pick is kept per
viser client (the tab), shown in that tab only (its own ``link`` list, and the picked link drawn
in red lines in its own 3D scene), and a button acts on the pick of the tab that pressed it.
Callbacks learn their tab from the event (``event.client``); the page keeps it in a thread-local
while the callback runs (viser runs callbacks on a pool). A pick made without a tab (the tests,
the server itself) is the pick of "no tab", and :attr:`selected` outside a callback is the last
pick of any tab.
"""

from __future__ import annotations

import threading
from typing import Any

from robotspec.errors import RobotSpecError
from robotspec.setup.page_base import PageBase

__all__ = ["PICK_COLOUR", "ClientsPart"]

#: The picked link's outline, in its tab's scene only.
PICK_COLOUR = (230, 20, 20)


class ClientsPart(PageBase):
    """The tabs' picks and presence, for :class:`~robotspec.setup.page.SetupPage`."""

    links: tuple[str, ...]
    _groups: dict[str, str]

    def _build_clients(self, gui: Any) -> None:
        """Where each tab's own pick list and presence line go (a shared folder)."""
        self._clients_lock = threading.RLock()
        self._here = threading.local()
        #: The pick of each tab (None: no tab), the last pick of any, each tab's handles.
        self._picks: dict[int | None, str] = {}
        self._last_pick: str | None = None
        self._lists: dict[int, Any] = {}
        self._presence: dict[int, Any] = {}
        self._marks: dict[int, list[Any]] = {}
        self._tab_slot = gui.add_folder("this tab")
        self.server.on_client_connect(self._joined)
        self.server.on_client_disconnect(self._left)

    # ------------------------------------------------------------------ which tab
    @property
    def client_id(self) -> int | None:
        """The tab whose callback runs on this thread (None outside one)."""
        return getattr(self._here, "client", None)

    def _entered(self, event: Any) -> None:
        client = getattr(event, "client", None)
        self._here.client = getattr(client, "client_id", None)

    def _exited(self) -> None:
        self._here.client = None

    @property
    def selected(self) -> str | None:
        """The pick of the tab acting now, or (outside a tab's callback) the last pick."""
        client = self.client_id
        with self._clients_lock:
            return self._picks.get(client) if client is not None else self._last_pick

    def pick_list(self, client_id: int) -> Any:
        """The ``link`` list shown in one tab (the browser test chooses in it)."""
        return self._lists[client_id]

    # ------------------------------------------------------------------ picking
    def select(self, link: str) -> None:
        """Pick a link for the tab acting now: its list, its outline in 3D, the message."""
        if link not in self.links:
            raise RobotSpecError(f"no link '{link}' in the robot", kind="link", name=link)
        client = self.client_id
        with self._clients_lock:
            self._picks[client] = link
            self._last_pick = link
            if client is not None:
                listed = self._lists.get(client)
                if listed is not None and listed.value != link:
                    listed.value = link
                self._mark(client, link)
        part = self._groups.get(link)
        self.say(f"picked **{link}**" + (f" (in {part})" if part else ""))

    def _mark(self, client_id: int, link: str) -> None:
        """The picked link drawn in red lines, in this tab's own scene (no other tab sees it)."""
        handle = self.server.get_clients().get(client_id)
        for old in self._marks.pop(client_id, []):
            old.remove()
        if handle is None:
            return
        marks = []
        for k, part in enumerate(self.viewer.scene.parts):
            if part.body == link:
                t = part.triangles
                marks.append(
                    handle.scene.add_mesh_simple(
                        f"/robot/{link}/picked_{k}",
                        t.vertices,
                        t.faces,
                        color=PICK_COLOUR,
                        wireframe=True,
                    )
                )
        marks.append(handle.scene.add_label(f"/robot/{link}/picked_label", link))
        self._marks[client_id] = marks

    # ------------------------------------------------------------------ tabs coming and going
    def _joined(self, client: Any) -> None:
        cid = int(client.client_id)
        with self._clients_lock, self._tab_slot:
            listed = client.gui.add_dropdown("link", self.links, initial_value=self.links[0])
            listed.on_update(self._guarded(lambda e: self.select(str(e.target.value))))
            self._lists[cid] = listed
            self._presence[cid] = client.gui.add_markdown("")
        self._show_presence()

    def _left(self, client: Any) -> None:
        cid = int(client.client_id)
        with self._clients_lock:
            self._lists.pop(cid, None)
            self._presence.pop(cid, None)
            self._marks.pop(cid, None)
            self._picks.pop(cid, None)
        self._show_presence()

    def _show_presence(self) -> None:
        """Each tab says which it is and how many others have the page open."""
        with self._clients_lock:
            ids = sorted(self._presence)
            for n, cid in enumerate(ids, start=1):
                others = len(ids) - 1
                text = (
                    f"<small>tab {n} of {len(ids)}: {others} other tab{'s' if others != 1 else ''}"
                    " open; its changes show here, its picks stay its own</small>"
                    if others
                    else "<small>no other tab has this page open</small>"
                )
                if self._presence[cid].content != text:
                    try:
                        self._presence[cid].content = text
                    except RuntimeError:  # that tab's handles went with it (it closed meanwhile)
                        continue
