"""Who may use the setup page: its own origin, holding this run's secret.

Why: the page edits a spec and saves files as the user, over a websocket. A browser lets any web
page open a websocket to ``127.0.0.1``, and viser accepts every handshake, so a page the user
merely visits could read the assistant's state and send it changes; bound to ``0.0.0.0``, anyone
on the network could. As notebook servers do, each run makes a secret (``token``) that is part
of the address printed with the URL. Opening that address sets a cookie (``HttpOnly``,
``SameSite=Strict``) that the page's own websocket then presents; a client without a browser
may give the token in the websocket's query (``ws://host:port/?token=...``). A handshake is
refused (HTTP 403, before viser sees it) when:

* it carries no valid token (query or cookie), whatever its origin;
* it is a browser's (it has an ``Origin``) and that origin is not the page's own host and port;
* the server listens on loopback only and the ``Host`` asked for is not a loopback name (a DNS
  rebinding page names its own host, resolved to 127.0.0.1).

viser has no hook for this, so :func:`start_guarded` wraps websockets' ``serve`` for the moment
viser starts its server, inserting :meth:`PageAccess.process_request` in front of viser's own
request handler; when viser starts no server through it (another viser), the page is refused
with a clear error rather than served unguarded.
"""

from __future__ import annotations

import contextlib
import hmac
import http
import ipaddress
import secrets
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from http.cookies import CookieError, SimpleCookie
from typing import TYPE_CHECKING, Any, TypeVar
from urllib.parse import parse_qs, urlsplit

from robotspec.errors import ServiceError

if TYPE_CHECKING:
    from websockets.asyncio.server import ServerConnection
    from websockets.http11 import Request, Response

__all__ = ["PageAccess", "is_loopback", "start_guarded"]

T = TypeVar("T")

#: viser's own request handler (serves its client; None for a websocket upgrade).
ProcessRequest = Callable[["ServerConnection", "Request"], "Response | None"]

_PATCH_LOCK = threading.Lock()


def is_loopback(host: str) -> bool:
    """Whether ``host`` (an interface to bind, or a Host header's name) is this machine only."""
    name = host.strip("[]").lower()
    if name == "localhost" or name.endswith(".localhost"):
        return True
    try:
        return ipaddress.ip_address(name).is_loopback
    except ValueError:
        return False


def _token_of(request: Request, cookie_name: str) -> str | None:
    """The token a request presents: ``?token=`` in its address, else the page's cookie."""
    query = parse_qs(urlsplit(request.path).query)
    if query.get("token"):
        return query["token"][0]
    jar = SimpleCookie()
    for header in request.headers.get_all("Cookie"):
        with contextlib.suppress(CookieError):
            jar.load(header)
    morsel = jar.get(cookie_name)
    return morsel.value if morsel is not None else None


@dataclass(frozen=True)
class PageAccess:
    """This run's secret and the rule for one server (``loopback``: bound to this machine only)."""

    loopback: bool
    token: str = field(default_factory=lambda: secrets.token_urlsafe(24), repr=False)

    @classmethod
    def for_host(cls, host: str) -> PageAccess:
        """The access of a server bound to ``host`` (a fresh secret each time)."""
        return cls(loopback=is_loopback(host))

    def address(self, url: str) -> str:
        """The page's address with its secret (``http://localhost:8080/?token=...``)."""
        return f"{url.rstrip('/')}/?token={self.token}"

    @staticmethod
    def cookie_name(port: int) -> str:
        """One cookie per port: cookies ignore ports, and two servers may run side by side."""
        return f"robotspec-setup-{port}"

    def refusal(self, request: Request, port: int) -> str | None:
        """Why ``request`` is refused, or None when it may go on to viser."""
        headers = request.headers
        if len(headers.get_all("Host")) != 1 or len(headers.get_all("Origin")) > 1:
            return "a request names one host and at most one origin"
        host = headers["Host"]
        try:
            name = urlsplit(f"//{host}").hostname or ""
        except ValueError:
            return f"'{host}' is no host name"
        if self.loopback and not is_loopback(name):
            return f"this page is served to this machine only, not to host '{host}'"
        given = _token_of(request, self.cookie_name(port))
        if given is None or not hmac.compare_digest(given.encode(), self.token.encode()):
            return (
                "open the address `robotspec setup` printed: it carries the page's token "
                "(...?token=...)"
            )
        origin = headers.get("Origin")
        if origin is not None:
            parts = urlsplit(origin)
            own = parts.scheme in ("http", "https") and parts.netloc.lower() == host.lower()
            if not own or parts.path not in ("", "/"):
                return f"a page from {origin} may not use this page's connection"
        return None

    def process_request(
        self, viser_handler: ProcessRequest | None
    ) -> Callable[[ServerConnection, Request], Response | None]:
        """The handshake hook (websockets' ``process_request``): this fence, then viser's."""

        def process(connection: ServerConnection, request: Request) -> Response | None:
            port = int(connection.local_address[1])
            reason = self.refusal(request, port)
            if reason is not None:
                return connection.respond(http.HTTPStatus.FORBIDDEN, f"robotspec setup: {reason}\n")
            response = viser_handler(connection, request) if viser_handler is not None else None
            if response is not None and response.status_code == 200:
                _add_page_additions(response)
            query = parse_qs(urlsplit(request.path).query)
            if response is not None and query.get("token") and response.status_code == 200:
                # The address with the token was opened: the page's websocket presents the
                # cookie from now on (a browser sends it to this host only, never cross-site).
                response.headers["Set-Cookie"] = (
                    f"{self.cookie_name(port)}={self.token}; Path=/; HttpOnly; SameSite=Strict"
                )
            return response

        return process


def _add_page_additions(response: Response) -> None:
    """The page's HTML with the keyboard and screen-reader additions (``setup/page_a11y.py``)."""
    if not response.headers.get("Content-Type", "").startswith("text/html"):
        return
    import gzip

    from robotspec.setup.page_a11y import add_to_page

    zipped = response.headers.get("Content-Encoding", "identity") == "gzip"
    page = gzip.decompress(response.body) if zipped else bytes(response.body)
    added = add_to_page(page)
    if added == page:
        return
    response.body = gzip.compress(added, compresslevel=6) if zipped else added
    del response.headers["Content-Length"]  # websockets' Headers adds, never replaces
    response.headers["Content-Length"] = str(len(response.body))


def start_guarded(access: PageAccess, start: Callable[[], T], stop: Callable[[T], None]) -> T:
    """``start()`` (which starts a viser server), every handshake of it checked by ``access``.

    When viser started no server through websockets' ``serve`` (a viser this module does not
    know), what ``start`` made is stopped again and a
    :class:`~robotspec.errors.ServiceError` says why: that server would be unguarded.
    """
    import websockets.asyncio.server as ws_server

    with _PATCH_LOCK:
        original: Any = ws_server.serve
        guarded = 0

        def serve(handler: Any, *args: Any, **kwargs: Any) -> Any:
            nonlocal guarded
            if str(getattr(handler, "__module__", "")).startswith("viser."):
                kwargs["process_request"] = access.process_request(kwargs.get("process_request"))
                guarded += 1
            return original(handler, *args, **kwargs)

        ws_server.serve = serve  # type: ignore[misc,assignment]
        try:
            made = start()
        finally:
            ws_server.serve = original  # type: ignore[misc]
    if not guarded:
        import viser

        stop(made)
        raise ServiceError(
            f"viser {getattr(viser, '__version__', '?')} did not start its server through "
            "websockets' serve(process_request=...), so robotspec cannot let only this page's "
            "own origin with its token in; install a viser robotspec is tested with "
            "(pip install 'viser>=1.0,<2')",
            kind="service",
            name="viser",
        )
    return made
