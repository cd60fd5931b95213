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

The period a report covers is bounded (:func:`bounded_period`): what was asked for is
clamped to the journal's own time (from its first row to its last, or to now), and a
request for more than :data:`MAX_SPAN_DAYS` days is refused with the bounds named, so
the work of a report never grows with the period asked for beyond what the journal
holds.  A report is made off the event loop, one at a time (:class:`ReportDesk`).
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from datetime import UTC, datetime
from typing import Final, TypeVar

from moas_gui.errors import MoasError

from .adif import adif_band
from .records import AntennaSpan, Contact, JournalReader, KeySpan, Period, Role

__all__ = [
    "HOUR",
    "MAX_SPAN_DAYS",
    "NO_ANTENNA",
    "REPORTS",
    "ROLES",
    "ContestReport",
    "NothingRecorded",
    "RadioTimeline",
    "ReportBusy",
    "ReportDesk",
    "TimelineSpan",
    "bounded_period",
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
MAX_SPAN_DAYS: Final = 366
"""The longest period a report covers, in days (a leap year)."""
MAX_SPAN: Final = MAX_SPAN_DAYS * 24 * HOUR
T = TypeVar("T")


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


# -- the period a report covers ---------------------------------------------------------------

class NothingRecorded(MoasError, ValueError):
    """The period asked for and the journal's own time do not meet."""


def utc_text(seconds: float) -> str:
    """``2026-11-28 14:00 UTC``; a time beyond the calendar as its seconds."""
    try:
        return datetime.fromtimestamp(seconds, UTC).strftime("%Y-%m-%d %H:%M UTC")
    except (OverflowError, OSError, ValueError):
        return f"{seconds:,.0f} s"


def bounded_period(reader: JournalReader, asked: Period | None, now: float) -> Period | None:
    """The period a report covers; None for an empty journal.

    ``asked`` None is the whole journal, its last :data:`MAX_SPAN_DAYS` days when it holds
    more; an infinite start or end of ``asked`` is the journal's first or last time.  A period asked for is clamped to the journal's own time, from its first row to
    its last row or to ``now``, whichever is later (the antennas recorded last are in
    force until now); :class:`NothingRecorded` when nothing of it is left.  A period of
    more than :data:`MAX_SPAN_DAYS` days is refused (``ValueError`` naming the bounds),
    whatever the journal holds."""
    extent = reader.extent()
    if asked is not None and extent is not None and math.isinf(asked.start):
        asked = Period(extent.start, asked.end)
    if asked is not None and extent is not None and math.isinf(asked.end):
        asked = Period(asked.start, math.floor(extent.end) + 1.0)
    if asked is not None and asked.end - asked.start > MAX_SPAN:
        holds = ("" if extent is None else
                 f"; the journal holds {utc_text(extent.start)} to {utc_text(extent.end)}")
        raise ValueError(
            f"the period {utc_text(asked.start)} to {utc_text(asked.end)} is "
            f"{(asked.end - asked.start) / 86400:,.0f} days: a report covers at most "
            f"{MAX_SPAN_DAYS} days{holds}")
    if extent is None:
        return None
    last = math.floor(extent.end) + 1.0
    if asked is None:
        return Period(max(extent.start, last - MAX_SPAN), last)
    start = max(asked.start, extent.start)
    end = min(asked.end, max(last, math.floor(now) + 1.0))
    if start >= end:
        raise NothingRecorded(
            f"Nothing was recorded from {utc_text(asked.start)} to {utc_text(asked.end)}: "
            f"the journal holds {utc_text(extent.start)} to {utc_text(extent.end)}.")
    return Period(start, end)


# -- one report at a time, off the loop -------------------------------------------------------

class ReportBusy(MoasError, RuntimeError):
    """Another contest report is being made."""


class ReportDesk:
    """Makes contest reports one at a time, each in a thread of its own.

    The thread is not a daemon (one stopped in the middle of matplotlib's C++ at the
    interpreter's exit aborts the process): a server told to stop waits for the report
    being made, which its bounded period keeps short, and whoever asks can stop it
    between reading and drawing.  The one making a report releases the desk when it is
    done, even when whoever asked for it has gone (a cancelled request), so two reports
    never run together.  The web page's
    ``/report`` is told :class:`ReportBusy` at once (:meth:`run`); the window waits its
    turn (:meth:`start`)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()

    @property
    def busy(self) -> bool:
        return self._lock.locked()

    async def run(self, job: Callable[[], T]) -> T:
        """``job()``'s result, made in a thread; :class:`ReportBusy` at once when a
        report is being made."""
        if not self._lock.acquire(blocking=False):
            raise ReportBusy("another contest report is being made")
        loop = asyncio.get_running_loop()
        future: asyncio.Future[T] = loop.create_future()

        def settle(result: T | None, error: BaseException | None) -> None:
            if future.done():
                return
            if error is not None:
                future.set_exception(error)
            else:
                future.set_result(result)  # type: ignore[arg-type]

        def done(result: T | None, error: BaseException | None) -> None:
            with contextlib.suppress(RuntimeError):  # the loop has closed: nobody waits
                loop.call_soon_threadsafe(settle, result, error)

        self._thread(job, done, wait=False)
        return await future

    def start(self, job: Callable[[], T],
              done: Callable[[T | None, BaseException | None], None]) -> None:
        """Runs ``job`` in a thread once the desk is free (it waits its turn), then calls
        ``done(result, None)`` or ``done(None, error)`` in that thread."""
        self._thread(job, done, wait=True)

    def _thread(self, job: Callable[[], T],
                done: Callable[[T | None, BaseException | None], None], *, wait: bool) -> None:
        def work() -> None:
            if wait:
                self._lock.acquire()
            outcome: tuple[T | None, BaseException | None]
            try:
                outcome = (job(), None)
            except Exception as exc:  # noqa: BLE001 - handed to whoever asked
                outcome = (None, exc)
            finally:
                self._lock.release()
            done(*outcome)

        try:
            threading.Thread(target=work, name="contest report").start()
        except RuntimeError:
            if not wait:
                self._lock.release()
            raise


REPORTS: Final = ReportDesk()
"""The process's one desk: the web page's reports and the window's share it."""
