"""The FlexRadio source: a Flex 6000/8000's slices as this server's radios (docs/sources.md).

A :class:`FlexSource` connects to the radio's API (TCP 4992, or the address
given; a serial number or nickname is looked up in the radios' discovery
datagrams), checks that the peer greets as a FlexRadio does (``V<version>``
then ``H<handle>``), names itself (``client program moas-gui``: a non-GUI
client, it never takes a GUI client's seat), subscribes to the slices and to
transmit (``sub slice all``, ``sub tx all``: the interlock), enables the
keepalive and pings every :data:`~moas_gui.sources.flex_api.PING_INTERVAL`
seconds.  It sends nothing that changes the radio.

Each status that changes a slice or the interlock is mapped to this server's
radios (:class:`~moas_gui.sources.flex_api.SliceMap`) and reported as a
:class:`~moas_gui.sources.base.FrequencyReport` when a radio's frequency or
transmit state changed; the radio of the transmitting slice is the station's
transmit focus (:class:`~moas_gui.sources.base.ActiveRadio`).  A radio whose
slice closes (``in_use=0``), or all of them when the radio goes away, is left
with its frequency unknown: nothing is reported for it until a slice is back,
never a guess.

The rules of every source: a line that makes no sense is dropped with a
rate-limited debug line and the connection goes on; a peer that is not a
FlexRadio is refused with one error line naming it; the radio going away is one
warning, then new attempts with a growing pause (``retry``, doubling to 10 s),
one info line when it is back.  :meth:`FlexSource.describe` says in words where
the radio and each of its radios stand (offline, which slice, which antennas).
"""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
import logging
import time
from collections.abc import Callable
from typing import Final

from moas_gui.errors import MoasError
from moas_gui.retry import Backoff, Pauses
from moas_gui.sources.base import (
    DEFAULT_RETRY,
    RETRY_LIMIT,
    ActiveRadio,
    BadInputLog,
    ConnectionLog,
    FrequencyReport,
    SourceSink,
)
from moas_gui.sources.flex_api import (
    API_PORT,
    OPENING,
    PING,
    PING_INTERVAL,
    FlexAnnouncement,
    FlexLineError,
    FlexRadioState,
    FlexReply,
    FlexStatus,
    Handle,
    LineSplitter,
    Message,
    RadioRef,
    Slice,
    SliceMap,
    Version,
    command,
    parse_line,
)
from moas_gui.sources.flex_discovery import FlexDiscovery
from moas_gui.sources.polling import _why

READ_SIZE: Final = 16384
DEFAULT_TIMEOUT: Final = 5.0
"""Seconds the connection and the greeting may take, and a discovery look-up."""
MAX_PENDING: Final = 64
"""Commands remembered while their answer is awaited."""


class NotFlex(MoasError):
    """The peer is not a FlexRadio (its greeting says so)."""


class RadioNotFound(MoasError):
    """A radio named by serial or nickname was not heard on the network."""


def split_target(text: str, port: int = API_PORT) -> tuple[str, int] | None:
    """``ADDR[:PORT]`` to a host and port; None when ``text`` is a serial or nickname
    (no dot, no colon, not an IP address).  :class:`ValueError` for a bad port."""
    text = text.strip()
    if not text:
        raise ValueError("no radio named: give its address, serial number or nickname")
    host, colon, tail = text.rpartition(":")
    if colon and tail.isdigit() and host and not host.endswith(":"):
        if not 1 <= int(tail) <= 65535:
            raise ValueError(f"port {tail} is not between 1 and 65535")
        return host.strip("[]"), int(tail)
    with contextlib.suppress(ValueError):
        return str(ipaddress.ip_address(text.strip("[]"))), port
    if "." in text:
        return text, port
    return None


class FlexSource:
    """One FlexRadio read for this server's radios (see the module notes)."""

    kind = "flex"
    label = "FlexRadio"

    def __init__(
        self,
        target: str,
        slices: SliceMap,
        on_event: SourceSink,
        *,
        retry: float = DEFAULT_RETRY,
        timeout: float = DEFAULT_TIMEOUT,
        ping_interval: float = PING_INTERVAL,
        silent_after: float | None = None,
        discovery_port: int = API_PORT,
        logger: logging.Logger | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.target = target.strip()
        self.address = split_target(self.target)
        self.slices = slices
        self.timeout = timeout
        self.ping_interval = ping_interval
        self.silent_after = 3 * ping_interval if silent_after is None else silent_after
        """Seconds without a line (pings are answered) after which the radio counts as
        gone."""
        self.discovery_port = discovery_port
        self._on_event = on_event
        self.origin = f"FlexRadio {self.target}"
        self.log = logger or logging.getLogger("moas_gui.sources.flex")
        self.bad = BadInputLog(self.log, self.origin, clock=clock)
        self.link = ConnectionLog(self.log, self.origin, clock=clock)
        self._backoff = Pauses(Backoff(first=retry, most=max(retry, RETRY_LIMIT)))
        self.state = FlexRadioState()
        self.found: FlexAnnouncement | None = None
        """The radio's discovery datagram, when it was looked up by serial or nickname."""
        self.version = ""
        self.online = False
        self.why_offline = "not connected yet"
        self._discovery: FlexDiscovery | None = None
        self._task: asyncio.Task[None] | None = None
        self._writer: asyncio.StreamWriter | None = None
        self._seq = 0
        self._pending: dict[int, str] = {}
        self._sent: dict[RadioRef, tuple[float, bool | None]] = {}
        self._antennas: dict[RadioRef, tuple[str, str, str]] = {}
        self._active: RadioRef | None = None
        self._refusing = False
        self.connects = 0
        self.reports = 0
        self.refusals = 0
        """Connections refused because the peer was not a FlexRadio."""
        self.status_at = 0.0
        """``time.perf_counter()`` when the last status line was read (for the benchmark)."""

    # -- the Source shape -----------------------------------------------------------------
    async def start(self) -> None:
        if self._task is None:
            self._task = asyncio.get_running_loop().create_task(self._run())

    async def close(self) -> None:
        task, self._task = self._task, None
        if task is not None:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task
        if self._discovery is not None:
            await self._discovery.close()
            self._discovery = None

    def forget(self) -> None:
        """The next status counts as a change for every radio (the engine restarted)."""
        self._sent.clear()
        self._active = None

    # -- connecting -----------------------------------------------------------------------
    async def _run(self) -> None:
        while True:
            try:
                host, port = await self._where()
                await self._session(host, port)
            except NotFlex as exc:
                self._refused(str(exc))
            except RadioNotFound as exc:
                self.link.lost(str(exc))
                self._offline(str(exc))
            except (OSError, TimeoutError, asyncio.IncompleteReadError, EOFError) as exc:
                self.link.lost(_why(exc))
                self._offline(_why(exc))
            except Exception as exc:  # a source never stops on a fault of its own
                self.log.debug("%s: unexpected fault", self.origin, exc_info=True)
                self.link.lost(f"an unexpected fault ({type(exc).__name__}: {exc})")
                self._offline("an unexpected fault; the log at Debug says more")
            await asyncio.sleep(self._backoff.next())

    async def _where(self) -> tuple[str, int]:
        if self.address is not None:
            return self.address
        if self._discovery is None:
            discovery = FlexDiscovery(port=self.discovery_port)
            await discovery.start()
            self._discovery = discovery
        loop = asyncio.get_running_loop()
        end = loop.time() + self.timeout
        while loop.time() < end:
            found = self._discovery.find(self.target)
            if found is not None:
                self.found = found
                return found.ip, found.port
            await asyncio.sleep(0.1)
        raise RadioNotFound(f"not heard on the network (UDP {self.discovery_port}); where "
                       "broadcasts do not reach, name the radio by its address")

    async def _session(self, host: str, port: int) -> None:
        reader, writer = await asyncio.wait_for(asyncio.open_connection(host, port),
                                                self.timeout)
        splitter = LineSplitter()
        pinger: asyncio.Task[None] | None = None
        try:
            pending = await self._greeting(reader, splitter, f"{host}:{port}")
            self._writer = writer
            self._opened(host, port)
            for text in OPENING:
                self._send(text)
            pinger = asyncio.get_running_loop().create_task(self._ping())
            for line in pending:
                self._line(line)
            while True:
                data = await asyncio.wait_for(reader.read(READ_SIZE), self.silent_after)
                if not data:
                    raise EOFError("closed")
                self._feed(splitter, data)
        finally:
            self._writer = None
            if pinger is not None:
                pinger.cancel()
            writer.close()
            with contextlib.suppress(Exception):
                await writer.wait_closed()

    async def _greeting(self, reader: asyncio.StreamReader, splitter: LineSplitter,
                        where: str) -> list[str]:
        """Reads ``V<version>`` and ``H<handle>``; returns the lines after them.
        :class:`NotFlex` when the peer says anything else first, or nothing in time."""
        loop = asyncio.get_running_loop()
        end = loop.time() + self.timeout
        lines: list[str] = []
        while len(lines) < 2:
            try:
                data = await asyncio.wait_for(reader.read(READ_SIZE), end - loop.time())
            except TimeoutError:
                raise NotFlex(f"the peer at {where} said nothing in {self.timeout:g} s; a "
                              "FlexRadio says V<version> then H<handle> at once") from None
            if not data:
                raise NotFlex(f"the peer at {where} closed the connection without a "
                              "FlexRadio's greeting")
            more, dropped = splitter.feed(data)
            if dropped:
                raise NotFlex(f"the peer at {where} sent a line of over 8 KiB first")
            lines += more
            self._check_greeting(lines[:2], where)
        return lines[2:]

    def _check_greeting(self, lines: list[str], where: str) -> None:
        """:class:`NotFlex` unless the lines so far begin ``V<version>``, ``H<handle>``."""
        wanted = (Version, Handle)
        for line, kind in zip(lines, wanted, strict=False):
            try:
                parsed = parse_line(line)
            except FlexLineError:
                parsed = None
            if not isinstance(parsed, kind):
                shown = line if len(line) <= 60 else line[:57] + "..."
                raise NotFlex(f"the peer at {where} is not a FlexRadio: it began with "
                              f"{shown!r} where a FlexRadio says V<version> then H<handle>")
            if isinstance(parsed, Version):
                self.version = parsed.text

    def _opened(self, host: str, port: int) -> None:
        self.connects += 1
        self.link.up()
        self._backoff.reset()
        self._refusing = False
        self.online = True
        self.why_offline = ""
        self.state = FlexRadioState()
        self._pending.clear()
        self.log.info("%s at %s:%d: API %s; reading its slices for %s", self.origin, host,
                      port, self.version, self._radios_text())

    def _refused(self, reason: str) -> None:
        self.refusals += 1
        if not self._refusing:
            self.log.error("%s: %s; nothing from it is used (trying again quietly)",
                           self.origin, reason)
        self._refusing = True
        self.link.connected = False
        self._offline(reason)

    def _offline(self, reason: str) -> None:
        self.online = False
        self.why_offline = reason
        self.state = FlexRadioState()
        if self._sent:  # radios had frequencies from it
            self.log.warning("%s offline: %s frequency unknown until it is back",
                             self.origin, self._radios_text())
        self._sent.clear()
        self._antennas.clear()
        self._active = None

    def _send(self, text: str) -> None:
        writer = self._writer
        if writer is None:
            return
        self._seq += 1
        if len(self._pending) >= MAX_PENDING:
            self._pending.pop(next(iter(self._pending)))
        self._pending[self._seq] = text
        writer.write(command(self._seq, text))

    async def _ping(self) -> None:
        while True:
            await asyncio.sleep(self.ping_interval)
            self._send(PING)

    # -- reading ------------------------------------------------------------------------------
    def _feed(self, splitter: LineSplitter, data: bytes) -> None:
        lines, dropped = splitter.feed(data)
        if dropped:
            self.bad.drop("too_long", self.target, f"{dropped} line(s) over 8 KiB")
        for line in lines:
            self._line(line)

    def _line(self, text: str) -> None:
        try:
            line = parse_line(text)
            changed = self.state.apply(line) if isinstance(line, FlexStatus) else False
        except FlexLineError as exc:
            self.bad.drop(exc.reason, self.target, str(exc))
            return
        if isinstance(line, FlexStatus):
            self.status_at = time.perf_counter()
            if changed:
                self._publish()
        elif isinstance(line, FlexReply):
            self._answered(line)
        elif isinstance(line, Message):
            self.log.debug("%s says: %s", self.origin, line.text[:200])

    def _answered(self, reply: FlexReply) -> None:
        asked = self._pending.pop(reply.seq, "")
        if reply.ok or not asked:
            return
        if asked.startswith("client program"):  # the radio may keep a list of programs
            self.log.debug("%s did not take the program name (0x%X %s)", self.origin,
                           reply.code, reply.message)
        elif asked != PING:
            self.log.warning("%s refused %r: 0x%X %s", self.origin, asked, reply.code,
                             reply.message[:100])

    def _publish(self) -> None:
        assigned = self.slices.assign(self.state.in_use())
        keyed = self.state.transmitting
        for ref in self.slices.radios():
            piece = assigned.get(ref)
            if piece is None or piece.khz is None:
                self._unknown(ref)
                continue
            self._antenna_names(ref, piece)
            tx = keyed if piece.tx else (None if keyed is None else False)
            now = (piece.khz, tx)
            if self._sent.get(ref) == now:
                continue
            self._sent[ref] = now
            self.reports += 1
            self._on_event(FrequencyReport(ref[0], ref[1], piece.khz, piece.khz, self.origin,
                                           mode=piece.mode, transmitting=tx))
        transmitter = next((ref for ref, s in assigned.items() if s.tx), None)
        if transmitter is not None and transmitter != self._active:
            self._active = transmitter
            self._on_event(ActiveRadio(transmitter[0], transmitter[1], self.origin))

    def _unknown(self, ref: RadioRef) -> None:
        if self._sent.pop(ref, None) is not None:
            self.log.info("%s: station %d radio %d has no slice in use; its frequency is "
                          "unknown", self.origin, ref[0], ref[1])
        self._antennas.pop(ref, None)

    def _antenna_names(self, ref: RadioRef, piece: Slice) -> None:
        """Logs which slice and antenna ports a radio follows: Info the first time after a
        connection, Debug after (an SO2R operator moves the transmitter often)."""
        names = (piece.letter, piece.rxant, piece.txant)
        before = self._antennas.get(ref)
        if before != names:
            self._antennas[ref] = names
            self.log.log(logging.INFO if before is None else logging.DEBUG,
                         "%s: station %d radio %d follows %s (the radio's RX antenna %s, "
                         "TX antenna %s)", self.origin, ref[0], ref[1], piece.name,
                         piece.rxant or "?", piece.txant or "?")

    # -- in words -------------------------------------------------------------------------------
    def _radios_text(self) -> str:
        return " and ".join(f"station {s} radio {r}" for s, r in self.slices.radios())

    def state_text(self) -> str:
        """``connected, API 1.4.0.0`` or ``offline (why)``."""
        if self.online:
            return f"connected, API {self.version}"
        return f"offline ({self.why_offline})"

    def describe(self) -> list[str]:
        """Where the radio stands, then each of this server's radios it feeds, in words."""
        name = self.found.label() if self.found is not None else self.target
        lines = [f"FlexRadio {name}: {self.state_text()}"]
        assigned = self.slices.assign(self.state.in_use()) if self.online else {}
        for ref in self.slices.radios():
            piece = assigned.get(ref)
            where = f"station {ref[0]} radio {ref[1]}"
            if piece is None or piece.khz is None:
                lines.append(f"{where}: no slice, frequency unknown")
                continue
            keyed = " transmitting" if piece.tx and self.state.transmitting else ""
            lines.append(f"{where}: {piece.name} {piece.khz:,.3f} kHz {piece.mode}, RX "
                         f"{piece.rxant or '?'}, TX {piece.txant or '?'}{keyed}".rstrip())
        return lines


__all__ = ["DEFAULT_TIMEOUT", "FlexSource", "NotFlex", "RadioNotFound", "split_target"]
