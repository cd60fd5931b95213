"""The antenna log as ADIF 3.1 (``.adi``): one record per contact, with the antennas.

::

    text = adif_text(reader.contacts(period), station_callsign="K1XX")
    count = write_adif(reader, period, Path("contest.adi"))

Each record carries what a logger's own export has (``CALL``, ``QSO_DATE``,
``TIME_ON``, ``BAND``, ``MODE``, ``FREQ``...) so that the two can be matched on the
call and the time, and what only this server knows: ``MY_ANTENNA`` (the transmit
antenna's name), ``ANT_AZ`` (the heading, only where a rotator turns the antenna) and
three application fields, ``APP_MOAS_TXANT``, ``APP_MOAS_RXANT`` and
``APP_MOAS_SWITCH_PATH``.  A field with nothing to say is left out.

A field's length counts characters (an antenna named ``Süd`` is ``<MY_ANTENNA:3>``);
the file is UTF-8.  Line breaks and other control characters in a value become spaces.
``docs/antenna-log.md`` says how to merge the file into a logger's export.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable
from datetime import UTC, datetime
from pathlib import Path

from moas_gui import __version__
from moas_gui.files import write_text_atomic

from .records import Contact, JournalReader, Period

__all__ = [
    "ADIF_VERSION",
    "PROGRAM_ID",
    "adif_band",
    "adif_mode",
    "adif_text",
    "parse_utc",
    "write_adif",
]

ADIF_VERSION = "3.1.4"
PROGRAM_ID = "moas-gui"

# ADIF's band enumeration: name, lowest and highest frequency in kHz
_BANDS: tuple[tuple[str, float, float], ...] = (
    ("2190m", 135.7, 137.8),
    ("630m", 472, 479),
    ("560m", 501, 504),
    ("160m", 1800, 2000),
    ("80m", 3500, 4000),
    ("60m", 5060, 5450),
    ("40m", 7000, 7300),
    ("30m", 10100, 10150),
    ("20m", 14000, 14350),
    ("17m", 18068, 18168),
    ("15m", 21000, 21450),
    ("12m", 24890, 24990),
    ("10m", 28000, 29700),
    ("8m", 40000, 45000),
    ("6m", 50000, 54000),
    ("5m", 54000.001, 69900),
    ("4m", 70000, 71000),
    ("2m", 144000, 148000),
    ("1.25m", 222000, 225000),
    ("70cm", 420000, 450000),
    ("33cm", 902000, 928000),
    ("23cm", 1240000, 1300000),
    ("13cm", 2300000, 2450000),
    ("9cm", 3300000, 3500000),
    ("6cm", 5650000, 5925000),
    ("3cm", 10000000, 10500000),
)
_BAND_NAMES = {name for name, _low, _high in _BANDS}
# the band as N1MM Logger+ and not1mm write it (the band's usual MHz figure), where that
# figure lies outside ADIF's limits for the band
_LOGGER_BANDS = {
    "0.136": "2190m",
    "0.472": "630m",
    "1.8": "160m",
    "3.5": "80m",
    "5": "60m",
    "7": "40m",
    "10": "30m",
    "14": "20m",
    "18": "17m",
    "21": "15m",
    "24": "12m",
    "28": "10m",
    "50": "6m",
    "70": "4m",
    "144": "2m",
    "222": "1.25m",
    "420": "70cm",
    "432": "70cm",
    "902": "33cm",
    "1240": "23cm",
    "1296": "23cm",
    "2304": "13cm",
    "3456": "9cm",
    "5760": "6cm",
    "10368": "3cm",
}
# loggers' modes that ADIF writes as a mode and a submode
_SUBMODES = {
    "USB": "SSB",
    "LSB": "SSB",
    "FT4": "MFSK",
    "JS8": "MFSK",
    "Q65": "MFSK",
    "PSK31": "PSK",
    "PSK63": "PSK",
    "PSK125": "PSK",
    "QPSK31": "PSK",
}
_CONTROL = re.compile(r"[\x00-\x1f\x7f]+")


def adif_band(band: str, khz: float | None = None) -> str:
    """ADIF's name for a logger's ``band`` (``"14"``, ``"20m"``, ``"20M"``), or for the
    band ``khz`` lies in; ``""`` when neither says."""
    text = band.strip().lower()
    if text in _BAND_NAMES:
        return text
    try:
        mhz = float(text)
    except ValueError:
        mhz = math.nan
    if math.isfinite(mhz):
        known = _LOGGER_BANDS.get(f"{mhz:g}")
        if known:
            return known
        found = _band_of(mhz * 1000)
        if found:
            return found
    return _band_of(khz) if khz is not None else ""


def _band_of(khz: float) -> str:
    for name, low, high in _BANDS:
        if low <= khz <= high:
            return name
    return ""


def adif_mode(mode: str) -> tuple[str, str]:
    """ADIF's ``(MODE, SUBMODE)`` for a logger's ``mode`` (``USB`` is SSB, submode USB)."""
    text = mode.strip().upper()
    parent = _SUBMODES.get(text)
    return (parent, text) if parent else (text, "")


def _mhz(khz: float | None) -> str:
    if khz is None or not math.isfinite(khz) or khz <= 0:
        return ""
    return f"{khz / 1000:.6f}".rstrip("0").rstrip(".")


def _degrees(heading: float | None) -> str:
    if heading is None or not math.isfinite(heading):
        return ""
    value = round(heading, 1) % 360
    return f"{value:.1f}".removesuffix(".0")


def _field(name: str, value: str) -> str:
    value = _CONTROL.sub(" ", value).strip()
    if not value:
        return ""
    return f"<{name}:{len(value)}>{value} "


def _record(contact: Contact, station_callsign: str) -> str:
    when = datetime.fromtimestamp(contact.time, UTC)
    mode, submode = adif_mode(contact.mode)
    fields = (
        ("CALL", contact.call.upper()),
        ("QSO_DATE", when.strftime("%Y%m%d")),
        ("TIME_ON", when.strftime("%H%M%S")),
        ("BAND", adif_band(contact.band, contact.tx_khz)),
        ("MODE", mode),
        ("SUBMODE", submode),
        ("FREQ", _mhz(contact.tx_khz)),
        ("FREQ_RX", _mhz(contact.rx_khz)),
        ("OPERATOR", contact.operator.upper()),
        ("CONTEST_ID", contact.contest),
        ("STATION_CALLSIGN", station_callsign.upper()),
        ("MY_ANTENNA", contact.tx_antenna),
        ("ANT_AZ", _degrees(contact.heading)),
        ("APP_MOAS_TXANT", contact.tx_antenna),
        ("APP_MOAS_RXANT", contact.rx_antenna),
        ("APP_MOAS_SWITCH_PATH", contact.switch_path),
    )
    return "".join(_field(name, value) for name, value in fields) + "<EOR>\n"


def adif_text(
    contacts: Iterable[Contact], *, station_callsign: str = "", created: datetime | None = None
) -> str:
    """The ``.adi`` file for ``contacts``: a header, then one record per contact."""
    stamp = (created or datetime.now(UTC)).astimezone(UTC).strftime("%Y%m%d %H%M%S")
    header = (
        f"Antenna log exported by moas-gui {__version__}\n"
        + _field("ADIF_VER", ADIF_VERSION)
        + "\n"
        + _field("PROGRAMID", PROGRAM_ID)
        + "\n"
        + _field("PROGRAMVERSION", __version__)
        + "\n"
        + _field("CREATED_TIMESTAMP", stamp)
        + "\n"
        + "<EOH>\n"
    )
    return header + "".join(_record(contact, station_callsign) for contact in contacts)


def write_adif(
    reader: JournalReader,
    period: Period,
    path: str | os.PathLike[str],
    *,
    station_callsign: str = "",
) -> int:
    """Writes the contacts of ``period`` to ``path`` (whole or not at all); returns how
    many.  Raises ``OSError`` when the file cannot be written."""
    contacts = reader.contacts(period)
    text = adif_text(contacts, station_callsign=station_callsign)
    write_text_atomic(Path(path), text)
    return len(contacts)


def parse_utc(text: str) -> float:
    """POSIX seconds for an ISO 8601 time (``2026-11-28T14:00Z``, ``2026-11-28 14:00``,
    ``2026-11-28``); one without an offset is UTC.  Raises ``ValueError`` saying what is
    wrong."""
    try:
        when = datetime.fromisoformat(text.strip())
    except ValueError:
        raise ValueError(
            f"{text!r} is not a time; write it as ISO 8601 in UTC, e.g. 2026-11-28T14:00Z"
        ) from None
    if when.tzinfo is None:
        when = when.replace(tzinfo=UTC)
    return when.timestamp()
