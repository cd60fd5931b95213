"""The Antenna Genius TCP/IP API's text, sans-IO: reading commands, writing answers.

The 4O3A Antenna Genius (AG) speaks lines of text on TCP (docs/antenna-genius.md):

* on connect the device says ``V<major.minor.patch> AG`` (`` AUTH`` appended when the
  client must send ``auth code=N`` first);
* a client sends ``C<seq>|<command>``;
* the device answers ``R<seq>|<hex code>|<message>`` (code ``0``: done); a list is
  one ``R`` line per item, all with code ``0``, ended by an empty ``R<seq>|0|``;
* what changes by itself is pushed as ``S0|<message>`` to the clients that subscribed.

Commands end with CR, LF or CR LF alike (the real firmware 4.1 takes all three and
clients differ); blank lines are ignored.  What this module writes ends with CR LF,
which every client's line reader takes.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from moas_gui.line_framer import Line, LineEnd, LineFramer

FIRMWARE = "4.1.0"
"""The firmware version the server announces (clients look for ``V4`` and ``AG``)."""

LINE_LIMIT = 512
"""The longest command line taken, in bytes; a longer one is answered with an error."""

EOL = b"\r\n"

OK = 0x0
"""Done."""
BAD_COMMAND = 0x10
"""Not a command line (no ``C<seq>|``), or no such command."""
UNSUPPORTED = 0x11
"""A command of the real device this server does not do (stack, group, output, flex...)."""
BAD_ARGUMENT = 0x12
"""An argument is missing, unknown or out of range (no such port, antenna, band)."""
REFUSED = 0x20
"""The MOAS engine refused: the message is its reason."""
NOT_RUNNING = 0x21
"""No configuration runs, or the switches are stopped."""
NO_AUTH = 0xFF
"""Not authenticated, or a wrong ``auth`` code: nothing else works until one is right."""

_COMMAND = re.compile(r"C(\d{1,9})\|(.*)\Z", re.DOTALL)


@dataclass(frozen=True, slots=True)
class AgCommand:
    """One ``C<seq>|...`` line: its sequence number, words and ``key=value`` arguments."""

    seq: int
    text: str
    words: tuple[str, ...] = ()
    """The words that are not ``key=value`` (``("port", "set", "1")``), lower case."""
    args: dict[str, str] = field(default_factory=dict)
    """The ``key=value`` words, keys in lower case."""

    @property
    def verb(self) -> str:
        """The first two words (``"port set"``), or the one there is."""
        return " ".join(self.words[:2])


@dataclass(frozen=True, slots=True)
class AgMalformed:
    """A line that is not a command: said back with the sequence number when it has one."""

    seq: int
    """The sequence number when the line had one, else 0."""
    reason: str


def parse_line(text: str) -> AgCommand | AgMalformed:
    """One line without its ending, as an :class:`AgCommand` or why it is not one."""
    match = _COMMAND.match(text.strip())
    if match is None:
        number = re.match(r"\s*C(\d{1,9})", text)
        return AgMalformed(int(number.group(1)) if number else 0,
                         f"not a command line (C<seq>|<command>): {text[:40]!r}")
    seq, body = int(match.group(1)), match.group(2)
    words: list[str] = []
    args: dict[str, str] = {}
    for word in body.split():
        key, equals, value = word.partition("=")
        if equals:
            args[key.lower()] = value
        else:
            words.append(word.lower())
    return AgCommand(seq, body.strip(), tuple(words), args)


class CommandReader:
    """Bytes in, commands out: lines ended by CR, LF or CR LF, blank lines skipped."""

    def __init__(self, limit: int = LINE_LIMIT) -> None:
        self._framer = LineFramer(limit, LineEnd.CR_OR_LF)

    def feed(self, data: bytes) -> list[AgCommand | AgMalformed]:
        out: list[AgCommand | AgMalformed] = []
        for item in self._framer.feed(data):
            if isinstance(item, Line):
                text = item.data.decode("utf-8", "replace")
                if text.strip():
                    out.append(parse_line(text))
            else:
                head = item.head.decode("utf-8", "replace")
                seq = re.match(r"C(\d{1,9})", head)
                out.append(AgMalformed(int(seq.group(1)) if seq else 0,
                                     f"a line of over {LINE_LIMIT} bytes"))
        return out


def greeting(auth: bool = False, firmware: str = FIRMWARE) -> bytes:
    """The first line on connect: ``V4.1.0 AG``, with `` AUTH`` when a code is needed."""
    return f"V{firmware} AG{' AUTH' if auth else ''}".encode() + EOL


def reply(seq: int, code: int = OK, message: str = "") -> bytes:
    """One answer line, ``R<seq>|<hex code>|<message>``."""
    return f"R{seq}|{code:X}|{_one_line(message)}".encode() + EOL


def list_reply(seq: int, items: list[str]) -> bytes:
    """A list: an ``R<seq>|0|item`` line per item, then the empty ``R<seq>|0|``.  A single
    answer that clients may wait a terminator for (``port get``) is a list of one."""
    return b"".join(reply(seq, OK, item) for item in items) + reply(seq)


def status(message: str) -> bytes:
    """A pushed line, ``S0|<message>``."""
    return f"S0|{_one_line(message)}".encode() + EOL


def name_text(name: str) -> str:
    """A name as the protocol carries it: no spaces (``_`` instead), no ``|`` or ``=``."""
    cleaned = re.sub(r"[\s|=]+", "_", name.strip())
    return cleaned or "_"


def _one_line(text: str) -> str:
    return re.sub(r"[\r\n]+", " ", text)


@dataclass(frozen=True, slots=True)
class PortStatus:
    """What ``port get`` and ``S0|port`` say of one AG port (a radio)."""

    port: int
    auto: bool = True
    source: str = "AUTO"
    band: int = 0
    rxant: int = 0
    txant: int = 0
    tx: bool = False
    inhibit: bool = False
    freq_mhz: float | None = None
    nickname: str = ""

    def text(self) -> str:
        """``port N auto=1 source=AUTO band=B rxant=A txant=A tx=0 inhibit=0 ...``."""
        words = [f"port {self.port}", f"auto={int(self.auto)}", f"source={self.source}",
                 f"band={self.band}", f"rxant={self.rxant}", f"txant={self.txant}",
                 f"tx={int(self.tx)}", f"inhibit={int(self.inhibit)}"]
        if self.freq_mhz is not None:
            words.append(f"freq={self.freq_mhz:.6f}")
        if self.nickname:
            words.append(f"nickname={name_text(self.nickname)}")
        return " ".join(words)


__all__ = [
    "BAD_ARGUMENT",
    "BAD_COMMAND",
    "EOL",
    "FIRMWARE",
    "LINE_LIMIT",
    "NOT_RUNNING",
    "NO_AUTH",
    "OK",
    "REFUSED",
    "UNSUPPORTED",
    "AgCommand",
    "AgMalformed",
    "CommandReader",
    "PortStatus",
    "greeting",
    "list_reply",
    "name_text",
    "parse_line",
    "reply",
    "status",
]
