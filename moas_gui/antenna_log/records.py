"""The antenna log's records: plain frozen values shared by the journal, the ADIF
export and the contest report.

Times are POSIX seconds (UTC).  An antenna is named by its configured name; ``""``
means no antenna.  A span still in force when it is read ends at the end of the
period asked for.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Final, Literal, Protocol

ContactKind = Literal["contactinfo", "contactreplace", "contactdelete"]
"""The three contact messages of N1MM Logger+ (and not1mm)."""

Role = Literal["tx", "rx", "alt", "sub"]
"""Which of a radio's antennas a span is: transmit, receive, alternate, sub receiver."""


EARLIEST_CONTACT: Final = 946_684_800.0
"""2000-01-01 00:00 UTC: a contact dated before it is refused."""
AHEAD_CONTACT: Final = 86_400.0
"""A contact dated more than this many seconds after the server's clock is refused."""


def contact_date_problem(when: float, now: float | None = None) -> str | None:
    """Why a contact dated ``when`` is refused (before 2000, or more than a day after
    ``now``, the server's clock), or None when its date can be kept."""
    now = time.time() if now is None else now
    if not when >= EARLIEST_CONTACT:  # NaN too
        return "it is dated before 2000"
    if when > now + AHEAD_CONTACT:
        return "it is dated more than a day ahead of this computer's clock"
    return None


@dataclass(frozen=True, slots=True)
class Period:
    """From ``start`` (included) to ``end`` (excluded), POSIX seconds."""

    start: float
    end: float


@dataclass(frozen=True, slots=True)
class AntennaSpan:
    """One radio had ``antenna`` as its ``role`` antenna from ``start`` to ``end``,
    as the switch confirmed it (timed when it landed)."""

    station: int
    radio: int
    role: Role
    antenna: str
    start: float
    end: float


@dataclass(frozen=True, slots=True)
class KeySpan:
    """One radio transmitted on ``antenna`` from ``start`` to ``end``."""

    station: int
    radio: int
    antenna: str
    start: float
    end: float


@dataclass(frozen=True, slots=True)
class HeadingMark:
    """A rotator settled on ``heading`` degrees at ``time``."""

    rotator: str
    heading: float
    time: float


@dataclass(frozen=True, slots=True)
class Contact:
    """One QSO from a logger, with the antennas and heading in force at its time.

    ``station``/``radio`` are ``None`` when the logger's radio maps to none of
    this server's radios; the antenna fields are then ``""``.
    """

    contact_id: str
    time: float
    call: str
    band: str
    mode: str
    station: int | None
    radio: int | None
    tx_antenna: str
    rx_antenna: str
    switch_path: str
    heading: float | None
    operator: str
    contest: str
    tx_khz: float | None
    rx_khz: float | None


@dataclass(frozen=True, slots=True)
class ContactPacket:
    """What one logger's contact packet says (parsed by
    :mod:`moas_gui.sources.n1mm_contact`).  ``time`` is POSIX seconds (UTC), ``None`` only
    for a ``contactdelete`` without a timestamp; frequencies are kHz or ``None``."""

    kind: ContactKind
    contact_id: str
    time: float | None
    call: str = ""
    band: str = ""
    mode: str = ""
    rx_khz: float | None = None
    tx_khz: float | None = None
    radio_nr: int = 1
    station_name: str = ""
    operator: str = ""
    contest: str = ""
    app: str = ""


class JournalReader(Protocol):
    """What the ADIF export and the contest report read from a journal."""

    def extent(self) -> Period | None:
        """The first and last time recorded, or ``None`` for an empty journal."""
        ...

    def contacts(self, period: Period) -> list[Contact]:
        """The contacts logged in ``period``, oldest first, deleted ones left out."""
        ...

    def antenna_spans(self, period: Period) -> list[AntennaSpan]:
        """Every radio's antenna spans overlapping ``period``, clipped to it."""
        ...

    def key_spans(self, period: Period) -> list[KeySpan]:
        """Every transmission overlapping ``period``, clipped to it."""
        ...

    def headings(self, period: Period) -> list[HeadingMark]:
        """The settled headings in ``period``, oldest first."""
        ...
