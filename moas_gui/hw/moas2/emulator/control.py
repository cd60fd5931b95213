"""Driving an emulated box from outside its window: key and unkey stations, and
read its relays, its state and its record, one line of text at a time.

The commands (one per line; replies are one line each, except ``record`` and
``watch``):

=================  ==========================================================
``key N``          assert station N's key line (1-6), as its radio does when it
                   transmits; reply ``ok key N``
``unkey N``        release it; reply ``ok unkey N``
``relays``         ``relays 0 20 (active, keyed 1)``, as the info log shows them
``status``         ``status {...}``: one JSON object with the box and each station
``record [N]``     every entry of the record after number N (default: all kept),
                   one ``record {...}`` line each (see :mod:`.record`), then
                   ``end M`` where M is the number of the last entry written
``watch [N]``      ``ok watch``, then the entries after N (default: from now on) as
                   ``record {...}`` lines, and every new one as it is written,
                   until the connection closes
``help``           the list of commands
=================  ==========================================================

Anything else gets ``error ...`` saying what was wrong; the box is untouched.
:class:`Control` is the line protocol without any input or output;
:func:`serve_control` puts it on a local socket, :func:`serve_stdin` on the
process's standard input and output.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import os
import stat
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

from moas_gui.edge.admission import Admission, Deadlines
from moas_gui.edge.gate import gate_factory, ticket_of
from moas_gui.edge.listener import Listener

from .box import EmulatedBox, Traffic
from .boxstate import STATIONS
from .record import Entry
from .view import BoxView

log = logging.getLogger(__name__)

HELP = ("commands: key N, unkey N (N = 1-6), relays, status, record [N], watch [N], help")

Writer = Callable[[str], None]
"""Sends one line (without its newline) back to whoever gave the command."""


def describe_relays(relays: frozenset[int], active: bool, keyed: frozenset[int]) -> str:
    """``relays 0 20 (active, keyed 1)``: the closed relays, as the info log shows them."""
    shown = " ".join(str(r) for r in sorted(relays)) or "none"
    state = "active" if active else "inactive"
    if keyed:
        state += ", keyed " + " ".join(str(n) for n in sorted(keyed))
    return f"relays {shown} ({state})"


def _keyed(view: BoxView) -> frozenset[int]:
    return frozenset(st.number for st in view.stations if st.key)


def status_json(view: BoxView) -> dict[str, Any]:
    """The box's state as one JSON object."""
    return {
        "active": view.active,
        "resolver": view.resolver_on,
        "relays": sorted(view.relays),
        "keyed": sorted(_keyed(view)),
        "unit_id": view.unit_id,
        "stations": [
            {
                "station": st.number,
                "key": st.key,
                "phase": st.phase.value,
                "transmitting": st.transmitting,
                "mode": "interrupt" if st.mode.name == "INTERRUPT" else "wait",
                "inhibited": st.inhibited,
                "tx": st.tx.antenna,
                "rx": st.rx.antenna,
                "alt": st.alt.antenna,
                "closed": sorted(st.closed),
                "pending": [f"{kind}{antenna}" for kind, antenna in st.pending],
            }
            for st in view.stations
        ],
    }


def record_line(entry: Entry) -> str:
    return "record " + json.dumps(entry.as_json(), separators=(",", ":"))


class Control:
    """The line protocol for one box; each connection gets a :meth:`session`."""

    def __init__(self, box: EmulatedBox) -> None:
        self.box = box

    def session(self, write: Writer) -> Session:
        return Session(self.box, write)


class Session:
    """One reader of commands: replies go to ``write``; a ``watch`` streams the record."""

    def __init__(self, box: EmulatedBox, write: Writer) -> None:
        self.box = box
        self.write = write
        self._watched = -1
        self._stop_watching: Callable[[], None] | None = None

    def close(self) -> None:
        if self._stop_watching is not None:
            self._stop_watching()
            self._stop_watching = None

    def handle(self, line: str) -> None:
        """Carry out one command line."""
        words = line.split()
        if not words:
            return
        verb, args = words[0].lower(), words[1:]
        try:
            if verb in ("key", "unkey"):
                self._key(verb, args)
            elif verb == "relays" and not args:
                view = self.box.view()
                self.write(describe_relays(view.relays, view.active, _keyed(view)))
            elif verb == "status" and not args:
                self.write("status " + json.dumps(status_json(self.box.view()),
                                                  separators=(",", ":")))
            elif verb == "record":
                after = self._number(args, 0)
                for entry in self.box.model.record.after(after):
                    self.write(record_line(entry))
                self.write(f"end {self.box.model.record.written}")
            elif verb == "watch":
                self._watch(self._number(args, self.box.model.record.written))
            elif verb == "help" and not args:
                self.write("ok " + HELP)
            else:
                raise ValueError(f"unknown command {line.strip()!r} ({HELP})")
        except ValueError as exc:
            self.write(f"error {exc}")

    def _key(self, verb: str, args: list[str]) -> None:
        if len(args) != 1 or not args[0].isdigit() or int(args[0]) not in STATIONS:
            raise ValueError(f"{verb} takes one station number, 1-6 (got {' '.join(args)!r})")
        station = int(args[0])
        self.box.set_tr(station, verb == "key")
        self.write(f"ok {verb} {station}")

    @staticmethod
    def _number(args: list[str], default: int) -> int:
        if not args:
            return default
        if len(args) != 1 or not args[0].isdigit():
            raise ValueError(f"expected one entry number, got {' '.join(args)!r}")
        return int(args[0])

    def _watch(self, after: int) -> None:
        self.close()
        self._watched = after
        self.write("ok watch")
        self._send_new()

        def changed(kind: Traffic, data: bytes) -> None:
            if kind is Traffic.CHANGED:
                self._send_new()

        self._stop_watching = self.box.add_listener(changed)

    def _send_new(self) -> None:
        for entry in self.box.model.record.after(self._watched):
            self.write(record_line(entry))
            self._watched = entry.seq


# --------------------------------------------------------------------------- transports


CONTROL_CONNECTIONS = 16
"""Control connections at once (the project's admission policy, moas_gui.edge)."""
CONTROL_DEADLINES = Deadlines(hello=60.0)
"""A control connection sends its first command within a minute (a ``watch`` may then
stay silent as long as it likes)."""


class ControlServer:
    """Where the control listens; :meth:`close` stops it."""

    def __init__(self, admission: Admission, listener: Listener | None = None,
                 server: asyncio.AbstractServer | None = None) -> None:
        self.admission = admission
        self._listener = listener
        self._server = server

    async def close(self) -> None:
        if self._listener is not None:
            await self._listener.close()
        if self._server is not None:
            self._server.close()
            await self._server.wait_closed()
        self.admission.close()


async def serve_control(control: Control, where: str) -> tuple[ControlServer, str]:
    """Listen for control connections at ``where``: a number is a TCP port on
    127.0.0.1 (0: any free one), anything else the path of a Unix socket (not on
    Windows).  Every connection passes the project's admission policy first (caps, a
    deadline for its first command).  Returns the server and where it listens, as text."""

    async def connected(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        def write(line: str) -> None:
            if not writer.is_closing():
                writer.write(line.encode() + b"\n")

        ticket = ticket_of(writer)
        session = control.session(write)
        try:
            while line := await reader.readline():
                if ticket is not None:
                    ticket.greeted()
                    ticket.touch()
                session.handle(line.decode("utf-8", errors="replace"))
                await writer.drain()
        except (ConnectionError, OSError):
            pass
        finally:
            session.close()
            writer.close()

    admission = Admission(CONTROL_CONNECTIONS, CONTROL_CONNECTIONS,
                          what="control connections")
    gate = gate_factory(admission, connected, front="control connection",
                        deadlines=CONTROL_DEADLINES, refusal=lambda why: f"error {why}\n".encode())
    if where.isdigit():
        listener = await Listener.open(gate, "127.0.0.1", int(where),
                                       what="control connections", trouble=admission.trouble)
        return ControlServer(admission, listener), f"127.0.0.1:{listener.port}"
    if sys.platform == "win32":
        raise OSError("on Windows --control takes a TCP port number (on 127.0.0.1)")
    path = Path(where)
    with contextlib.suppress(FileNotFoundError):
        if not stat.S_ISSOCK(path.lstat().st_mode):
            raise OSError(f"{path} exists and is not a socket; not replacing it")
        path.unlink()  # left behind by an emulator that was killed
    server = await asyncio.get_running_loop().create_unix_server(gate, path=str(path))
    os.chmod(path, 0o600)
    return ControlServer(admission, server=server), str(path)


def remove_control(where: str) -> None:
    """Remove the control socket's path (nothing for a TCP port)."""
    if not where.isdigit() and sys.platform != "win32":
        path = Path(where)
        with contextlib.suppress(OSError):
            if stat.S_ISSOCK(path.lstat().st_mode):
                path.unlink()


def serve_stdin(control: Control, loop: asyncio.AbstractEventLoop) -> None:
    """Take commands from standard input, reply on standard output (a thread reads,
    the loop carries them out).  The end of the input ends nothing but the control."""

    def write(line: str) -> None:
        try:
            print(line, flush=True)
        except (OSError, ValueError) as exc:  # nobody reads our output any more
            log.debug("emulator control: cannot reply: %s", exc)

    session = control.session(write)

    def pump() -> None:
        for line in sys.stdin:
            try:
                loop.call_soon_threadsafe(session.handle, line)
            except RuntimeError:  # the loop has ended: so has the emulator
                return

    threading.Thread(target=pump, name="emulator control", daemon=True).start()


__all__ = [
    "CONTROL_CONNECTIONS",
    "CONTROL_DEADLINES",
    "HELP",
    "Control",
    "ControlServer",
    "Session",
    "describe_relays",
    "record_line",
    "remove_control",
    "serve_control",
    "serve_stdin",
    "status_json",
]
