"""Hamlib rigctld's replies, without I/O: the poll's bytes out, one reading in.

rigctld (Hamlib's network rig daemon, TCP port 4532 by default) answers text
commands one per line and pushes nothing, so the source polls.  Each poll is
four commands in the *extended response* form (a ``+`` before the command):

========  ===============  ===========================================
command   long name        record(s) in the reply
========  ===============  ===========================================
``+f``    get_freq         ``Frequency: <Hz>``
``+s``    get_split_vfo    ``Split: 0|1`` and ``TX VFO: <name>``
``+i``    get_split_freq   ``TX Frequency: <Hz>``
``+t``    get_ptt          ``PTT: 0|1|2|3``
========  ===============  ===========================================

Every extended reply is the command's long name and a colon, the records
(``Key: value``), then ``RPRT n``: ``RPRT 0`` for success, a negative number
for an error (``RPRT -11`` when the backend cannot read that value, as the
dummy rig does for PTT).  The ``RPRT`` line ends each reply, so the parser
never has to know how many records a command has.  Sources: Hamlib's
rigctld(1) manual page ("Extended Response Protocol") and
shared/specs/logger-network.md section 3.

:class:`ReplyParser` takes bytes as they come and returns a
:class:`RigReading` each time the four replies of a poll are complete.  A
line that is not part of an extended reply, an over-long line or an absurd
value raises :class:`RigctldReplyError`; the connection is then out of step
and the I/O part starts a fresh one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from moas_gui.config.rigs import RIGCTLD_PORT
from moas_gui.errors import ProtocolError
from moas_gui.line_framer import LineEnd, LineFramer, LongLine

DEFAULT_PORT: Final = RIGCTLD_PORT
POLL: Final = b"+f\n+s\n+i\n+t\n"
"""One poll: frequency, split, split (transmit) frequency, PTT."""
COMMANDS: Final = ("get_freq", "get_split_vfo", "get_split_freq", "get_ptt")
MAX_LINE: Final = 256
"""No rigctld reply line to these commands comes near this; a longer one is garbage."""
MAX_HZ: Final = 300_000_000_000
"""300 GHz."""


class RigctldReplyError(ProtocolError, ValueError):
    """The reply is not what rigctld sends; ``reason`` is a short key for counting."""

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


@dataclass(frozen=True, slots=True)
class RigReading:
    """What one poll said.  ``None``: the rig could not tell (an ``RPRT`` error)."""

    rx_hz: int | None
    split: bool | None
    tx_hz: int | None
    ptt: bool | None

    @property
    def transmit_hz(self) -> int | None:
        """Where the radio transmits: the split frequency when split, else the receive one."""
        if self.split and self.tx_hz:
            return self.tx_hz
        return self.rx_hz


def _hz(text: str, what: str) -> int:
    try:
        value = int(text.strip())
    except ValueError:
        try:
            number = float(text.strip())  # some backends print "14025000.000000"
        except ValueError:
            raise RigctldReplyError("bad_number", f"{what} {text.strip()[:40]!r} is not a "
                                    "number") from None
        if math.isnan(number) or not 0 <= number <= MAX_HZ:  # NaN or absurd
            raise RigctldReplyError("absurd", f"{what} of {text.strip()[:40]} Hz is absurd") \
                from None
        value = int(number)
    if not 0 <= value <= MAX_HZ:
        raise RigctldReplyError("absurd", f"{what} of {value} Hz is absurd")
    return value


def _flag(text: str, what: str, allowed: frozenset[str]) -> bool:
    value = text.strip()
    if value not in allowed:
        raise RigctldReplyError("bad_value", f"{what} {value[:40]!r} is not one of "
                                f"{', '.join(sorted(allowed))}")
    return value != "0"


class ReplyParser:
    """Bytes from rigctld in, one :class:`RigReading` per completed poll out."""

    def __init__(self) -> None:
        self._lines = LineFramer(MAX_LINE, LineEnd.LF)
        self._index = 0
        """Which of :data:`COMMANDS` the next reply answers."""
        self._in_reply = False
        self._records: dict[str, str] = {}
        self._values: dict[str, str | None] = {}

    def reset(self) -> None:
        """A new connection: forget any half-read reply."""
        self.__init__()  # type: ignore[misc]

    def feed(self, data: bytes) -> list[RigReading]:
        readings: list[RigReading] = []
        for line in self._lines.feed(data):
            if isinstance(line, LongLine):
                raise RigctldReplyError("too_long", f"a reply line is longer than {MAX_LINE} "
                                        "bytes")
            reading = self._line(line.data.decode("ascii", errors="replace"))
            if reading is not None:
                readings.append(reading)
        return readings

    def _line(self, line: str) -> RigReading | None:
        command = COMMANDS[self._index]
        if not self._in_reply:
            if line != f"{command}:":
                raise RigctldReplyError("out_of_step", f"expected the {command} reply, got "
                                        f"{line[:60]!r}")
            self._in_reply = True
            self._records = {}
            return None
        if line.startswith("RPRT "):
            try:
                code = int(line[5:])
            except ValueError:
                raise RigctldReplyError("bad_rprt", f"{line[:60]!r} is not a result code") \
                    from None
            self._finish(command, code)
            self._in_reply = False
            self._index += 1
            if self._index < len(COMMANDS):
                return None
            self._index = 0
            return self._reading()
        key, colon, value = line.partition(":")
        if not colon or not key.strip():
            raise RigctldReplyError("not_a_record", f"{command} reply line {line[:60]!r} is "
                                    "not 'Key: value'")
        if len(self._records) >= 8:
            raise RigctldReplyError("too_many", f"{command} reply has too many records")
        self._records[key.strip()] = value.strip()
        return None

    def _finish(self, command: str, code: int) -> None:
        records = self._records if code == 0 else {}
        if command == "get_freq":
            self._values["rx"] = records.get("Frequency")
        elif command == "get_split_vfo":
            self._values["split"] = records.get("Split")
        elif command == "get_split_freq":
            self._values["tx"] = records.get("TX Frequency")
        else:
            self._values["ptt"] = records.get("PTT")

    def _reading(self) -> RigReading:
        values, self._values = self._values, {}
        rx, split, tx, ptt = (values.get(k) for k in ("rx", "split", "tx", "ptt"))
        return RigReading(
            rx_hz=None if rx is None else _hz(rx, "frequency"),
            split=None if split is None else _flag(split, "split", frozenset({"0", "1"})),
            tx_hz=None if tx is None else _hz(tx, "split frequency"),
            ptt=None if ptt is None else _flag(ptt, "PTT", frozenset({"0", "1", "2", "3"})),
        )


__all__ = ["COMMANDS", "DEFAULT_PORT", "MAX_LINE", "POLL", "ReplyParser", "RigReading",
           "RigctldReplyError"]
