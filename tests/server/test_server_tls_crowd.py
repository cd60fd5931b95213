"""A real ``moas-server --tls`` against connections that never start their handshake, from
loopback addresses other than this computer's own: 8, then 50 from one address, then 50
from each of ten, on the client port and the web page together.  A loopback client still
completes its TLS hello and its HTTPS ``GET /`` (the handshake is admitted first and never
holds the accept loop), a silent handshake is closed by its deadline, and the address's
reserve counts connections still in their handshake (the one over it is closed before a
byte of TLS)."""

from __future__ import annotations

import json
import os
import socket
import ssl
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from helpers import EXAMPLES, free_port, wait_for

from moas_gui.tls import client_context

pytestmark = pytest.mark.realtime

HOST = "127.0.0.1"
PATIENT = 30.0
"""Seconds a check may wait under load: far more than a loopback hello takes, far less
than the minute asyncio itself gave a stuck handshake."""


def environment(tmp_path: Path, runtime: Path) -> dict[str, str]:
    return dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_CONFIG_HOME=str(tmp_path / "cfg"),
                XDG_STATE_HOME=str(tmp_path / "state"), PYTHONUNBUFFERED="1")


@pytest.fixture
def tls_server(tmp_path: Path, runtime_dir: Path) -> Iterator[tuple[int, int, Path]]:
    tcp, web = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    log = tmp_path / "server.log"
    with log.open("w") as sink:
        process = subprocess.Popen(
            [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / "small-station.moas"),
             "--headless", "--bind", HOST, "--tcp-port", str(tcp), "--udp-port", "0",
             "--web-port", str(web), "--no-rotator-program", "--tls", "--new-instance"],
            env=environment(tmp_path, runtime_dir), stderr=sink, stdout=subprocess.DEVNULL)
    try:
        wait_for(lambda: tls_hello(tcp), timeout=60, what="the server's TLS client port")
        yield tcp, web, log
    finally:
        process.terminate()
        try:
            process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=15)
            raise


def silent(port: int, source: str) -> socket.socket:
    """A TCP connection from ``source`` that never sends a byte (never starts TLS)."""
    return socket.create_connection((HOST, port), timeout=PATIENT, source_address=(source, 0))


def tls_hello(port: int, source: str = HOST) -> bool:
    """A loopback client's hello over TLS is answered."""
    with socket.create_connection((HOST, port), timeout=PATIENT,
                                  source_address=(source, 0)) as raw, \
            client_context().wrap_socket(raw) as conn:
        conn.sendall(b'{"id": 1, "cmd": "hello", "client": "crowd test"}\n')
        reader = conn.makefile("rb")
        while True:
            line = reader.readline()
            if not line:
                return False
            reply = json.loads(line)
            if reply.get("id") == 1:
                return bool(reply.get("ok"))


def https_page(port: int) -> bool:
    """``GET /`` over HTTPS from loopback is answered 200."""
    with socket.create_connection((HOST, port), timeout=PATIENT) as raw, \
            client_context().wrap_socket(raw) as conn:
        conn.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")
        return conn.makefile("rb").readline().startswith(b"HTTP/1.1 200")


def closed_by_server(sock: socket.socket) -> bool:
    """The server closed ``sock`` (end of stream or a reset), sending nothing."""
    sock.settimeout(PATIENT)
    try:
        return sock.recv(1024) == b""
    except ConnectionError:
        return True


def test_silent_crowds_never_delay_a_loopback_tls_hello_or_https_page(
        tls_server: tuple[int, int, Path]) -> None:
    tcp, web, _log = tls_server
    held: list[socket.socket] = []
    try:
        ten = [f"127.0.0.{n}" for n in range(2, 12)]
        for count, sources in ((8, ["127.0.0.2"]), (50, ["127.0.0.2"]), (50, ten)):
            for source in sources:
                for port in (tcp, web):
                    held += [silent(port, source) for _ in range(count)]
            wait_for(lambda: tls_hello(tcp), timeout=PATIENT,
                     what=f"a loopback TLS hello beside {count} silent from {len(sources)}")
            wait_for(lambda: https_page(web), timeout=PATIENT,
                     what=f"the HTTPS page beside {count} silent from {len(sources)}")
        # each silent handshake is closed by its deadline (or made room for by the fair share)
        assert closed_by_server(held[0])
        assert closed_by_server(held[-1])
    finally:
        for sock in held:
            sock.close()


def test_the_address_reserve_counts_connections_still_in_their_handshake(
        tls_server: tuple[int, int, Path]) -> None:
    tcp, _web, log = tls_server
    source = "127.0.0.12"
    held: list[socket.socket] = []

    def refused_before_its_handshake() -> bool:
        # the reserve (16 by default) taken by silent handshakes; the next one from the
        # same address is closed on the bare socket: its handshake ends at once in an
        # end of stream, not in a wait
        for sock in held:
            sock.close()
        held[:] = [silent(tcp, source) for _ in range(16)]
        try:
            tls_hello(tcp, source)
        except (ConnectionError, ssl.SSLError) as exc:
            return not isinstance(exc, TimeoutError)
        return False

    try:
        wait_for(refused_before_its_handshake, timeout=120,
                 what="a 17th connection refused while 16 are in their handshake")
        wait_for(lambda: "have not said who they are yet" in log.read_text(), timeout=PATIENT,
                 what="the refusal's log line")
        assert tls_hello(tcp, "127.0.0.13")  # another address is served meanwhile
    finally:
        for sock in held:
            sock.close()
