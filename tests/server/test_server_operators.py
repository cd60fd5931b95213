"""moas-server's operators and TLS as real processes: --add/--list/--remove-operator,
--fingerprint, a running headless server reached by --remove-operator, both ports over
TLS for ``openssl s_client``, and the desktop client's connection pinning the fingerprint."""

from __future__ import annotations

import asyncio
import json
import os
import shutil
import socket
import ssl
import stat
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from helpers import free_port, until, wait_for
from logged_server import LoggedServer, module_server

from moas_gui.client.connection import ClientConnection
from moas_gui.operators import FILE_NAME, OperatorBook, Role
from moas_gui.places import APP
from moas_gui.tls import client_context, format_fingerprint

pytestmark = [pytest.mark.realtime, pytest.mark.shared]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def environment(tmp_path: Path, runtime: Path) -> dict[str, str]:
    return dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_CONFIG_HOME=str(tmp_path / "cfg"),
                XDG_STATE_HOME=str(tmp_path / "state"), PYTHONUNBUFFERED="1",
                QT_QPA_PLATFORM="offscreen")


def server(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "moas_gui.cli.server", *args], env=env,
                          capture_output=True, text=True, check=False, timeout=60)


def book_of(env: dict[str, str]) -> OperatorBook:
    """The operators file the server started with ``env`` reads."""
    return OperatorBook(Path(env["XDG_CONFIG_HOME"]) / APP / FILE_NAME)


def hello(port: int, token: str | None, *, context: ssl.SSLContext | None = None,
          source: str = "127.0.0.2", name: str = "test") -> tuple[dict, socket.socket]:
    raw = socket.create_connection(("127.0.0.1", port), timeout=10,
                                   source_address=(source, 0))
    conn: socket.socket = (context.wrap_socket(raw, server_hostname="127.0.0.1")
                           if context is not None else raw)
    message: dict[str, object] = {"id": 1, "cmd": "hello", "client": name}
    if token is not None:
        message["token"] = token
    conn.sendall(json.dumps(message).encode() + b"\n")
    reader = conn.makefile("rb")
    while True:
        line = reader.readline()
        if not line:
            return {"closed": True}, conn
        reply = json.loads(line)
        if reply.get("id") == 1:
            return reply, conn


def test_operators_are_added_listed_and_removed_with_only_a_hash_kept(
        tmp_path: Path, runtime_dir: Path) -> None:
    env = environment(tmp_path, runtime_dir)
    added = server(env, "--add-operator", "alice", "--role", "operate", "--radios", "1/1,1/2")
    assert added.returncode == 0, added.stderr
    token = added.stdout.splitlines()[-1]
    assert token.startswith("moas1.") and " " not in token
    book = tmp_path / "cfg" / "moas-gui" / "operators.json"
    text = book.read_text()
    assert token.rsplit(".", 1)[1] not in text and '"hash"' in text
    assert stat.S_IMODE(book.stat().st_mode) == 0o600
    listed = server(env, "--list-operators")
    assert listed.stdout.split() == ["alice", "operate", "1/1,1/2"]
    twice = server(env, "--add-operator", "Alice", "--role", "view")
    assert twice.returncode == 1 and "already an operator" in twice.stderr
    bad = server(env, "--add-operator", "bob", "--role", "view", "--radios", "one")
    assert bad.returncode == 1 and "STATION/RADIO" in bad.stderr
    removed = server(env, "--remove-operator", "alice")
    assert removed.returncode == 0, removed.stderr
    assert "No operators" in server(env, "--list-operators").stdout


def ask(conn: socket.socket, request_id: int, cmd: str, **args: object) -> dict:
    conn.sendall(json.dumps({"id": request_id, "cmd": cmd, **args}).encode() + b"\n")
    reader = conn.makefile("rb")
    while True:
        reply = json.loads(reader.readline())
        if reply.get("id") == request_id:
            return reply  # type: ignore[no-any-return]


class Guarded(LoggedServer):
    """``moas-server --headless --require-token`` with four operators (vera views, otto
    operates radio 1/1, ada is an admin, rita operates every radio), started once for the
    tests of this module that take :func:`guarded`."""

    def __init__(self, root: Path, runtime: Path) -> None:
        env = environment(root, runtime)
        book = book_of(env)  # written here as --add-operator writes it (tested above)
        self.tokens = {name: book.add(name, role, radios)[1]
                       for name, role, radios in (("vera", Role.VIEW, None),
                                                  ("otto", Role.OPERATE, frozenset({(1, 1)})),
                                                  ("ada", Role.ADMIN, None),
                                                  ("rita", Role.OPERATE, None))}
        tcp = free_port(socket.SOCK_STREAM)
        super().__init__(
            [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / "small-station.moas"),
             "--headless", "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port",
             "0", "--no-rotator-program", "--require-token"], env, tcp)
        opened: list[socket.socket] = []
        wait_for(lambda: _greets(self.tcp, self.tokens["ada"], opened))
        for each in opened:
            each.close()


@pytest.fixture(scope="module")
def started(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Guarded]:
    yield from module_server(Guarded, tmp_path_factory, "guarded")


@pytest.fixture
def guarded(started: Guarded) -> Guarded:
    """The module's server, running; what it says from here on is the test's."""
    started.begin()
    return started


def test_the_real_engine_refuses_what_a_role_may_not_do(guarded: Guarded) -> None:
    tcp = guarded.tcp
    tokens = {name: guarded.tokens[name] for name in ("vera", "otto", "ada")}
    conns = {}
    for name, token in tokens.items():
        reply, conns[name] = hello(tcp, token)
        assert reply["ok"], reply
    anonymous, conns["nobody"] = hello(tcp, None)
    assert anonymous["error"]["code"] == "forbidden"
    assert ask(conns["otto"], 2, "frequency", station=1, radio=1, khz=14025)["ok"]
    mine = ask(conns["otto"], 3, "select", station=1, radio=1, antenna=3)
    assert mine["ok"], mine
    other = ask(conns["otto"], 4, "frequency", station=1, radio=2, khz=7025)
    assert other["error"]["code"] == "forbidden" and "1/2" in other["error"]["message"]
    assert ask(conns["otto"], 5, "stop_switches")["error"]["code"] == "forbidden"
    assert ask(conns["vera"], 6, "frequency", station=1, radio=1,
               khz=7025)["error"]["code"] == "forbidden"
    assert ask(conns["ada"], 7, "frequency", station=1, radio=2, khz=7025)["ok"]
    assert ask(conns["ada"], 8, "stop_switches")["ok"]
    assert ask(conns["ada"], 9, "start_switches")["ok"]
    for each in conns.values():
        each.close()
    stderr = guarded.said()
    assert "otto at 127.0.0.2:" in stderr and "tuning radio 1/1" in stderr
    assert "ada at 127.0.0.2:" in stderr and "stop the switches" in stderr
    assert all(token.rsplit(".", 1)[1][:10] not in stderr for token in tokens.values())


def _greets(port: int, token: str, opened: list[socket.socket]) -> bool:
    try:
        reply, conn = hello(port, token)
    except OSError:
        return False
    opened.append(conn)
    return bool(reply.get("ok"))


def test_remove_operator_reaches_the_running_server_and_ends_its_session(
        guarded: Guarded) -> None:
    env, tcp, token = guarded.env, guarded.tcp, guarded.tokens["rita"]
    reply, session = hello(tcp, token)
    assert reply["ok"], reply
    removed = server(env, "--remove-operator", "rita")
    assert removed.returncode == 0, removed.stderr
    assert "1 session of operator rita ended" in removed.stdout
    session.settimeout(10)
    while session.recv(65536):  # the state event, then the end
        pass
    reply, conn = hello(tcp, token)
    assert reply["error"]["code"] == "forbidden"
    for each in (session, conn):
        each.close()
    stderr = guarded.said()
    assert 'Operator "rita" was removed: 1 session ended' in stderr
    assert token.rsplit(".", 1)[1][:10] not in stderr


@pytest.mark.skipif(shutil.which("openssl") is None, reason="needs the openssl command")
def test_both_ports_serve_tls_to_openssl_and_the_client_pins_the_fingerprint(
        tmp_path: Path, runtime_dir: Path) -> None:
    env = environment(tmp_path, runtime_dir)
    printed = server(env, "--fingerprint", "--bind", "127.0.0.1")  # as the server binds
    assert printed.returncode == 0, printed.stderr
    pin = printed.stdout.strip()
    assert len(pin) == 95 and pin.count(":") == 31
    tcp, web = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    first = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / "small-station.moas"),
         "--headless", "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
         "--web-port", str(web), "--no-rotator-program", "--tls", "--new-instance"],
        env=env, stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: _tls_answers(tcp))
        # openssl's s_client -quiet waits for the server to close the connection (it
        # ignores the end of its input): the HTTP/1.0 page is closed after its answer, the
        # client port after the state's answer and three lines that are no requests
        # (its rule), rather than at the 5 s deadline for a hello
        for port, request in ((tcp, b'{"id": 1, "cmd": "state"}\n' + b"no request\n" * 3),
                              (web, b"GET / HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")):
            shown = subprocess.run(
                ["openssl", "s_client", "-connect", f"127.0.0.1:{port}", "-quiet",
                 "-verify_quiet"], input=request, capture_output=True, timeout=30,
                check=False)
            if port == tcp:
                assert b'"config": "small-station.moas"' in shown.stdout, shown.stderr
            else:
                assert shown.stdout.startswith(b"HTTP/1.") and b"200" in shown.stdout[:20]
        seen = subprocess.run(
            ["openssl", "s_client", "-connect", f"127.0.0.1:{tcp}"], input=b"",
            capture_output=True, timeout=30, check=False)
        der = subprocess.run(["openssl", "x509", "-outform", "DER"], input=seen.stdout,
                             capture_output=True, timeout=30, check=True).stdout
        assert format_fingerprint(der) == pin
        names = subprocess.run(["openssl", "x509", "-noout", "-ext", "subjectAltName"],
                               input=seen.stdout, capture_output=True, timeout=30,
                               check=True).stdout.decode()
        assert "IP Address:127.0.0.1" in names and "DNS:localhost" in names, names
        asyncio.run(_pinned_client(tcp, pin))
    finally:
        first.terminate()
        _, stderr = first.communicate(timeout=15)
    assert f"SHA-256 fingerprint {pin}" in stderr


def _tls_answers(port: int) -> bool:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=5) as raw, \
                client_context().wrap_socket(raw) as conn:
            conn.sendall(b'{"id": 1, "cmd": "state"}\n')
            return b'"ok": true' in conn.recv(65536)
    except OSError:
        return False


async def _pinned_client(port: int, pin: str) -> None:
    good = ClientConnection("127.0.0.1", port, tls=True, pin=pin, connect_timeout=10)
    good.start()
    await good.wait_connected(20)
    assert good.fingerprint == pin
    assert good.snapshot is not None or await _state(good)
    await good.aclose()
    wrong = "00:" * 31 + "00"
    bad = ClientConnection("127.0.0.1", port, tls=True, pin=wrong, connect_timeout=10)
    bad.start()
    # its handshake is refused for the certificate (not waited out for 2 s as before)
    await until(lambda: "not the pinned" in bad._last_problem, 20, "the pin's refusal")
    assert bad.connects == 0 and not bad._connected.is_set()
    await bad.aclose()


async def _state(conn: ClientConnection) -> bool:
    return bool(await conn.request("state", {}))
