"""N1MM Logger+ contact packets: bytes in, a frozen :class:`ContactPacket` out.

Sans-IO, with the same safety as :mod:`.n1mm_packet` (packets over
:data:`~.n1mm_packet.MAX_PACKET_BYTES` refused unread, a document type declaration
refused before any entity in it is read).  Three packets carry the log, on the
same UDP port as ``RadioInfo`` (N1MM's "Contacts" broadcast, which not1mm sends too):

``contactinfo``
    a QSO was logged: ``timestamp`` (UTC, ``YYYY-MM-DD HH:MM:SS``), ``call``,
    ``band`` (MHz, as N1MM writes it: ``14``, ``3.5``), ``mode``, ``rxfreq`` and
    ``txfreq`` (10 Hz units), ``radionr``, ``StationName`` (the logging computer),
    ``operator``, ``contestname`` and ``ID`` (the contact's own identity, the same
    on every computer of a network);
``contactreplace``
    the same fields, for a QSO edited after it was logged (same ``ID``);
``contactdelete``
    ``ID`` (and ``timestamp``, ``call``, ``StationName``) of a QSO removed from the log.

:func:`parse_contact` raises :class:`~.n1mm_packet.N1MMPacketError` with reason
``not_contact`` for any other packet, ``missing_field`` when ``ID`` (or, but for a
delete, ``timestamp`` or ``call``) is missing, ``bad_value`` for a value that
cannot be read and ``bad_date`` for a logged or edited contact dated before 2000 or
more than a day ahead of the server's clock
(:func:`~moas_gui.antenna_log.records.contact_date_problem`: a journal keeps no
contact its retention could not expire).  A missing or empty ``radionr`` is radio 1 (a logger with one radio).
"""

from __future__ import annotations

import calendar
import re
import time
from typing import Final

from moas_gui.antenna_log.records import ContactKind, ContactPacket, contact_date_problem
from moas_gui.sources.n1mm_packet import (
    MAX_PACKET_BYTES,
    MAX_RADIO_NR,
    N1MMPacketError,
    _fields,
    _int,
    _khz,
    _parse_xml,
)

KINDS: Final[tuple[ContactKind, ...]] = ("contactinfo", "contactreplace", "contactdelete")

MAX_ID_CHARS: Final = 64
"""N1MM's IDs are 32 hex digits (a GUID); anything past 64 characters is refused."""
MAX_TEXT_CHARS: Final = 64
"""Calls, modes, names: longer text is cut to this (it is shown, never interpreted)."""

_ID: Final = re.compile(r"[0-9A-Za-z{}_-]{1,64}")
_TIMESTAMP: Final = re.compile(
    r"([0-9]{4})-([0-9]{2})-([0-9]{2})[ T]([0-9]{2}):([0-9]{2}):([0-9]{2})(?:\.[0-9]{1,7})?Z?")


def _text(fields: dict[str, str], name: str) -> str:
    return fields.get(name, "")[:MAX_TEXT_CHARS]


def parse_timestamp(text: str) -> float:
    """N1MM's ``timestamp`` (UTC) as POSIX seconds; :class:`N1MMPacketError` when unreadable."""
    match = _TIMESTAMP.fullmatch(text.strip())
    if match is None:
        raise N1MMPacketError(
            "bad_value", f"<timestamp>{text[:40]}</timestamp> is not a time written "
                         "YYYY-MM-DD HH:MM:SS")
    parts = tuple(int(g) for g in match.groups())
    try:
        time.strptime(match.group(0)[:19].replace("T", " "), "%Y-%m-%d %H:%M:%S")
    except ValueError:
        raise N1MMPacketError("bad_value", f"<timestamp>{text[:40]}</timestamp> is not a "
                                           "date and time that exists") from None
    return float(calendar.timegm((*parts, 0, 0, 0)))


def parse_contact(data: bytes, now: float | None = None) -> ContactPacket:
    """Read one datagram; raise :class:`N1MMPacketError` when it is not a usable contact
    packet.  ``now`` is the server's clock (POSIX seconds; default: now)."""
    if len(data) > MAX_PACKET_BYTES:
        raise N1MMPacketError(
            "too_large", f"packet of {len(data)} bytes is over the {MAX_PACKET_BYTES}-byte limit")
    root = _parse_xml(data)
    kind = str(root.tag)
    if kind not in KINDS:
        raise N1MMPacketError("not_contact", f"<{kind[:40]}> packet is not a contact")
    fields = _fields(root)
    contact_id = fields.get("ID", "")
    if not contact_id:
        raise N1MMPacketError("missing_field", f"{kind} without <ID>")
    if _ID.fullmatch(contact_id) is None:
        raise N1MMPacketError("bad_value", f"<ID>{contact_id[:MAX_ID_CHARS]}</ID> is not a "
                                           "contact identity (letters, digits, - and _)")
    if kind != "contactdelete":
        for name in ("timestamp", "call"):
            if not fields.get(name):
                raise N1MMPacketError("missing_field", f"{kind} {contact_id} without <{name}>")
    stamp = fields.get("timestamp", "")
    radio_nr = _int(fields, "radionr")
    if radio_nr is None or radio_nr == 0:
        radio_nr = 1
    if radio_nr > MAX_RADIO_NR:
        raise N1MMPacketError("bad_value", f"<radionr>{radio_nr}</radionr> is not a radio "
                                           f"number 1-{MAX_RADIO_NR}")
    when = parse_timestamp(stamp) if stamp else None
    problem = None if when is None or kind == "contactdelete" else contact_date_problem(when, now)
    if problem is not None:
        raise N1MMPacketError("bad_date", f"{kind} {contact_id} of {stamp[:19]} refused: "
                                          f"{problem}")
    return ContactPacket(
        kind=kind,  # one of KINDS, checked above
        contact_id=contact_id,
        time=when,
        call=_text(fields, "call").upper(),
        band=_text(fields, "band"),
        mode=_text(fields, "mode"),
        rx_khz=_khz(fields, "rxfreq"),
        tx_khz=_khz(fields, "txfreq"),
        radio_nr=radio_nr,
        station_name=_text(fields, "StationName"),
        operator=_text(fields, "operator"),
        contest=_text(fields, "contestname"),
        app=_text(fields, "app"),
    )


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def contact_packet(
    kind: ContactKind,
    contact_id: str,
    when: float,
    call: str = "",
    *,
    band: str = "14",
    mode: str = "CW",
    rx_khz: float = 14025.0,
    tx_khz: float | None = None,
    radio_nr: int = 1,
    station_name: str = "STATION1",
    operator: str = "",
    contest: str = "CQ-WW-CW",
) -> bytes:
    """A contact datagram laid out as N1MM Logger+ documents it (the fake logger of the
    tests and benchmarks); ``contactdelete`` carries only what N1MM's does."""
    stamp = time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(when))
    if kind == "contactdelete":
        body = ["\t<app>N1MM</app>", f"\t<timestamp>{stamp}</timestamp>",
                f"\t<call>{_escape(call)}</call>", "\t<contestnr>1</contestnr>",
                f"\t<StationName>{_escape(station_name)}</StationName>",
                f"\t<ID>{contact_id}</ID>"]
    else:
        tx = rx_khz if tx_khz is None else tx_khz
        body = [
            "\t<app>N1MM</app>", f"\t<contestname>{_escape(contest)}</contestname>",
            "\t<contestnr>1</contestnr>", f"\t<timestamp>{stamp}</timestamp>",
            "\t<mycall>N0CALL</mycall>", f"\t<band>{_escape(band)}</band>",
            f"\t<rxfreq>{round(rx_khz * 100)}</rxfreq>", f"\t<txfreq>{round(tx * 100)}</txfreq>",
            f"\t<operator>{_escape(operator)}</operator>", f"\t<mode>{_escape(mode)}</mode>",
            f"\t<call>{_escape(call)}</call>", "\t<snt>599</snt>", "\t<rcv>599</rcv>",
            f"\t<radionr>{radio_nr}</radionr>", "\t<IsOriginal>True</IsOriginal>",
            f"\t<NetBiosName>{_escape(station_name)}</NetBiosName>",
            f"\t<StationName>{_escape(station_name)}</StationName>",
            f"\t<ID>{contact_id}</ID>",
        ]
    lines = ['<?xml version="1.0" encoding="utf-8"?>', f"<{kind}>", *body, f"</{kind}>"]
    return ("\r\n".join(lines) + "\r\n").encode("utf-8")


__all__ = [
    "KINDS",
    "MAX_ID_CHARS",
    "ContactKind",
    "ContactPacket",
    "contact_packet",
    "parse_contact",
    "parse_timestamp",
]
