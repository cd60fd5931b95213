"""N1MM Logger+ in full over real UDP on 127.0.0.1: StationName, transmit and receive
focus, run state; not1mm's and DXLog.net's packets; newest wins; a logger that returns.

Recorded packets:

- N1MM's own: the documented examples (n1mmwp.hamdocs.com/appendices/
  external-udp-broadcasts/, reproduced in shared/specs/logger-network.md 1.8);
- not1mm's: laid out as mbridak/not1mm writes it (not1mm/lib/n1mm.py, its
  ``radio_info`` fields in that order, serialised on one line by ``dicttoxml``
  with the extra ``uNICORNbLOOD`` element; ``Freq`` is the Hz figure without its
  last digit, not1mm/__main__.py).
"""

from __future__ import annotations

import asyncio
import logging
import socket

import pytest

from moas_gui.config.model import N1MMStation
from moas_gui.sources.base import (
    ActiveRadio,
    FocusRadio,
    FrequencyReport,
    RunOrSearch,
    SourceEvent,
    SourceHub,
)
from moas_gui.sources.dxlog import DXLogListener
from moas_gui.sources.n1mm import N1MMListener, radio_info_packet

NOT1MM_RADIO_INFO = (
    b'<?xml version="1.0" encoding="UTF-8" ?><RadioInfo><app>NOT1MM</app>'
    b"<StationName>fedora-shack</StationName><uNICORNbLOOD>1</uNICORNbLOOD>"
    b"<RadioNr>1</RadioNr><Freq>1403250</Freq><TXFreq>1403250</TXFreq><Mode>CW</Mode>"
    b"<OpCall>K6GTE</OpCall><IsRunning>True</IsRunning><FocusEntry>0</FocusEntry>"
    b"<EntryWindowHwnd>0</EntryWindowHwnd><Antenna></Antenna><Rotors></Rotors>"
    b"<FocusRadioNr>1</FocusRadioNr><IsStereo>False</IsStereo><IsSplit>False</IsSplit>"
    b"<ActiveRadioNr>1</ActiveRadioNr><IsTransmitting>False</IsTransmitting>"
    b"<FunctionKeyCaption></FunctionKeyCaption><RadioName>Little Todd</RadioName>"
    b"<AuxAntSelected>-1</AuxAntSelected><AuxAntSelectedName></AuxAntSelectedName></RadioInfo>"
)

SO2R_RADIO2_SPLIT = (
    b'<?xml version="1.0" encoding="utf-8"?>\r\n<RadioInfo>\r\n\t<app>N1MM</app>\r\n'
    b"\t<StationName>SO2R-PC</StationName>\r\n\t<RadioNr>2</RadioNr>\r\n"
    b"\t<Freq>2102500</Freq>\r\n\t<TXFreq>2102800</TXFreq>\r\n\t<Mode>CW</Mode>\r\n"
    b"\t<OpCall>K1ABC</OpCall>\r\n\t<IsRunning>True</IsRunning>\r\n"
    b"\t<FocusEntry>264342</FocusEntry>\r\n\t<EntryWindowHwnd>264342</EntryWindowHwnd>\r\n"
    b"\t<Antenna>3</Antenna>\r\n\t<Rotors>TH6</Rotors>\r\n\t<FocusRadioNr>1</FocusRadioNr>\r\n"
    b"\t<IsStereo>True</IsStereo>\r\n\t<IsSplit>True</IsSplit>\r\n"
    b"\t<ActiveRadioNr>2</ActiveRadioNr>\r\n\t<IsTransmitting>True</IsTransmitting>\r\n"
    b"\t<FunctionKeyCaption>F1 CQ</FunctionKeyCaption>\r\n\t<RadioName>IC-7610</RadioName>\r\n"
    b"\t<AuxAntSelected>-1</AuxAntSelected>\r\n\t<AuxAntSelectedName></AuxAntSelectedName>\r\n"
    b"\t<IsConnected>True</IsConnected>\r\n</RadioInfo>\r\n"
)


class Sender:
    def __init__(self, port: int) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.port = port

    async def send(self, listener: N1MMListener, *packets: bytes) -> None:
        target = listener.stats().received + len(packets)
        for packet in packets:
            self.sock.sendto(packet, ("127.0.0.1", self.port))
        async with asyncio.timeout(5):
            while listener.stats().received < target:
                await asyncio.sleep(0.005)


async def started(listener: N1MMListener) -> Sender:
    return Sender(await listener.start(port=0, host="127.0.0.1"))


def frequencies(events: list[SourceEvent]) -> list[tuple[int, int, float, float]]:
    return [(e.station, e.radio, e.rx_khz, e.tx_khz) for e in events
            if isinstance(e, FrequencyReport)]


@pytest.mark.asyncio
async def test_the_so2r_sample_gives_split_tx_transmit_focus_receive_focus_and_run_state() -> None:
    events: list[SourceEvent] = []
    listener = N1MMListener([N1MMStation(station_name="SO2R-PC", station=4)],
                            on_event=events.append)
    sender = await started(listener)
    try:
        await sender.send(listener, SO2R_RADIO2_SPLIT, SO2R_RADIO2_SPLIT)
    finally:
        sender.sock.close()
        await listener.close()
    origin = "N1MM SO2R-PC (127.0.0.1)"
    assert events == [
        ActiveRadio(4, 2, origin),
        FocusRadio(4, 1, origin),
        RunOrSearch(4, 2, True, origin),
        FrequencyReport(4, 2, 21025.0, 21028.0, origin, mode="CW", transmitting=True),
    ], "the heartbeat repeat changes nothing and says nothing"


@pytest.mark.asyncio
async def test_focus_changes_are_told_once_each() -> None:
    events: list[SourceEvent] = []
    listener = N1MMListener({"127.0.0.1": 1}, on_event=events.append)
    sender = await started(listener)
    try:
        await sender.send(
            listener,
            radio_info_packet(1, 14025.0, active_radio_nr=1, focus_radio_nr=1),
            radio_info_packet(2, 7025.0, active_radio_nr=1, focus_radio_nr=1),
            radio_info_packet(1, 14025.0, active_radio_nr=2, focus_radio_nr=1),
            radio_info_packet(2, 7025.0, active_radio_nr=2, focus_radio_nr=2, is_running=True),
        )
    finally:
        sender.sock.close()
        await listener.close()
    focus = [e for e in events if not isinstance(e, FrequencyReport)]
    origin = "N1MM STATION1 (127.0.0.1)"
    assert focus == [
        ActiveRadio(1, 1, origin), FocusRadio(1, 1, origin), RunOrSearch(1, 1, False, origin),
        RunOrSearch(1, 2, False, origin),
        ActiveRadio(1, 2, origin),
        FocusRadio(1, 2, origin), RunOrSearch(1, 2, True, origin),
    ]


@pytest.mark.asyncio
async def test_a_station_is_found_by_its_name_after_its_address_changed() -> None:
    """DHCP gave the logging computer a new address: its StationName still maps it."""
    events: list[SourceEvent] = []
    listener = N1MMListener([N1MMStation("192.168.1.20", 2, station_name="Run-PC"),
                             N1MMStation("127.0.0.1", 5)], on_event=events.append)
    sender = await started(listener)
    try:
        await sender.send(listener, radio_info_packet(1, 3525.0, station_name="RUN-PC"),
                          radio_info_packet(1, 7025.0, station_name="other"))
    finally:
        sender.sock.close()
        await listener.close()
    assert frequencies(events) == [(2, 1, 3525.0, 3525.0), (5, 1, 7025.0, 7025.0)], (
        "the name wins (compared without case); an unnamed computer falls back to its address")


@pytest.mark.asyncio
async def test_with_names_only_an_unknown_name_is_ignored_with_one_debug_line(
    caplog: pytest.LogCaptureFixture,
) -> None:
    events: list[SourceEvent] = []
    listener = N1MMListener([N1MMStation(station_name="Run-PC", station=2)],
                            on_event=events.append)
    sender = await started(listener)
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.n1mm")
    try:
        await sender.send(listener, *[radio_info_packet(1, 3525.0, station_name="Mult-PC")] * 4)
    finally:
        sender.sock.close()
        await listener.close()
    assert events == [] and listener.stats().unknown_sender == 4
    lines = [r.getMessage() for r in caplog.records if "N1MMLogger" in r.getMessage()]
    assert lines == [("N1MM packet from 127.0.0.1 ignored: neither that address nor "
                     "StationName 'Mult-PC' is in N1MMLogger")]


@pytest.mark.asyncio
async def test_not1mm_packets_are_read_like_n1mms() -> None:
    events: list[SourceEvent] = []
    listener = N1MMListener({}, on_event=events.append, every_sender=3)
    sender = await started(listener)
    try:
        await sender.send(listener, NOT1MM_RADIO_INFO)
    finally:
        sender.sock.close()
        await listener.close()
    assert frequencies(events) == [(3, 1, 14032.5, 14032.5)]
    assert RunOrSearch(3, 1, True, "NOT1MM fedora-shack (127.0.0.1)") in events


@pytest.mark.asyncio
async def test_dxlog_radio_information_is_read_and_named_dxlog() -> None:
    events: list[SourceEvent] = []
    listener = DXLogListener({"127.0.0.1": 1}, on_event=events.append)
    sender = await started(listener)
    try:
        await sender.send(listener, radio_info_packet(2, 28025.0, app="DXLog", station_name="OP2"))
    finally:
        sender.sock.close()
        await listener.close()
    assert frequencies(events) == [(1, 2, 28025.0, 28025.0)]
    assert listener.kind == "dxlog" and listener.label == "DXLog.net"


@pytest.mark.asyncio
async def test_n1mm_and_a_second_source_for_one_radio_newest_wins_logged_once(
    caplog: pytest.LogCaptureFixture,
) -> None:
    got: list[SourceEvent] = []
    hub = SourceHub(got.append)
    first = N1MMListener({"127.0.0.1": 1}, on_event=hub)
    second = DXLogListener({"127.0.0.1": 1}, on_event=hub)
    a, b = await started(first), await started(second)
    caplog.set_level(logging.INFO, logger="moas_gui.sources")
    try:
        await a.send(first, radio_info_packet(1, 14000.0, station_name="A"))
        await b.send(second, radio_info_packet(1, 7000.0, app="DXLog", station_name="B"))
        await a.send(first, radio_info_packet(1, 14010.0, station_name="A"))
        await b.send(second, radio_info_packet(1, 7010.0, app="DXLog", station_name="B"))
    finally:
        for sender in (a, b):
            sender.sock.close()
        await first.close()
        await second.close()
    assert [k for _, _, k, _ in frequencies(got)] == [14000.0, 7000.0, 14010.0, 7010.0]
    overlaps = [r.getMessage() for r in caplog.records if "two sources" in r.getMessage()]
    assert len(overlaps) == 2, "once for the radio's frequency, once for the station's focus"
    assert any("radio 1" in line for line in overlaps)


@pytest.mark.asyncio
async def test_a_logger_that_goes_away_and_returns_is_heard_again() -> None:
    events: list[SourceEvent] = []
    listener = N1MMListener({"127.0.0.1": 1}, on_event=events.append)
    sender = await started(listener)
    try:
        await sender.send(listener, radio_info_packet(1, 14000.0))
        sender.sock.close()  # N1MM quits (no packets at all for a while) ...
        await asyncio.sleep(0.05)
        back = Sender(sender.port)  # ... and starts again on another source port
        await back.send(listener, radio_info_packet(1, 14000.0), radio_info_packet(1, 21000.0))
        back.sock.close()
    finally:
        await listener.close()
    assert [k for _, _, k, _ in frequencies(events)] == [14000.0, 21000.0]


@pytest.mark.asyncio
@pytest.mark.parametrize("packet", [
    b"\x00\x01garbage",
    SO2R_RADIO2_SPLIT[:200],
    b"<RadioInfo>" + b"<x>1</x>" * 3000 + b"</RadioInfo>",
    (b'<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;">]>'
    b"<RadioInfo><RadioNr>1</RadioNr><Freq>&b;</Freq></RadioInfo>"),
    radio_info_packet(1, 14000.0).replace(b"<Freq>1400000<", b"<Freq>99999999999999<"),
    radio_info_packet(1, 14000.0).replace(b"<Freq>1400000<", b"<Freq>\xd9\xa1\xd9\xa4<"),
])
async def test_bad_packets_never_reach_the_engine(packet: bytes) -> None:
    events: list[SourceEvent] = []
    listener = N1MMListener({"127.0.0.1": 1}, on_event=events.append)
    sender = await started(listener)
    try:
        await sender.send(listener, packet)
        await sender.send(listener, radio_info_packet(1, 3500.0))
    finally:
        sender.sock.close()
        await listener.close()
    assert frequencies(events) == [(1, 1, 3500.0, 3500.0)]
    assert listener.stats().malformed == 1
