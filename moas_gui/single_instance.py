"""One server per user: a second ``moas-server FILE`` hands FILE to the running one and exits.

Two servers would fight over the same serial ports, so the first one to start
*claims* the instance and every later one *hands over* its file::

    server = claim("moas-server")
    if server is None:                       # another instance is running
        if hand_over("moas-server", args.file):
            return 0                         # it opens the file; we are done
        print("another moas-server is running but does not answer")
        return 1
    ...                                      # then, on the asyncio loop:
    await server.start(on_open)              # on_open(Path | None), on the loop
    ...
    server.close()

How, without Qt (the headless server uses it too):

- **Who is running** is an exclusive lock on ``<name>.lock`` in a per-user
  directory (``flock`` on POSIX, ``msvcrt.locking`` on Windows).  The system
  drops the lock when its process ends, however it ends, so a crash never
  leaves a false "running" behind.
- **How to reach it** is a Unix-domain socket ``<name>.sock`` beside the lock
  on POSIX (the directory is ``$XDG_RUNTIME_DIR/moas-gui``, else
  ``<temp>/moas-gui-<uid>``, mode 0700 and checked to be the user's own).  On
  Windows it is a TCP port on 127.0.0.1 written with a random token in
  ``<name>.port`` under ``%LOCALAPPDATA%\\moas-gui``; a request must carry the
  token, which only the same user can read.
- **Who gets in** is the program's one door of every listener
  (:mod:`moas_gui.edge.gate`): at most :data:`HAND_OVERS` connections at once, the
  next told why and closed.
- **A stale socket** (the last instance crashed and left its socket file) is
  recognised because its lock is free: :func:`claim` removes it and binds anew.

A ``launch`` holding ``"command"`` (``moas-server --remove-operator``: ``{"command":
"remove_operator", "name": ...}``) is no hand-over: the vetting callback does it, and
the reply is ``{"ok": true, "done": "what it did"}``.  A command the server registered
with :meth:`InstanceServer.start` (``commands``: the station builder's ``"restart"``)
is awaited instead, and its reply is the handler's own object (``ok``, ``done`` or
``error``, and whatever else it tells, such as who transmits); :func:`command` sends one
and never sends it twice.

The request is one line of JSON, ``{"open": "/absolute/path.moas", "launch":
{...}}`` (``open`` null: just show the window; ``launch`` what the second
command line asked for, which the running server may refuse: a headless
server takes no hand-over, other ports cannot be honoured), and the reply
``{"ok": true}`` once the callback has taken it.  Anything else gets ``{"ok":
false, "error": ...}``, a log line, and the server carries on.  On POSIX the
socket also checks its peer's user id (``SO_PEERCRED`` where the system has
it) and refuses any other user, root included.
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import json
import logging
import os
import re
import secrets
import socket
import struct
import sys
import tempfile
import time
from collections.abc import Awaitable, Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Final, Literal

from moas_gui.edge.admission import Admission
from moas_gui.edge.gate import gate_factory
from moas_gui.errors import MoasError

log = logging.getLogger(__name__)

DEFAULT_NAME: Final = "moas-server"
MAX_REQUEST: Final = 64 * 1024
HAND_OVERS: Final = 8
"""Hand-over connections open at once, at most (the program's admission policy, like
every listener's: a second command line hands over one file, once)."""
HAND_OVER_TIMEOUT: Final = 10.0
"""Seconds :func:`hand_over` waits for a starting instance to take the file."""

Transport = Literal["unix", "tcp"]
OpenCallback = Callable[[Path | None], object]
Vetting = Callable[[Path | None, dict[str, object]], str | None]
"""``vet(path, launch)``: why the running instance refuses this hand-over, or None."""
Command = Callable[[dict[str, object]], Awaitable[dict[str, object]]]
"""A command the running instance does (``launch`` in, the reply out), awaited on its loop."""


@dataclass(frozen=True, slots=True)
class HandOver:
    """How a hand-over went: ``taken``, or ``refusal`` says why not; neither when nobody answered."""

    taken: bool
    refusal: str | None = None
    running: bool = True
    """False when no instance runs at all."""
    done: str | None = None
    """What the running instance did for a command (``launch`` with ``"command"``)."""
    answer: Mapping[str, object] = field(default_factory=dict, compare=False)
    """The whole reply (a command's handler may tell more than ``done`` or ``error``)."""
    trouble: str | None = None
    """Why nothing was heard from a running instance (a refused or dropped connection)."""


class InstanceError(MoasError, OSError):
    """The per-user instance directory is unsafe or unusable; the message says why."""


def default_transport() -> Transport:
    return "tcp" if sys.platform == "win32" or not hasattr(socket, "AF_UNIX") else "unix"


def instance_dir() -> Path:
    """The per-user directory for the lock and the socket (made if missing)."""
    if sys.platform == "win32":
        base = os.environ.get("LOCALAPPDATA") or tempfile.gettempdir()
        return Path(base) / "moas-gui"
    runtime = os.environ.get("XDG_RUNTIME_DIR", "")
    if runtime and os.path.isabs(runtime) and os.path.isdir(runtime):
        return Path(runtime) / "moas-gui"
    return Path(tempfile.gettempdir()) / f"moas-gui-{os.getuid()}"


def _prepare(directory: Path) -> None:
    """Make ``directory`` (0700) or check that the existing one is this user's alone."""
    try:
        directory.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError as exc:
        raise InstanceError(exc.errno, f"cannot make the instance directory {directory}: "
                                       f"{exc.strerror}") from exc
    if sys.platform == "win32":
        return
    info = directory.lstat()
    if directory.is_symlink() or info.st_uid != os.getuid():
        raise InstanceError(f"{directory} belongs to someone else (or is a link); "
                            "remove it or set XDG_RUNTIME_DIR")
    if info.st_mode & 0o077:
        raise InstanceError(f"{directory} can be read or written by other users "
                            f"(mode {info.st_mode & 0o777:o}); make it 700")


def _safe_name(name: str) -> str:
    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}", name):
        raise ValueError(f"instance name {name!r}: use letters, digits, '.', '_' and '-'")
    return name


# -- the lock ------------------------------------------------------------------------------


def _lock(path: Path) -> int | None:
    """An open descriptor holding the exclusive lock on ``path``, or None if someone has it."""
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o600)
    try:
        if sys.platform == "win32":
            import msvcrt

            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        else:
            import fcntl

            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return None
    return fd


def _unlock(fd: int) -> None:
    try:
        if sys.platform == "win32":
            import msvcrt

            os.lseek(fd, 0, os.SEEK_SET)
            msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)
        else:
            import fcntl

            fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)


def _someone_holds(path: Path) -> bool:
    fd = _lock(path)
    if fd is None:
        return True
    _unlock(fd)
    return False


# -- the server side -----------------------------------------------------------------------


class InstanceServer:
    """The running instance: holds the lock and the listening socket; see :func:`claim`."""

    def __init__(self, name: str, directory: Path, lock_fd: int, sock: socket.socket,
                 transport: Transport, token: str) -> None:
        self.name = name
        self.directory = directory
        self.transport = transport
        self._lock_fd: int | None = lock_fd
        self._sock = sock
        self._token = token
        self._server: asyncio.AbstractServer | None = None
        self._on_open: OpenCallback | None = None
        self._vet: Vetting | None = None
        self.admission = Admission(HAND_OVERS, HAND_OVERS, what="hand-over connections")
        """The hand-over connections open now (the program's admission policy)."""
        self._commands: Mapping[str, Command] = {}

    @property
    def address(self) -> str:
        """The socket path, or ``127.0.0.1:port``."""
        where = self._sock.getsockname()
        return str(where) if self.transport == "unix" else f"{where[0]}:{where[1]}"

    async def start(self, on_open: OpenCallback, vet: Vetting | None = None,
                    commands: Mapping[str, Command] | None = None) -> None:
        """Serve hand-overs on the running loop; ``on_open(path)`` is called for each
        that ``vet(path, launch)`` (when given) does not refuse; a launch whose
        ``"command"`` names one of ``commands`` is given to that handler, whose reply
        is sent back."""
        self._on_open = on_open
        self._vet = vet
        # through the one door of every listener: at most HAND_OVERS at once
        door = gate_factory(
            self.admission, self._serve,
            front="hand-over connection", limit=MAX_REQUEST,
            refusal=lambda why: json.dumps({"ok": False, "error": why}).encode() + b"\n")
        loop = asyncio.get_running_loop()
        self._commands = dict(commands or {})
        if self.transport == "unix":
            if sys.platform == "win32":
                raise InstanceError("Unix sockets are not on Windows: use the tcp transport")
            self._server = await loop.create_unix_server(door, sock=self._sock)
        else:
            self._server = await loop.create_server(door, sock=self._sock)

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        try:
            async with asyncio.timeout(5):
                line = await reader.readline()
            error = self._foreign_peer(writer)
            path: Path | None = None
            launch: dict[str, object] = {}
            if error is None:
                path, launch, error = self._read_request(line)
            handler = self._commands.get(str(launch.get("command"))) if error is None else None
            if handler is not None:
                answer = await self._command(handler, launch)
                writer.write(json.dumps(answer).encode() + b"\n")
                await writer.drain()
                return
            if error is None and "command" in launch and self._vet is not None:
                # a command for the running server (moas-server --remove-operator): vet
                # does it and says what it did; nothing is opened
                done = self._vet(None, launch)
                log.info("Another moas-server asked: %s", done)
                writer.write(json.dumps({"ok": True, "done": done}).encode() + b"\n")
                await writer.drain()
                return
            if error is None and self._vet is not None:
                error = self._vet(path, launch)
            if error is None:
                error = self._deliver(path)
            reply = {"ok": True} if error is None else {"ok": False, "error": error}
            if error is not None:
                log.warning("Refused a hand-over on %s: %s", self.address, error)
            writer.write(json.dumps(reply).encode() + b"\n")
            await writer.drain()
        except (TimeoutError, ValueError, ConnectionError) as exc:
            log.warning("Hand-over connection on %s dropped: %s", self.address,
                        exc or type(exc).__name__)
        finally:
            writer.close()
            with contextlib.suppress(ConnectionError):
                await writer.wait_closed()

    @staticmethod
    async def _command(handler: Command, launch: dict[str, object]) -> dict[str, object]:
        try:
            return await handler(launch)
        except Exception as exc:
            log.exception("The command %s of another moas-server failed", launch.get("command"))
            return {"ok": False, "error": f"the running instance could not do it: {exc}"}

    def _foreign_peer(self, writer: asyncio.StreamWriter) -> str | None:
        """Why the peer may not hand over (another user), or None."""
        sock = writer.get_extra_info("socket")
        if (sys.platform == "win32" or self.transport != "unix" or sock is None
                or not hasattr(socket, "SO_PEERCRED")):
            return None
        try:
            credentials = sock.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED,
                                          struct.calcsize("3i"))
        except OSError as exc:
            return f"cannot tell who is asking ({exc.strerror or exc})"
        _pid, uid, _gid = struct.unpack("3i", credentials)
        if uid != os.getuid():
            return f"user id {uid} is not this server's user; only the same user may hand over"
        return None

    def _read_request(self, line: bytes) -> tuple[Path | None, dict[str, object], str | None]:
        try:
            request = json.loads(line)
        except (UnicodeDecodeError, json.JSONDecodeError):
            return None, {}, f"not a JSON line: {line[:60]!r}"
        if not isinstance(request, dict) or "open" not in request:
            return None, {}, "the request has no 'open'"
        if self.transport == "tcp" and not hmac.compare_digest(
                str(request.get("token", "")), self._token):
            return None, {}, "wrong token (not from this user)"
        launch = request.get("launch", {})
        if not isinstance(launch, dict):
            return None, {}, "'launch' must be an object"
        target = request["open"]
        if target is None:
            return None, launch, None
        if not isinstance(target, str) or not target or "\0" in target:
            return None, {}, f"'open' must be a path or null, not {target!r:.60}"
        return Path(target), launch, None

    def _deliver(self, path: Path | None) -> str | None:
        assert self._on_open is not None
        # said first: what the callback logs (asking, "already open") follows from it
        log.info("Another moas-server handed over %s", path or "(no file: show the window)")
        try:
            self._on_open(path)
        except Exception as exc:
            log.exception("Opening %s handed over by another moas-server failed", path)
            return f"the running instance could not take it: {exc}"
        return None

    def close(self) -> None:
        """Stop serving, remove the socket (or port file) and release the lock (idempotent)."""
        if self._server is not None:
            self._server.close()
            self._server = None
        if self._lock_fd is None:
            return
        address_file = self.directory / (
            f"{self.name}.sock" if self.transport == "unix" else f"{self.name}.port")
        with contextlib.suppress(OSError):
            self._sock.close()
        with contextlib.suppress(FileNotFoundError):
            address_file.unlink()
        _unlock(self._lock_fd)
        self._lock_fd = None


def claim(name: str = DEFAULT_NAME, *, directory: Path | None = None,
          transport: Transport | None = None) -> InstanceServer | None:
    """Become the running instance, or return ``None`` when another one runs.

    Raises :class:`InstanceError` when the per-user directory is unsafe.
    """
    name = _safe_name(name)
    directory = directory or instance_dir()
    transport = transport or default_transport()
    _prepare(directory)
    lock_fd = _lock(directory / f"{name}.lock")
    if lock_fd is None:
        return None
    try:
        if transport == "unix":
            sock, token = _bind_unix(directory / f"{name}.sock"), ""
        else:
            sock, token = _bind_tcp(directory / f"{name}.port")
    except BaseException:
        _unlock(lock_fd)
        raise
    return InstanceServer(name, directory, lock_fd, sock, transport, token)


def _bind_unix(path: Path) -> socket.socket:
    if sys.platform == "win32":
        raise InstanceError("Unix sockets are not on Windows: use the tcp transport")
    if len(os.fsencode(path)) > 100:
        raise InstanceError(f"the socket path {path} is too long for a Unix socket; "
                            "set XDG_RUNTIME_DIR to a shorter directory")
    if path.exists() or path.is_symlink():
        log.info("Removing %s, left by a moas-server that ended without cleaning up", path)
        path.unlink()
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        sock.bind(str(path))
        os.chmod(path, 0o600)
        sock.listen(16)
        sock.setblocking(False)
    except BaseException:
        sock.close()
        raise
    return sock


def _bind_tcp(port_file: Path) -> tuple[socket.socket, str]:
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        sock.bind(("127.0.0.1", 0))
        sock.listen(16)
        sock.setblocking(False)
        token = secrets.token_hex(16)
        scratch = port_file.with_suffix(".tmp")
        fd = os.open(scratch, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, "w", encoding="utf-8") as out:
            json.dump({"port": sock.getsockname()[1], "token": token}, out)
        os.replace(scratch, port_file)
    except BaseException:
        sock.close()
        raise
    return sock, token


# -- the client side -----------------------------------------------------------------------


def hand_over(name: str = DEFAULT_NAME, path: str | os.PathLike[str] | None = None, *,
              directory: Path | None = None, transport: Transport | None = None,
              timeout: float = HAND_OVER_TIMEOUT) -> bool:
    """Give ``path`` (made absolute) to the running instance; True once it has taken it.

    False at once when no instance runs; False after ``timeout`` seconds when
    one runs but does not answer; False when it refuses.
    """
    return offer(name, path, directory=directory, transport=transport, timeout=timeout).taken


def offer(name: str = DEFAULT_NAME, path: str | os.PathLike[str] | None = None,
          launch: dict[str, object] | None = None, *, directory: Path | None = None,
          transport: Transport | None = None, timeout: float = HAND_OVER_TIMEOUT) -> HandOver:
    """Like :func:`hand_over`, with what this launch asked for, and the refusal's reason."""
    name = _safe_name(name)
    directory = directory or instance_dir()
    transport = transport or default_transport()
    request: dict[str, object] = {
        "open": None if path is None else str(Path(path).expanduser().absolute()),
        "launch": launch or {}}
    deadline = time.monotonic() + timeout
    while True:
        if not _someone_holds(directory / f"{name}.lock"):
            return HandOver(taken=False, running=False)
        try:
            return _ask(directory, name, transport, request, deadline)
        except (OSError, ValueError) as exc:
            if time.monotonic() >= deadline:
                log.warning("The running moas-server did not take %s: %s",
                            request["open"] or "a launch without a file", exc)
                return HandOver(taken=False)
            time.sleep(0.05)


def _ask(directory: Path, name: str, transport: Transport, request: dict[str, object],
         deadline: float) -> HandOver:
    if transport == "unix":
        if sys.platform == "win32":
            raise InstanceError("Unix sockets are not on Windows: use the tcp transport")
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        address: str | tuple[str, int] = str(directory / f"{name}.sock")
    else:
        details = json.loads((directory / f"{name}.port").read_text(encoding="utf-8"))
        request = {**request, "token": str(details["token"])}
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        address = ("127.0.0.1", int(details["port"]))
    with sock:
        sock.settimeout(max(0.05, deadline - time.monotonic()))
        sock.connect(address)
        sock.sendall(json.dumps(request).encode() + b"\n")
        reply = b""
        while not reply.endswith(b"\n"):
            sock.settimeout(max(0.05, deadline - time.monotonic()))
            chunk = sock.recv(4096)
            if not chunk:
                raise ConnectionResetError("the running instance closed the connection")
            reply += chunk
    answer = json.loads(reply)
    if not isinstance(answer, dict):
        raise ValueError(  # noqa: TRY004 (a bad answer, caught as the others)
            f"the running instance answered {answer!r:.60}, not an object")
    if answer.get("ok") and "done" in answer:
        return HandOver(taken=True, done=str(answer["done"]), answer=answer)
    if not answer.get("ok"):
        log.info("The running moas-server refused %s: %s",
                 request["open"] or "a launch without a file", answer.get("error"))
        return HandOver(taken=False, refusal=str(answer.get("error")), answer=answer)
    return HandOver(taken=True, answer=answer)


def command(name: str = DEFAULT_NAME, launch: dict[str, object] | None = None, *,
            directory: Path | None = None, transport: Transport | None = None,
            timeout: float = HAND_OVER_TIMEOUT) -> HandOver:
    """Ask the running instance to do ``launch`` (with its ``"command"``), once.

    Unlike :func:`offer` it never sends again: a command may act (a restart) before
    its connection drops, so trouble is told (``trouble``), not tried again.  No
    instance running: ``running`` is False at once.
    """
    name = _safe_name(name)
    directory = directory or instance_dir()
    transport = transport or default_transport()
    if not (directory / f"{name}.lock").exists():
        return HandOver(taken=False, running=False)
    try:
        _prepare(directory)  # this user's own directory, nobody else's
        running = _someone_holds(directory / f"{name}.lock")
    except OSError as exc:
        return HandOver(taken=False, trouble=str(exc))
    if not running:
        return HandOver(taken=False, running=False)
    request: dict[str, object] = {"open": None, "launch": launch or {}}
    try:
        return _ask(directory, name, transport, request, time.monotonic() + timeout)
    except (OSError, ValueError) as exc:
        log.warning("The running moas-server did not answer %s: %s",
                    (launch or {}).get("command"), exc or type(exc).__name__)
        return HandOver(taken=False, trouble=str(exc) or type(exc).__name__)


__all__ = [
    "DEFAULT_NAME", "Command", "HandOver", "InstanceError", "InstanceServer", "OpenCallback",
    "Vetting", "claim", "command", "default_transport", "hand_over", "instance_dir", "offer",
]
