"""Contact packets (moas_gui.sources.n1mm_contact): not1mm's captured datagrams and N1MM
Logger+'s documented ones read, bad ones refused with a reason, and the N1MM listener
mapping each to a station and radio as it maps RadioInfo."""

from __future__ import annotations

import calendar
from pathlib import Path

import pytest

from moas_gui.sources.n1mm import N1MMListener
from moas_gui.sources.n1mm_contact import (
    ContactPacket,
    contact_packet,
    parse_contact,
    parse_timestamp,
)
from moas_gui.sources.n1mm_packet import MAX_PACKET_BYTES, N1MMPacketError, radio_info_packet

FIXTURES = Path(__file__).resolve().parent / "fixtures"


def fixture(name: str) -> bytes:
    (path,) = FIXTURES.glob(f"{name}*.xml")
    return path.read_bytes()


def utc(text: str) -> float:
    return float(calendar.timegm(tuple(int(x) for x in  # type: ignore[arg-type]
                                       text.replace("-", " ").replace(":", " ").split())
                                 + (0, 0, 0)))


def test_not1mm_contactinfo_as_captured() -> None:
    packet = parse_contact(fixture("not1mm-1-"))
    assert packet == ContactPacket(
        kind="contactinfo", contact_id="5b0c7c2e4a0c4f3e8c1f1b7d2b0e6a11",
        time=utc("2026-11-28 10:00:05"), call="DL1ABC", band="14", mode="CW",
        rx_khz=14025.12, tx_khz=14025.12, radio_nr=1, station_name="NOT1MM-PC",
        operator="K1XX", contest="CQWWCW", app="NOT1MM")


def test_not1mm_replace_and_delete() -> None:
    replaced = parse_contact(fixture("not1mm-4-"))
    assert (replaced.kind, replaced.contact_id, replaced.call) == (
        "contactreplace", "9e3f6d1a2b7c4e5f8a0b1c2d3e4f5a62", "JA1XYW")
    deleted = parse_contact(fixture("not1mm-5-"))
    assert (deleted.kind, deleted.contact_id, deleted.call, deleted.time) == (
        "contactdelete", "c1d2e3f4a5b6478899aabbccddeeff03", "PY2AA", utc("2026-11-28 10:02:13"))
    with pytest.raises(N1MMPacketError) as refused:
        parse_contact(fixture("not1mm-6-radioinfo"))
    assert refused.value.reason == "not_contact"


def test_n1mm_documented_packets() -> None:
    logged = parse_contact(fixture("n1mm-1-"))
    assert (logged.kind, logged.radio_nr, logged.station_name, logged.rx_khz, logged.band,
            logged.operator, logged.contest) == (
        "contactinfo", 2, "RUN2-PC", 7025.30, "7", "N1OP", "CQWWCW")
    assert parse_contact(fixture("n1mm-3-")).contact_id == logged.contact_id  # the duplicate
    assert parse_contact(fixture("n1mm-2-")).call == "OH2BHX"
    assert parse_contact(fixture("n1mm-4-")).kind == "contactdelete"


def test_our_fake_loggers_packets_read_back() -> None:
    data = contact_packet("contactinfo", "abc123", utc("2026-01-02 03:04:05"), "W1AW",
                          band="3.5", rx_khz=3525.5, radio_nr=2, operator="AB1CD")
    packet = parse_contact(data)
    assert (packet.call, packet.band, packet.rx_khz, packet.tx_khz, packet.radio_nr,
            packet.time) == ("W1AW", "3.5", 3525.5, 3525.5, 2, utc("2026-01-02 03:04:05"))


@pytest.mark.parametrize(("data", "reason", "words"), [
    (b"x" * (MAX_PACKET_BYTES + 1), "too_large", "limit"),
    (b"<contactinfo><call>W1AW", "not_xml", "not XML"),
    (b'<?xml version="1.0"?><!DOCTYPE a [<!ENTITY b "c">]><contactinfo/>', "doctype",
     "document type"),
    ((b"<contactinfo><timestamp>2026-01-01 00:00:00</timestamp><call>W1AW</call>"
     b"</contactinfo>"), "missing_field", "without <ID>"),
    (b"<contactinfo><ID>a1</ID><call>W1AW</call></contactinfo>", "missing_field",
     "without <timestamp>"),
    ((b"<contactinfo><ID>a b</ID><call>W</call><timestamp>2026-01-01 00:00:00</timestamp>"
     b"</contactinfo>"), "bad_value", "not a contact identity"),
    ((b"<contactinfo><ID>a1</ID><call>W</call><timestamp>yesterday</timestamp>"
     b"</contactinfo>"), "bad_value", "YYYY-MM-DD"),
    ((b"<contactinfo><ID>a1</ID><call>W</call><timestamp>2026-02-30 00:00:00</timestamp>"
     b"</contactinfo>"), "bad_value", "exists"),
    ((b"<contactinfo><ID>a1</ID><call>W</call><timestamp>2026-01-01 00:00:00</timestamp>"
     b"<rxfreq>14O25</rxfreq></contactinfo>"), "bad_value", "rxfreq"),
    ((b"<contactinfo><ID>a1</ID><call>W</call><timestamp>2026-01-01 00:00:00</timestamp>"
     b"<radionr>100</radionr></contactinfo>"), "bad_value", "radionr"),
    (b"<spot><call>W1AW</call></spot>", "not_contact", "not a contact"),
])
def test_bad_packets_are_refused_saying_what(data: bytes, reason: str, words: str) -> None:
    with pytest.raises(N1MMPacketError, match=words) as refused:
        parse_contact(data)
    assert refused.value.reason == reason


def test_timestamps_are_utc() -> None:
    assert parse_timestamp("1970-01-01 00:01:00") == 60.0
    assert parse_timestamp("2026-11-28T10:00:05.123") == utc("2026-11-28 10:00:05")


def test_the_listener_maps_contacts_as_it_maps_radio_info() -> None:
    got: list[tuple[ContactPacket, int | None, int | None]] = []
    listener = N1MMListener({"10.0.0.5": 1}, names={"RUN2-PC": 2},
                            on_contact=lambda p, s, r: got.append((p, s, r)))
    listener.handle(fixture("n1mm-1-"), "10.0.0.9")  # by its StationName: station 2
    listener.handle(fixture("not1mm-1-"), "10.0.0.5")  # by its address: station 1
    listener.handle(fixture("not1mm-2-"), "10.0.0.77")  # neither: no station
    listener.handle(b"<contactinfo><ID>a1</ID></contactinfo>", "10.0.0.5")  # bad
    listener.handle(b"<spot/>", "10.0.0.5")  # another packet, not ours
    assert [(p.call, s, r) for p, s, r in got] == [("OH2BH", 2, 2), ("DL1ABC", 1, 1),
                                                   ("JA1XYZ", None, None)]
    stats = listener.stats()
    assert stats.contacts == 3
    assert stats.refused == {"missing_field": 1, "not_radio_info": 1}


def test_without_a_contact_callback_contacts_are_not_ours() -> None:
    listener = N1MMListener({"10.0.0.5": 1})
    listener.handle(fixture("not1mm-1-"), "10.0.0.5")
    assert listener.stats().contacts == 0
    assert listener.stats().refused == {"not_radio_info": 1}


def test_a_contact_named_for_its_host_takes_the_station_its_senders_radio_info_maps_to() -> None:
    """not1mm: RadioInfo carries its configured station name (mapped by the file), a
    contact its computer's host name (NOT1MM-PC in the captures, matching no entry)."""
    got: list[tuple[str, int | None, int | None]] = []
    listener = N1MMListener({}, names={"RUN": 1, "MULT": 2},
                            on_contact=lambda p, s, r: got.append((p.call, s, r)))
    listener.handle(fixture("not1mm-1-"), "10.0.0.5")  # before any RadioInfo: unknown
    listener.handle(radio_info_packet(1, 14025.0, station_name="RUN", app="NOT1MM"), "10.0.0.5")
    listener.handle(radio_info_packet(1, 7025.0, station_name="MULT", app="NOT1MM"), "10.0.0.6")
    listener.handle(fixture("not1mm-2-"), "10.0.0.5")  # the run computer's QSO
    listener.handle(fixture("not1mm-3-"), "10.0.0.6")  # the mult computer's
    listener.handle(fixture("not1mm-4-"), "10.0.0.7")  # a computer that never said its name
    assert got == [("DL1ABC", None, None), ("JA1XYZ", 1, 1), ("PY2AA", 2, 1),
                   ("JA1XYW", None, None)]
    # a contact's own StationName, where the file names it, still decides
    named = N1MMListener({}, names={"NOT1MM-PC": 2, "RUN": 1},
                         on_contact=lambda p, s, r: got.append((p.call, s, r)))
    named.handle(radio_info_packet(1, 14025.0, station_name="RUN"), "10.0.0.5")
    named.handle(fixture("not1mm-2-"), "10.0.0.5")
    assert got[-1] == ("JA1XYZ", 2, 1)


@pytest.mark.parametrize(("stamp", "refused"), [
    ("9999-12-31 23:59:59", "more than a day ahead"),
    ("2026-11-30 12:00:01", "more than a day ahead"),
    ("1999-12-31 23:59:59", "before 2000"),
    ("0001-01-01 00:00:00", "before 2000"),
    ("2026-11-30 12:00:00", ""),  # a day ahead: a logging computer's clock, or its zone
    ("2000-01-01 00:00:00", ""),
])
def test_a_contact_dated_before_2000_or_over_a_day_ahead_is_refused(stamp: str,
                                                                     refused: str) -> None:
    now = utc("2026-11-29 12:00:00")
    when = utc(stamp)
    data = contact_packet("contactinfo", "ab12", 0.0, "DL1ABC").replace(
        b"1970-01-01 00:00:00", stamp.encode())
    for kind in ("contactinfo", "contactreplace"):
        packet = data.replace(b"contactinfo", kind.encode())
        if refused:
            with pytest.raises(N1MMPacketError, match=refused) as caught:
                parse_contact(packet, now)
            assert caught.value.reason == "bad_date" and f"{kind} ab12 of {stamp}" in str(caught.value)
        else:
            assert parse_contact(packet, now).time == when
    # a delete's date is not kept: it deletes whatever its ID names
    gone = contact_packet("contactdelete", "ab12", 0.0, "DL1ABC").replace(
        b"1970-01-01 00:00:00", stamp.encode())
    assert parse_contact(gone, now).kind == "contactdelete"


def test_the_listener_counts_a_contact_refused_for_its_date() -> None:
    got: list[object] = []
    listener = N1MMListener({"10.0.0.5": 1}, on_contact=lambda *a: got.append(a))
    far = contact_packet("contactinfo", "ab12", 0.0, "DL1ABC").replace(
        b"1970-01-01 00:00:00", b"9999-12-31 23:59:59")
    for _ in range(3):
        listener.handle(far, "10.0.0.5")
    assert got == [] and listener.stats().refused == {"bad_date": 3}
