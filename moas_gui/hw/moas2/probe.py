"""``moas-server --probe PORT``: what a box on a serial port says about itself.

The probe is for the first contact with a real switch (``docs/switch.md``): it
opens the port for itself alone, asks the questions of :data:`PROBE_QUESTIONS`
(ping, unit id and firmware, box status, inhibit polarity, relay report), each
up to :data:`TRIES` times, and prints what came back in words an owner can read
and share.  Nothing it sends can move a relay: every command is checked against
the session's list of questions (:data:`.questions.QUESTIONS`) before it is
written, the same list the session's questions are held to; no reset,
no activation, no table is ever sent.

A port held by a running server (its switch link opens the port for itself
alone) is refused with a sentence that says so; the probe never shares a port.
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from ...engine.switchstate import NO_ANTENNA
from ...serial import PortError
from .commands import encode
from .decoder import SwitchDecoder
from .errors import ProbeRefused
from .messages import (
    BoxMessage,
    BoxStatus,
    Command,
    Malformed,
    Ping,
    PolarityStatus,
    Pong,
    RelayStatus,
    RelayStatusRequest,
    StatusKind,
    StatusRequest,
    TRState,
    UnitId,
    UnitIdReply,
)
from .questions import QUESTIONS
from .recording import SerialRecorder, answer_type, bytes_text
from .transport import SerialTransport, switch_port

PROBE_QUESTIONS: tuple[Command, ...] = (
    Ping(),
    UnitId(),
    StatusRequest(StatusKind.BOX),
    StatusRequest(StatusKind.POLARITY),
    RelayStatusRequest(),
)
"""What the probe asks, in order; every one is a question (:data:`.questions.QUESTIONS`)."""

ANSWER_TIMEOUT = 1.0
"""Seconds the probe waits for each answer (the box answers within milliseconds)."""

TRIES = 2
"""How many times each question is asked before it counts as unanswered."""

UNKNOWN_KEYS = (
    "CANNOT KNOW whether a station is keyed: the box is not active (or did not say",
    "whether it is), and the MOAS II programming guide does not say that an inactive",
    "box reports its key (T/R) lines, so a station shown receiving may be transmitting.",
    "Unkey every radio (amplifiers to standby) before a server loads this box: loading",
    "activates it, and a keyed station then stays on the air where it stands.",
)
"""Said under the stations of a box that is not known to be active."""

_TR_WORDS = {TRState.TRANSMIT: "TRANSMITTING", TRState.RECEIVE: "receiving",
             TRState.INHIBITED: "inhibited by command"}


@dataclass(slots=True)
class ProbeReport:
    """What the box answered, question by question."""

    port: str
    answers: dict[type[Any], BoxMessage] = field(default_factory=dict)
    """Each question's reply type -> the reply (what did not answer is missing)."""
    exchange: list[tuple[str, bytes]] = field(default_factory=list)
    """Both directions in order: ``("->", sent)`` and ``("<-", received)``."""
    also: list[str] = field(default_factory=list)
    """What else the box said (events, errors, garbage), in words."""
    started: float = field(default_factory=time.time)

    @property
    def answered(self) -> bool:
        return bool(self.answers)

    def text(self) -> str:
        """The report, as an owner reads and shares it."""
        when = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime(self.started))
        lines = [f"MOAS II probe of {self.port} at 9600 baud 8N1, {when}",
                 "Only questions were sent: no relay can have moved.", ""]
        if not self.answered:
            lines += ["No answer to any question.",
                      ("Check: the box has power (it draws none from USB); the USB cable is "
                       "in (a USB B plug at the box); the system shows the box's FTDI serial "
                       "port (its driver is loaded) and this is its name."), ""]
        else:
            lines += self._answer_lines()
        lines += ["Also heard:" if self.also else "Also heard: nothing else."]
        lines += [f"  {item}" for item in self.also]
        lines += ["", "The exchange (-> sent, <- received):"]
        lines += [f"  {way} {bytes_text(data)}" for way, data in self.exchange]
        return "\n".join(lines) + "\n"

    def _answer_lines(self) -> list[str]:
        out: list[str] = []
        pong = self.answers.get(Pong)
        if isinstance(pong, Pong):
            out.append("Ping: answered; the box is " + (
                "ACTIVE (a server loaded it and it is switching)" if pong.active else
                "inactive (reset or just powered up: it waits for a server to load it)"))
        else:
            out.append("Ping: no answer")
        unit = self.answers.get(UnitIdReply)
        if isinstance(unit, UnitIdReply):
            out.append(f"Unit id: {unit.unit}  (the .moas file's Echo for this switch)")
            out.append(f"Firmware: V{unit.version[:1]}.{unit.version[1:]}")
        else:
            out.append("Unit id and firmware: no answer")
        out += self._station_lines()
        polarity = self.answers.get(PolarityStatus)
        if isinstance(polarity, PolarityStatus):
            low = ", ".join(str(s) for s in sorted(polarity.enable_low)) or "none"
            out.append(f"Inhibit polarity: stations enabled when pulled down: {low}")
        else:
            out.append("Inhibit polarity: no answer")
        relays = self.answers.get(RelayStatus)
        if isinstance(relays, RelayStatus):
            closed = ", ".join(str(r) for r in sorted(relays.relays)) or "none"
            out.append(f"Closed relays ({len(relays.relays)} of 64): {closed}")
        else:
            out.append("Relays: no answer")
        return [*out, ""]

    def _station_lines(self) -> list[str]:
        status = self.answers.get(BoxStatus)
        if not isinstance(status, BoxStatus):
            return ["Stations: no answer"]
        keyed = [n for n, tr in enumerate(status.tr, 1) if tr is TRState.TRANSMIT]
        out = ["Stations (slot numbers as the box holds them; 63 = none):"]
        for n, (tr, tx, rx, alt) in enumerate(
                zip(status.tr, status.tx, status.rx, status.alt, strict=True), 1):
            out.append(f"  station {n}: {_TR_WORDS.get(tr, str(tr)):22} TX {_slot(tx):>4}  "
                       f"RX {_slot(rx):>4}  alternate RX {_slot(alt):>4}")
        if keyed:
            out.append("  WARNING: station " + ", ".join(map(str, keyed)) + " transmits now.")
        pong = self.answers.get(Pong)
        if not (isinstance(pong, Pong) and pong.active):
            out += [f"  {line}" for line in UNKNOWN_KEYS]
        return out


def _slot(slot: int) -> str:
    return "none" if slot == NO_ANTENNA else str(slot)


async def probe(port: str, *, answer_timeout: float = ANSWER_TIMEOUT,
                recorder: SerialRecorder | None = None,
                settings: tuple[bool | None, bool | None] = (None, None),
                questions: Sequence[Command] = PROBE_QUESTIONS) -> ProbeReport:
    """Ask the box on ``port`` the :data:`PROBE_QUESTIONS`; :class:`ProbeRefused` when
    the port cannot be opened.  ``settings`` are the DTR and RTS levels to open it with
    (None: as the system's open leaves them)."""
    for command in questions:
        if not isinstance(command, QUESTIONS):
            raise TypeError(f"{type(command).__name__} is not a question: the probe sends "
                            "nothing that could move a relay")
    report = ProbeReport(port)
    loop = asyncio.get_running_loop()
    arrived: asyncio.Queue[bytes] = asyncio.Queue()
    lost: list[str] = []
    transport = SerialTransport(port, settings=switch_port(dtr=settings[0], rts=settings[1]))
    start = loop.time()
    try:
        transport.open(arrived.put_nowait, lost.append)
    except PortError as exc:
        raise ProbeRefused(_refusal(port, str(exc))) from None
    decoder = SwitchDecoder()
    try:
        for command in questions:
            await _ask(transport, command, report, arrived, decoder, answer_timeout,
                       recorder, lambda: loop.time() - start)
            if lost:
                report.also.append(f"the port went away: {lost[0]}")
                break
    finally:
        transport.close()
    return report


async def _ask(transport: SerialTransport, command: Command, report: ProbeReport,
               arrived: asyncio.Queue[bytes], decoder: SwitchDecoder, answer_timeout: float,
               recorder: SerialRecorder | None, clock: Any) -> None:
    wanted = answer_type(command)
    data = encode(command)
    for _ in range(TRIES):
        report.exchange.append(("->", data))
        if recorder is not None:
            recorder.note(0, "out", clock(), data=data)
        try:
            transport.write(data)
        except PortError as exc:
            report.also.append(f"writing {bytes_text(data)} failed: {exc}")
            return
        deadline = asyncio.get_running_loop().time() + answer_timeout
        while (left := deadline - asyncio.get_running_loop().time()) > 0:
            try:
                chunk = await asyncio.wait_for(arrived.get(), left)
            except TimeoutError:
                break
            report.exchange.append(("<-", chunk))
            if recorder is not None:
                recorder.note(0, "in", clock(), data=chunk)
            if _take(decoder.feed(chunk), wanted, report):
                return


def _take(messages: list[Any], wanted: type[Any], report: ProbeReport) -> bool:
    """Keep the answer of type ``wanted`` (True when it came); the rest goes to ``also``."""
    found = False
    for message in messages:
        if isinstance(message, wanted) and not found:
            report.answers[wanted] = message
            found = True
        elif isinstance(message, Malformed):
            report.also.append(f"garbage: {bytes_text(message.raw)} ({message.reason})")
        else:
            report.also.append(repr(message))
    return found


def _refusal(port: str, reason: str) -> str:
    if "lock" in reason.lower() or "busy" in reason.lower():
        return (f"{port} is in use by another program (a running moas-server's switch link "
                f"holds its port alone): close that server, or probe another port ({reason})")
    return f"cannot open {port}: {reason}"


__all__ = ["ANSWER_TIMEOUT", "PROBE_QUESTIONS", "TRIES", "ProbeRefused", "ProbeReport", "probe"]
