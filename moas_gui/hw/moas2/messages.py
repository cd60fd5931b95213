"""The MOAS II's messages as values: commands the computer sends, and the
replies, events and errors the box sends back.

Every message is a frozen dataclass; the numbers in them are plain integers
(stations 0-6, antennas 0-63, relays 0-63, milliseconds) and the one-letter
options of the manual are enums whose values are those letters.  Turning
them into bytes and back is the job of :mod:`.commands`, :mod:`.replies` and
:mod:`.decoder`.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

# --------------------------------------------------------------------------- options


class AntennaKind(str, Enum):
    """Which of a station's antenna sets an ``!`` command sets."""

    TX = "T"
    RX = "R"
    BOTH = "B"
    ALT = "A"
    EXTRA = "X"


class ConflictOp(str, Enum):
    """Sub-commands of the conflict table command ``%``."""

    NONE = "0"
    """No antennas conflict (not even with themselves)."""
    ALL = "1"
    """Every antenna conflicts with every antenna."""
    SET = "C"
    """The listed pairs conflict."""
    CLEAR = "c"
    """The listed pairs do not conflict."""


class FastOp(str, Enum):
    """Sub-commands of the fast table command ``&``."""

    ALL_SLOW = "0"
    ALL_FAST = "1"
    FAST = "F"
    """The listed pairs switch fast."""
    SLOW = "f"
    """The listed pairs switch slowly."""


class PolarityOp(str, Enum):
    """Sub-commands of the inhibit polarity command ``^``."""

    ALL_INHIBIT_LOW = "0"
    ALL_ENABLE_LOW = "1"
    ENABLE_LOW = "E"
    INHIBIT_LOW = "I"


class StationMode(str, Enum):
    """What a station does with an antenna change while it transmits."""

    WAIT = "W"
    INTERRUPT = "I"


class StateOp(str, Enum):
    """Sub-commands of the set state command ``*``."""

    RESET = "0"
    ACTIVATE = "1"
    ANTENNA_EVENTS_ON = "A"
    ANTENNA_EVENTS_OFF = "a"
    TR_EVENTS_ON = "T"
    TR_EVENTS_OFF = "t"
    INHIBIT_EVENTS_ON = "I"
    INHIBIT_EVENTS_OFF = "i"
    RESOLVER_ON = "R"
    RESOLVER_OFF = "r"
    EXTRA_EVENTS_ON = "X"
    EXTRA_EVENTS_OFF = "x"


class StatusKind(str, Enum):
    """Sub-commands of the status command ``"``."""

    BOX = "B"
    POLARITY = "I"


class AntennaStatus(str, Enum):
    """The status letter of an antenna event ``!{station}{status}{antenna};``."""

    TX_CONFLICT = "C"
    RX_CONFLICT = "c"
    TX_FAST = "F"
    RX_FAST = "f"
    TX_SLOW = "S"
    RX_SLOW = "s"
    ALT_FREE = "A"
    ALT_CONFLICT = "a"


class TRState(str, Enum):
    """One station's letter in a box status reply."""

    TRANSMIT = "T"
    RECEIVE = "R"
    INHIBITED = "I"


ERROR_MEANINGS: dict[str, str] = {
    "U": "unknown command",
    "A": "invalid argument",
    "T": "a station may not inhibit or switch itself when it transmits",
    "C": "communications error",
    "F": "input buffer overflow",
}
"""What each ``?`` error letter means."""

# --------------------------------------------------------------------------- commands


@dataclass(frozen=True, slots=True)
class SetAntenna:
    """``!``: set a station's antenna and the relays that select it.

    Station 0 with kind ``EXTRA`` sets relays held regardless of any station.
    """

    station: int
    kind: AntennaKind
    antenna: int
    relays: tuple[int, ...] = ()


@dataclass(frozen=True, slots=True)
class ConflictTable:
    """``%``: clear, fill, or change pairs of the conflict table."""

    op: ConflictOp
    pairs: tuple[tuple[int, int], ...] = ()


@dataclass(frozen=True, slots=True)
class FastTable:
    """``&``: clear, fill, or change pairs of the fast table."""

    op: FastOp
    pairs: tuple[tuple[int, int], ...] = ()


@dataclass(frozen=True, slots=True)
class Inhibit:
    """``(``: inhibit stations by command."""

    stations: frozenset[int] = frozenset()


@dataclass(frozen=True, slots=True)
class Uninhibit:
    """``)``: lift the command inhibit from stations."""

    stations: frozenset[int] = frozenset()


@dataclass(frozen=True, slots=True)
class InhibitOthers:
    """``~``: the stations inhibited while ``station`` transmits (replaces the list)."""

    station: int
    stations: frozenset[int] = frozenset()


@dataclass(frozen=True, slots=True)
class InhibitPolarity:
    """``^``: which stations' inhibit outputs pull down to enable."""

    op: PolarityOp
    stations: frozenset[int] = frozenset()


@dataclass(frozen=True, slots=True)
class InhibitTime:
    """``[``: slow-transition inhibit, 1-9999 ms."""

    ms: int


@dataclass(frozen=True, slots=True)
class InterruptDelay:
    """``]``: interrupt-mode delay, 0-99 ms."""

    ms: int


@dataclass(frozen=True, slots=True)
class Mode:
    """``/``: set stations to wait or interrupt mode."""

    mode: StationMode
    stations: frozenset[int] = frozenset()


@dataclass(frozen=True, slots=True)
class Ping:
    """``'``: ask whether the box is there and active."""


@dataclass(frozen=True, slots=True)
class ReceiveDelay:
    """``\\``: how long a station's key line must be released before it
    receives, 0-9999 ms."""

    station: int
    ms: int


@dataclass(frozen=True, slots=True)
class RelayStatusRequest:
    """``|``: ask for the 64 relays."""


@dataclass(frozen=True, slots=True)
class SetState:
    """``*``: reset, activate, events on/off, resolver on/off (in order)."""

    ops: tuple[StateOp, ...]


@dataclass(frozen=True, slots=True)
class StatusRequest:
    """``"``: ask for the box status (``B``) or the inhibit polarity (``I``)."""

    kind: StatusKind


@dataclass(frozen=True, slots=True)
class SystemTable:
    """``_``: clear the antenna system table, or give antennas systems."""

    clear: bool
    pairs: tuple[tuple[int, int], ...] = ()
    """``(antenna, system)``; system 0 means none."""


@dataclass(frozen=True, slots=True)
class UnitId:
    """``:``: ask for (``unit`` None) or store the unit identifier 0-99."""

    unit: int | None = None


@dataclass(frozen=True, slots=True)
class UseAlternate:
    """``@``: the stations moved to their alternate antenna while ``station``
    transmits (replaces the list)."""

    station: int
    stations: frozenset[int] = frozenset()


@dataclass(frozen=True, slots=True)
class VendorExtension:
    """``#``: vendor-specific text."""

    text: str = ""


Command = (
    SetAntenna
    | ConflictTable
    | FastTable
    | Inhibit
    | Uninhibit
    | InhibitOthers
    | InhibitPolarity
    | InhibitTime
    | InterruptDelay
    | Mode
    | Ping
    | ReceiveDelay
    | RelayStatusRequest
    | SetState
    | StatusRequest
    | SystemTable
    | UnitId
    | UseAlternate
    | VendorExtension
)

# --------------------------------------------------------------------------- from the box


@dataclass(frozen=True, slots=True)
class Pong:
    """``!;`` (active) or ``.;`` (inactive): the answer to a ping."""

    active: bool


@dataclass(frozen=True, slots=True)
class AntennaEvent:
    """``!{station}{status}{antenna};``: the resolver took or held a change."""

    station: int
    status: AntennaStatus
    antenna: int


@dataclass(frozen=True, slots=True)
class ExtraRelaysEvent:
    """``!{station}X;``: a station's extra relays (or station 0's relays) changed."""

    station: int


@dataclass(frozen=True, slots=True)
class TransmitEvent:
    """``<{station}{antenna};``: a station started transmitting."""

    station: int
    antenna: int


@dataclass(frozen=True, slots=True)
class ReceiveEvent:
    """``>{station}{antenna};``: a station went back to receive."""

    station: int
    antenna: int


@dataclass(frozen=True, slots=True)
class InhibitReply:
    """``({stations};``: the stations inhibited by command, after ``(``."""

    stations: frozenset[int]


@dataclass(frozen=True, slots=True)
class UninhibitReply:
    """``){stations};``: the stations still inhibited by command, after ``)``."""

    stations: frozenset[int]


@dataclass(frozen=True, slots=True)
class BoxStatus:
    """``"B...;``: every station's T/R letter and antennas."""

    tr: tuple[TRState, ...]
    tx: tuple[int, ...]
    rx: tuple[int, ...]
    alt: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class PolarityStatus:
    """``"I{stations};``: the stations whose inhibit pulls down to enable."""

    enable_low: frozenset[int]


@dataclass(frozen=True, slots=True)
class RelayStatus:
    """``|{11 sixbit};``: the closed relays."""

    relays: frozenset[int]


@dataclass(frozen=True, slots=True)
class UnitIdReply:
    """``:{version}{unit};``: firmware version (three characters) and unit id."""

    version: str
    unit: int


@dataclass(frozen=True, slots=True)
class ErrorReply:
    """``?{letter};``: the box could not process a command."""

    code: str

    @property
    def meaning(self) -> str:
        return ERROR_MEANINGS.get(self.code, f"unknown error {self.code!r}")


@dataclass(frozen=True, slots=True)
class VendorReply:
    """``#...;``: vendor-specific text."""

    text: str


@dataclass(frozen=True, slots=True)
class Malformed:
    """Bytes from the box that are not a message, with the reason."""

    raw: bytes
    reason: str


BoxMessage = (
    Pong
    | AntennaEvent
    | ExtraRelaysEvent
    | TransmitEvent
    | ReceiveEvent
    | InhibitReply
    | UninhibitReply
    | BoxStatus
    | PolarityStatus
    | RelayStatus
    | UnitIdReply
    | ErrorReply
    | VendorReply
)

__all__ = [
    "ERROR_MEANINGS",
    "AntennaEvent",
    "AntennaKind",
    "AntennaStatus",
    "BoxMessage",
    "BoxStatus",
    "Command",
    "ConflictOp",
    "ConflictTable",
    "ErrorReply",
    "ExtraRelaysEvent",
    "FastOp",
    "FastTable",
    "Inhibit",
    "InhibitOthers",
    "InhibitPolarity",
    "InhibitReply",
    "InhibitTime",
    "InterruptDelay",
    "Malformed",
    "Mode",
    "Ping",
    "PolarityOp",
    "PolarityStatus",
    "Pong",
    "ReceiveDelay",
    "ReceiveEvent",
    "RelayStatus",
    "RelayStatusRequest",
    "SetAntenna",
    "SetState",
    "StateOp",
    "StationMode",
    "StatusKind",
    "StatusRequest",
    "SystemTable",
    "TRState",
    "TransmitEvent",
    "Uninhibit",
    "UninhibitReply",
    "UnitId",
    "UnitIdReply",
    "UseAlternate",
    "VendorExtension",
    "VendorReply",
]
