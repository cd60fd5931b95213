"""The contest report's figures, computed from a journal over a period: plain data.

::

    report = contest_report(reader, Period(start, end))
    report.qsos["Yagi 20"]["20m"]      # contacts made transmitting on Yagi 20, on 20 m
    report.rate["Yagi 20"]             # contacts per clock hour, one per report.hours
    report.transmit["Yagi 20"]         # seconds keyed on it
    report.timelines[0].spans["tx"]    # the first radio's transmit antennas, in time order

A contact is counted for its transmit antenna; one the journal could not match to a
radio of this station counts for :data:`NO_ANTENNA`.  Rates count clock hours (UTC), the
first the one the period starts in.  :mod:`.report_charts` draws these figures.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

from .adif import adif_band
from .records import AntennaSpan, Contact, JournalReader, KeySpan, Period, Role

__all__ = [
    "HOUR",
    "NO_ANTENNA",
    "ROLES",
    "ContestReport",
    "RadioTimeline",
    "TimelineSpan",
    "contest_report",
    "last_hours",
    "qsos_per_antenna_per_band",
    "rate_per_hour",
    "timelines",
    "transmit_seconds",
    "whole_journal",
]

HOUR = 3600.0
NO_ANTENNA = "(no antenna)"
"""The antenna a contact counts for when the journal matched it to none of the radios."""
ROLES: tuple[Role, ...] = ("tx", "rx", "alt", "sub")


@dataclass(frozen=True, slots=True)
class TimelineSpan:
    """One antenna in use from ``start`` to ``end`` (POSIX seconds)."""

    antenna: str
    start: float
    end: float


@dataclass(frozen=True, slots=True)
class RadioTimeline:
    """One radio's antennas over the period, per role (only the roles it had)."""

    station: int
    radio: int
    spans: dict[Role, list[TimelineSpan]]

    @property
    def label(self) -> str:
        return f"Station {self.station} radio {self.radio}"


@dataclass(frozen=True, slots=True)
class ContestReport:
    """What the contest report shows for ``period``."""

    period: Period
    contacts: int
    qsos: dict[str, dict[str, int]]
    """Per transmit antenna, per ADIF band name: contacts."""
    hours: list[float]
    """The clock hours the rates count, by their first second."""
    rate: dict[str, list[int]]
    """Per transmit antenna: contacts in each of :attr:`hours`."""
    transmit: dict[str, float]
    """Per antenna: seconds transmitted on it."""
    timelines: list[RadioTimeline] = field(default_factory=list)

    @property
    def antennas(self) -> list[str]:
        """Every antenna with a contact or a transmission, by name."""
        return sorted(set(self.qsos) | set(self.transmit))

    @property
    def bands(self) -> list[str]:
        """Every band with a contact, lowest frequency first."""
        return sorted({band for counts in self.qsos.values() for band in counts}, key=_band_order)

    def antenna_qsos(self, antenna: str) -> int:
        return sum(self.qsos.get(antenna, {}).values())

    @property
    def empty(self) -> bool:
        """Nothing happened in the period: no contact, no transmission, no antenna."""
        return not (self.contacts or self.transmit or self.timelines)


def _band_order(band: str) -> tuple[float, str]:
    # 160m before 80m ... before 70cm; names ADIF does not know go last
    for unit, scale in (("mm", 0.001), ("cm", 0.01), ("m", 1.0)):
        number = band.removesuffix(unit)
        if number != band:
            try:
                return -float(number) * scale, band
            except ValueError:
                break
    return math.inf, band


def _antenna(contact: Contact) -> str:
    return contact.tx_antenna if contact.radio is not None and contact.tx_antenna else NO_ANTENNA


def _band(contact: Contact) -> str:
    return adif_band(contact.band, contact.tx_khz) or contact.band.strip() or "?"


def qsos_per_antenna_per_band(contacts: Iterable[Contact]) -> dict[str, dict[str, int]]:
    """Contacts per transmit antenna, per band (ADIF's names: ``20m``)."""
    counts: dict[str, dict[str, int]] = {}
    for contact in contacts:
        per_band = counts.setdefault(_antenna(contact), {})
        band = _band(contact)
        per_band[band] = per_band.get(band, 0) + 1
    return counts


def _hour_starts(period: Period) -> list[float]:
    first = math.floor(period.start / HOUR) * HOUR
    count = max(1, math.ceil((period.end - first) / HOUR))
    return [first + i * HOUR for i in range(count)]


def rate_per_hour(
    contacts: Iterable[Contact], period: Period
) -> tuple[list[float], dict[str, list[int]]]:
    """The clock hours of ``period`` and, per transmit antenna, its contacts in each."""
    hours = _hour_starts(period)
    rates: dict[str, list[int]] = {}
    for contact in contacts:
        index = int((contact.time - hours[0]) // HOUR)
        if 0 <= index < len(hours):
            rates.setdefault(_antenna(contact), [0] * len(hours))[index] += 1
    return hours, rates


def transmit_seconds(keys: Iterable[KeySpan]) -> dict[str, float]:
    """Seconds transmitted per antenna (every radio's key spans added up)."""
    seconds: dict[str, float] = {}
    for key in keys:
        name = key.antenna or NO_ANTENNA
        seconds[name] = seconds.get(name, 0.0) + max(0.0, key.end - key.start)
    return seconds


def timelines(spans: Iterable[AntennaSpan]) -> list[RadioTimeline]:
    """Each radio's antennas per role, radios in order, spans in time order; a span with
    no antenna (``""``) is left out, so the gap shows."""
    found: dict[tuple[int, int], dict[Role, list[TimelineSpan]]] = {}
    for span in spans:
        roles = found.setdefault((span.station, span.radio), {})
        if span.antenna and span.end > span.start:
            roles.setdefault(span.role, []).append(TimelineSpan(span.antenna, span.start, span.end))
    return [
        RadioTimeline(
            station,
            radio,
            {role: sorted(roles[role], key=lambda s: s.start) for role in ROLES if role in roles},
        )
        for (station, radio), roles in sorted(found.items())
    ]


def contest_report(reader: JournalReader, period: Period) -> ContestReport:
    """Everything the report shows for ``period``, read from ``reader``."""
    contacts = reader.contacts(period)
    hours, rate = rate_per_hour(contacts, period)
    return ContestReport(
        period=period,
        contacts=len(contacts),
        qsos=qsos_per_antenna_per_band(contacts),
        hours=hours,
        rate=rate,
        transmit=transmit_seconds(reader.key_spans(period)),
        timelines=timelines(reader.antenna_spans(period)),
    )


def whole_journal(reader: JournalReader) -> Period | None:
    """The whole journal as a period (its last second included); None when it is empty."""
    extent = reader.extent()
    if extent is None:
        return None
    return Period(extent.start, math.floor(extent.end) + 1.0)


def last_hours(now: float, hours: float) -> Period:
    """The ``hours`` before ``now`` (``now`` included)."""
    return Period(now - hours * HOUR, math.floor(now) + 1.0)
