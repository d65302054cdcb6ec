"""The setup assistant's fences (issue 31): its page is the user's alone, its writes stay put.

The page: a real websocket client (the ``websockets`` package viser itself uses) connects as a
page from another site, without the run's token, with a wrong one, and as the page itself; only
the last gets the assistant's state. The writes: "save as" stays in the output's folder (unless
the command line allows another), never replaces a file of the robot, and a refused save leaves
nothing behind; the collision matrix waits in the session until "save" and never takes the
name of the robot's own SRDF.
"""

from __future__ import annotations

import urllib.error
import urllib.request
from collections.abc import Iterator
from typing import Any

import pytest

from robotspec.setup.access import PageAccess, is_loopback
from tests.conftest import erd_robots


# ---------------------------------------------------------------------------------- the page
@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    pytest.importorskip("viser")
    from robotspec.setup import SetupSession
    from robotspec.setup.page import SetupPage

    urdf = erd_robots() / "xarm_description" / "urdf" / "xarm7.urdf"
    out = tmp_path_factory.mktemp("page") / "xarm.yaml"
    p = SetupPage(SetupSession.open(str(urdf), output=out), port=0)
    yield p
    p.stop()


def _connect(page: Any, query: str = "", *, host: str = "127.0.0.1", **kw: Any) -> str:
    """Open the page's websocket; what came back first ('state N bytes') or why it was refused.

    ``host`` is the name the request gives (its Host header); the socket goes to 127.0.0.1.
    """
    import socket

    import viser
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    port = page.viewer.port
    sock = socket.create_connection(("127.0.0.1", port), timeout=20)
    try:
        with connect(
            f"ws://{host}:{port}/{query}",
            sock=sock,
            subprotocols=[f"viser-v{viser.__version__}"],
            max_size=None,
            open_timeout=20,
            **kw,
        ) as ws:
            message = ws.recv(timeout=20)
            return f"state {len(message)} bytes"
    except InvalidStatus as exc:
        body = exc.response.body.decode()
        return f"refused {exc.response.status_code}: {body}"
    finally:
        sock.close()


def test_a_page_from_another_site_is_refused_and_gets_no_state(page: Any) -> None:
    token = page.access.token
    got = _connect(page, origin="http://evil.example")
    assert got.startswith("refused 403") and "token" in got
    # Even a page that somehow holds the token: another origin is refused by name.
    got = _connect(page, f"?token={token}", origin="http://evil.example")
    assert got == (
        "refused 403: robotspec setup: a page from http://evil.example may not use this "
        "page's connection\n"
    )
    # The page's own origin with a port of another server is another origin.
    other = f"http://127.0.0.1:{page.viewer.port + 1}"
    assert _connect(page, f"?token={token}", origin=other).startswith("refused 403")


def test_no_token_or_a_wrong_one_is_refused(page: Any) -> None:
    for query in ("", "?token=", "?token=wrong", f"?token={page.access.token[:-1]}"):
        assert _connect(page, query).startswith("refused 403: robotspec setup: open the address")
    own = f"http://127.0.0.1:{page.viewer.port}"
    assert _connect(page, origin=own).startswith("refused 403")  # own origin, no token
    cookie = {"Cookie": f"{PageAccess.cookie_name(page.viewer.port)}=nope"}
    assert _connect(page, origin=own, additional_headers=cookie).startswith("refused 403")


def test_the_token_and_the_own_origin_get_the_page(page: Any) -> None:
    port = page.viewer.port
    token = page.access.token
    assert page.url.endswith(f":{port}/?token={token}")  # printed as notebook servers do
    assert _connect(page, f"?token={token}").startswith("state ")  # a client without a browser
    own = f"http://127.0.0.1:{port}"
    assert _connect(page, f"?token={token}", origin=own).startswith("state ")
    # A browser: opening the printed address sets the cookie its websocket then presents.
    with urllib.request.urlopen(page.url.replace("localhost", "127.0.0.1"), timeout=20) as resp:
        assert resp.status == 200
        cookie = resp.headers["Set-Cookie"]
    assert "HttpOnly" in cookie and "SameSite=Strict" in cookie
    jar = {"Cookie": cookie.split(";")[0]}
    assert _connect(page, origin=own, additional_headers=jar).startswith("state ")
    # The page without its token says what to open, and serves nothing else.
    with pytest.raises(urllib.error.HTTPError) as exc:
        urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=20)
    assert exc.value.code == 403 and b"carries the page's token" in exc.value.read()


def test_a_loopback_page_refuses_other_host_names(page: Any) -> None:
    """DNS rebinding: a page of evil.example resolved to 127.0.0.1 names its own host."""
    token = page.access.token
    port = page.viewer.port
    got = _connect(
        page, f"?token={token}", host="evil.example", origin=f"http://evil.example:{port}"
    )
    assert got.startswith("refused 403") and "this machine only" in got
    assert _connect(page, f"?token={token}", host="localhost").startswith("state ")
    two_hosts = {"additional_headers": {"Host": f"127.0.0.1:{port}"}}
    assert "one host" in _connect(page, f"?token={token}", **two_hosts)
    assert is_loopback("127.0.0.1") and is_loopback("localhost") and is_loopback("[::1]")
    assert not is_loopback("0.0.0.0") and not is_loopback("evil.example")
    assert not PageAccess.for_host("0.0.0.0").loopback and PageAccess.for_host("::1").loopback
    assert PageAccess.for_host("x").token != PageAccess.for_host("x").token  # one per run


def test_a_viser_without_the_hook_is_refused_not_served_unguarded() -> None:
    from robotspec.errors import ServiceError
    from robotspec.setup.access import start_guarded

    stopped: list[str] = []
    with pytest.raises(ServiceError, match="cannot let only this page's own origin"):
        start_guarded(PageAccess(loopback=True), lambda: "server", stopped.append)
    assert stopped == ["server"]
