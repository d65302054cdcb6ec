"""The Robot Raconteur boundary: importing RR, and nodes with safe defaults.

Robot Raconteur ships no type stubs, so everything that comes out of it is ``Any``. This module is
the only place that imports it (through :func:`rr`), which keeps the untyped surface in one spot
and lets ``robotspec`` import without the optional extra installed.

Why an explicit node instead of RR's ``ServerNodeSetup``: the stock setup listens on every
interface, announces itself by UDP broadcast, listens for discovery packets and keeps its NodeID
and lock files in the user's or the system's Robot Raconteur directories (``~/.local/share`` and
``/var/lib`` ... when run as root). A simulator started from a terminal must do none of that
unless asked: :func:`start_server_node` listens on loopback only, starts no discovery unless
``public`` is set, and points all ten of the node's directories (``NodeDirectories``) at one
folder the user chose. The same redirection is available process-wide through the
``ROBOTRACONTEUR_{USER,SYSTEM}_{DATA,CONFIG,STATE,CACHE,RUN}_DIR`` variables; a per-node setting
is used instead so that nothing global changes.

Global state: none of ours. Robot Raconteur itself keeps a process-wide singleton node
(``RobotRaconteurNode.s``, created lazily by the Companion utilities at import); it is never
started or given a transport here, so it opens no socket and writes no file.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from robotspec.driver.rr_names import valid_rr_name
from robotspec.errors import ServiceError
from robotspec.extras import ROBOTRACONTEUR, ROBOTRACONTEUR_COMPANION, missing_extras, require_all

__all__ = [
    "NODE_DIRECTORY_FIELDS",
    "ServerNode",
    "default_state_dir",
    "missing_packages",
    "new_node",
    "remove_own_run_files",
    "rr",
    "start_server_node",
]

#: The ``NodeDirectories`` fields; every one is redirected under the state folder.
NODE_DIRECTORY_FIELDS = (
    "system_data_dir",
    "system_config_dir",
    "system_state_dir",
    "system_cache_dir",
    "system_run_dir",
    "user_data_dir",
    "user_config_dir",
    "user_state_dir",
    "user_cache_dir",
    "user_run_dir",
)

#: The local transport's socket is ``<state>/run/socket/<16 chars>.sock``; UNIX socket paths are
#: limited to 107 bytes, so the state folder path must stay within this many.
MAX_STATE_DIR_CHARS = 107 - len("/run/socket/0123456789abcdef.sock")


#: What serving imports: Robot Raconteur and its companion (the ``robotraconteur`` extra).
_RR_EXTRAS = (ROBOTRACONTEUR, ROBOTRACONTEUR_COMPANION)

#: Set once the structure-class cache is installed (:func:`rr`).
_types_cached: list[bool] = []


def missing_packages() -> list[str]:
    """The optional packages the service needs that are not installed (empty when ready)."""
    return [e.package for e in missing_extras(_RR_EXTRAS)]


def rr() -> Any:
    """The ``RobotRaconteur`` module (untyped: RR has no stubs, so it is ``Any`` here).

    Raises:
        ServiceError: the optional extra is not installed.
    """
    require_all(_RR_EXTRAS, "serving", ServiceError)
    module = importlib.import_module("RobotRaconteur")
    if not _types_cached:
        # One class per structure type, not one per decoded value (see rr_types).
        from robotspec.service.rr_types import install

        install(importlib.import_module("RobotRaconteur.RobotRaconteurPythonUtil"))
        _types_cached.append(True)
    return module


def companion(module: str) -> Any:
    """A ``RobotRaconteurCompanion`` submodule, e.g. ``"Util.InfoFileLoader"`` (untyped)."""
    rr()
    return importlib.import_module(f"RobotRaconteurCompanion.{module}")


def default_state_dir() -> Path:
    """Where nodes keep their NodeID and lock files unless told otherwise.

    ``$XDG_CACHE_HOME/robotspec/rr``, else ``~/.cache/robotspec/rr``: a folder the user owns,
    never a system directory, and one that may be deleted at any time (only the NodeID and the
    device UUID are kept there, and new ones are made if they are gone).
    """
    base = os.environ.get("XDG_CACHE_HOME")
    root = Path(base) if base else Path.home() / ".cache"
    return root / "robotspec" / "rr"


def valid_name(name: str) -> bool:
    """Whether ``name`` is a valid RR node or identifier name (``^[a-zA-Z][a-zA-Z0-9_.-]*$``)."""
    return valid_rr_name(name)


def _node_directories(rrmod: Any, state_dir: Path) -> Any:
    dirs = rrmod.NodeDirectories()
    for name in NODE_DIRECTORY_FIELDS:
        scope, kind, _ = name.split("_")
        sub = state_dir / kind if scope == "user" else state_dir / "system" / kind
        setattr(dirs, name, rrmod.FilesystemPath(str(sub)))
    return dirs


def new_node(state_dir: Path) -> Any:
    """An initialised, transport-less RR node whose directories all live in ``state_dir``.

    Why not the singleton: a node owns its transports, services and directories; a private one
    can be shut down and another started (tests, several servers in one process) without side
    effects on anything else that uses Robot Raconteur in the process.
    """
    rrmod = rr()
    state_dir.mkdir(parents=True, exist_ok=True, mode=0o700)
    node = rrmod.RobotRaconteurNode()
    node.SetNodeDirectories(_node_directories(rrmod, state_dir))
    node.Init()
    node.SetLogLevel(rrmod.LogLevel_Warning)
    if os.environ.get("ROBOTRACONTEUR_LOG_LEVEL"):
        node.SetLogLevelFromEnvVariable()
    return node


@dataclass
class ServerNode:
    """A running server node: the node, its TCP transport and the device identifier lock."""

    node: Any
    tcp: Any
    port: int
    node_name: str
    state_dir: Path
    public: bool
    locks: list[Any] = field(default_factory=list)

    @property
    def host(self) -> str:
        """The address clients on this machine should use."""
        return "127.0.0.1"

    def url(self, service: str) -> str:
        """The connection URL of ``service`` on this node (loopback address)."""
        return f"rr+tcp://{self.host}:{self.port}?service={service}"

    def run_files(self) -> list[Path]:
        """The lock and discovery files this node keeps in the run folder while it runs."""
        run = self.state_dir / "run"
        local = run / "transport" / "local"
        node_id = str(self.node.NodeID).strip("{}")
        return [
            run / "nodeids" / f"{self.node_name}.pid",
            local / "by-nodename" / f"{self.node_name}.pid",
            local / "by-nodename" / f"{self.node_name}.info",
            local / "by-nodeid" / f"{node_id}.pid",
            local / "by-nodeid" / f"{node_id}.info",
        ]

    def shutdown(self) -> None:
        """Stop the node: close the transports and connections, release the locks.

        Robot Raconteur leaves its ``.pid`` and ``.info`` files in the run folder when a node
        shuts down; they are removed here (those that still name this process), while the
        node still holds their locks, so a later start finds no stale ones.
        """
        try:
            remove_own_run_files(self.run_files())
            self.node.Shutdown()
        finally:
            self.locks.clear()


def remove_own_run_files(paths: list[Path]) -> list[Path]:
    """Delete those of ``paths`` that name this process; return the ones deleted.

    A ``.pid`` file must hold this process's PID, an ``.info`` file its ``pid:`` line. Others
    are left alone: another process may have taken the name since.
    """
    pid = str(os.getpid())
    removed = []
    for path in paths:
        try:
            with path.open("r", encoding="utf-8", errors="replace") as f:
                text = f.read(4096)
        except OSError:
            continue
        if path.suffix == ".pid":
            mine = text.strip() == pid
        else:
            mine = any(line.strip() == f"pid: {pid}" for line in text.splitlines())
        if mine:
            try:
                path.unlink()
            except OSError:
                continue
            removed.append(path)
    return removed


#: Robot Raconteur's TcpTransport sets SO_REUSEADDR on its listening sockets only when this
#: variable says so; it reads it (``std::getenv``) each time a server starts.
REUSEADDR_VARIABLE = "ROBOTRACONTEUR_TCP_SERVER_REUSEADDR"


@contextmanager
def _reuse_address() -> Iterator[None]:
    """While inside, a starting TcpTransport server binds with ``SO_REUSEADDR``.

    Why: a driver stopped while a client is connected closes that connection first, so the
    closed connection waits out TCP's TIME_WAIT (60 s on Linux) on the driver's own port, and
    without ``SO_REUSEADDR`` a restarted driver could not listen on that port for a minute
    ("TCP port P is already in use"). With it the port is free at once, while a port another
    server is *listening* on is still refused (that needs ``SO_REUSEPORT``, which is not set).
    The variable is set only around the start and restored after, so nothing else in the
    process (another transport, a child process) sees it.
    """
    previous = os.environ.get(REUSEADDR_VARIABLE)
    os.environ[REUSEADDR_VARIABLE] = "1"
    try:
        yield
    finally:
        if previous is None:
            os.environ.pop(REUSEADDR_VARIABLE, None)
        else:
            os.environ[REUSEADDR_VARIABLE] = previous


def _start_error(exc: BaseException, what: str, hint: str) -> ServiceError:
    return ServiceError(f"{what}: {exc} ({hint})")


def start_server_node(
    *, node_name: str, port: int, public: bool, state_dir: Path | None = None
) -> ServerNode:
    """Start a server node: local transport under ``node_name``, TCP on ``port``.

    The local (UNIX socket) transport takes an exclusive lock on ``node_name`` in the state folder
    and keeps the node's NodeID there, so a second server with the same name fails here instead
    of two drivers answering for one robot. TCP listens on 127.0.0.1 and ::1 only, unless
    ``public``, which listens on every interface and turns on announce and discovery.

    Raises:
        ServiceError: bad name, port in use, name in use, or the state folder is unusable.
    """
    rrmod = rr()
    if not valid_name(node_name):
        raise ServiceError(
            f"invalid node name '{node_name}': use letters, digits, '_', '.' and '-', "
            "starting with a letter"
        )
    if not 0 <= port <= 65535:
        raise ServiceError(f"invalid TCP port {port} (0-65535; 0 picks a free one)")
    state = (state_dir or default_state_dir()).expanduser().resolve()
    if len(os.fsencode(state)) > MAX_STATE_DIR_CHARS:
        raise ServiceError(
            f"the state folder path {state} is {len(os.fsencode(state))} characters long; "
            f"Robot Raconteur's local socket lives in it and allows at most {MAX_STATE_DIR_CHARS}: "
            "give a shorter --state-dir"
        )
    try:
        node = new_node(state)
    except OSError as exc:
        raise ServiceError(f"cannot use state folder {state}: {exc}") from None
    # Start-up failures are reported as ServiceError below; RR would also log them to stderr.
    node.SetLogLevel(rrmod.LogLevel_Disable)
    try:
        local = rrmod.LocalTransport(node)
        try:
            local.StartServerAsNodeName(node_name, False)
        except Exception as exc:  # noqa: BLE001 - RR raises plain Exception
            if "in use" in str(exc).lower():
                raise ServiceError(
                    f"another Robot Raconteur node named '{node_name}' is already running "
                    f"(lock in {state}); stop it, or give this one another --node-name"
                ) from None
            raise _start_error(
                exc, "cannot start the local transport", f"state folder {state}"
            ) from None
        node.RegisterTransport(local)
        tcp = rrmod.TcpTransport(node)
        try:
            with _reuse_address():
                tcp.StartServer(port, not public)
        except Exception as exc:  # noqa: BLE001 - RR raises plain Exception
            if "in use" in str(exc).lower():
                where = "" if public else " on 127.0.0.1"
                raise ServiceError(
                    f"TCP port {port} is already in use{where}; choose another with --port "
                    "(0 picks a free one)"
                ) from None
            raise _start_error(
                exc, f"cannot listen on TCP port {port}", "try another --port"
            ) from None
        if public:
            tcp.EnableNodeAnnounce()
            tcp.EnableNodeDiscoveryListening()
        node.RegisterTransport(tcp)
        actual_port = int(tcp.GetListenPort())
    except BaseException:
        node.Shutdown()
        raise
    node.SetLogLevel(rrmod.LogLevel_Warning)
    if os.environ.get("ROBOTRACONTEUR_LOG_LEVEL"):
        node.SetLogLevelFromEnvVariable()
    return ServerNode(
        node=node, tcp=tcp, port=actual_port, node_name=node_name, state_dir=state, public=public
    )


def start_client_node(state_dir: Path) -> Any:
    """A client node with a TCP transport (no server, no discovery), directories in state_dir.

    Why here: tests and the benchmark connect the same way a user's client would, and must not
    write into the user's Robot Raconteur folders either.
    """
    rrmod = rr()
    node = new_node(state_dir)
    tcp = rrmod.TcpTransport(node)
    node.RegisterTransport(tcp)
    return node
