"""The FlexRadio source against the test radio over real sockets on loopback."""

from __future__ import annotations

import asyncio
import logging
import socket
from collections.abc import AsyncIterator

import pytest
import pytest_asyncio
from helpers import free_port, until

from moas_gui.sources.base import ActiveRadio, FrequencyReport, SourceEvent
from moas_gui.sources.flex import FlexSource, split_target
from moas_gui.sources.flex_api import OPENING, SliceMap, parse_slice_map
from moas_gui.sources.flex_discovery import FlexDiscovery
from moas_gui.testing.flex_radio import FlexRadio


@pytest_asyncio.fixture
async def radio() -> AsyncIterator[FlexRadio]:
    r = FlexRadio(keepalive_timeout=2.0)
    await r.start()
    yield r
    await r.stop()


def reports(events: list[SourceEvent], ref: tuple[int, int]) -> list[FrequencyReport]:
    return [e for e in events if isinstance(e, FrequencyReport)
            and (e.station, e.radio) == ref]


def source_for(radio: FlexRadio, events: list[SourceEvent], slices: SliceMap | None = None,
               **kw: float) -> FlexSource:
    return FlexSource(f"127.0.0.1:{radio.port}", slices or SliceMap(), events.append,
                      retry=0.01, timeout=2.0, **kw)


def test_a_target_is_an_address_or_a_name() -> None:
    assert split_target("192.168.1.50") == ("192.168.1.50", 4992)
    assert split_target("192.168.1.50:5000") == ("192.168.1.50", 5000)
    assert split_target("flex.local") == ("flex.local", 4992)
    assert split_target("[fe80::1]:4992") == ("fe80::1", 4992)
    assert split_target("::1") == ("::1", 4992)
    assert split_target("1234-5678-9012-3456") is None
    assert split_target("Shack") is None
    with pytest.raises(ValueError):
        split_target("host:70000")
    with pytest.raises(ValueError):
        split_target(" ")


@pytest.mark.asyncio
async def test_slices_become_radios_and_band_changes_are_followed(radio: FlexRadio) -> None:
    radio.set_slice(0, RF_frequency=14.025, tx=1, active=1, txant="ANT2")
    radio.set_slice(1, RF_frequency=21.025)
    events: list[SourceEvent] = []
    source = source_for(radio, events)
    await source.start()
    try:
        await until(lambda: reports(events, (1, 1)) and reports(events, (1, 2)),
                    what="both radios reported")
        assert reports(events, (1, 1))[-1].rx_khz == pytest.approx(14025.0)
        assert reports(events, (1, 2))[-1].rx_khz == pytest.approx(21025.0)
        assert ActiveRadio(1, 1, source.origin) in events
        assert radio.commands[:4] == list(OPENING)
        radio.set_slice(0, RF_frequency=7.0125)
        await until(lambda: reports(events, (1, 1))[-1].rx_khz == pytest.approx(7012.5),
                    what="the band change")
        assert source.describe()[1] == "station 1 radio 1: slice A 7,012.500 kHz CW, RX ANT1, " \
                                       "TX ANT2"
    finally:
        await source.close()
    assert all(not c.startswith(("slice set", "client gui", "xmit")) for c in radio.commands)


@pytest.mark.asyncio
async def test_the_interlock_moves_the_transmitting_state(radio: FlexRadio) -> None:
    radio.set_slice(0, RF_frequency=14.025, tx=1)
    radio.set_slice(1, RF_frequency=21.025)
    events: list[SourceEvent] = []
    source = source_for(radio, events)
    await source.start()
    try:
        await until(lambda: reports(events, (1, 1)), what="the first report")
        radio.set_interlock("TRANSMITTING")
        await until(lambda: reports(events, (1, 1))[-1].transmitting is True, what="keyed")
        assert reports(events, (1, 2))[-1].transmitting is False
        radio.set_interlock("READY")
        await until(lambda: reports(events, (1, 1))[-1].transmitting is False, what="unkeyed")
    finally:
        await source.close()


@pytest.mark.asyncio
async def test_tx_moving_to_the_other_slice_swaps_the_default_radios(radio: FlexRadio) -> None:
    radio.set_slice(0, RF_frequency=14.025, tx=1)
    radio.set_slice(1, RF_frequency=21.025)
    events: list[SourceEvent] = []
    source = source_for(radio, events)
    await source.start()
    try:
        await until(lambda: reports(events, (1, 2)), what="the first reports")
        radio.set_slice(1, tx=1)
        await until(lambda: reports(events, (1, 1))[-1].rx_khz == pytest.approx(21025.0),
                    what="radio 1 on the transmitting slice")
        assert reports(events, (1, 2))[-1].rx_khz == pytest.approx(14025.0)
    finally:
        await source.close()


@pytest.mark.asyncio
async def test_a_map_by_letter_and_a_slice_removed(radio: FlexRadio) -> None:
    radio.set_slice(0, RF_frequency=14.025, tx=1)
    radio.set_slice(1, RF_frequency=21.025)
    events: list[SourceEvent] = []
    source = source_for(radio, events, SliceMap(by_letter=parse_slice_map("A=1/1,B=2/1")))
    await source.start()
    try:
        await until(lambda: reports(events, (2, 1)), what="slice B on station 2")
        radio.set_slice(1, tx=1)
        await until(lambda: ActiveRadio(2, 1, source.origin) in events, what="focus to B")
        assert reports(events, (1, 1))[-1].rx_khz == pytest.approx(14025.0)  # stays on A
        count = len(reports(events, (2, 1)))
        radio.remove_slice(1)
        await until(lambda: "no slice" in source.describe()[2], what="slice B gone")
        radio.set_slice(0, RF_frequency=3.525)
        await until(lambda: reports(events, (1, 1))[-1].rx_khz == pytest.approx(3525.0),
                    what="A still followed")
        assert len(reports(events, (2, 1))) == count  # nothing guessed for the gone slice
    finally:
        await source.close()


@pytest.mark.asyncio
async def test_the_radio_gone_and_back(radio: FlexRadio, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO)
    radio.set_slice(0, RF_frequency=14.025, tx=1)
    events: list[SourceEvent] = []
    source = source_for(radio, events)
    await source.start()
    try:
        await until(lambda: reports(events, (1, 1)), what="the first report")
        port = radio.port
        await radio.stop()
        await until(lambda: not source.online, what="offline")
        assert source.describe()[0].startswith("FlexRadio 127.0.0.1:")
        assert "offline" in source.describe()[0]
        assert source.describe()[1] == "station 1 radio 1: no slice, frequency unknown"
        before = len(events)
        tried = source.link.failures  # it keeps trying: two more attempts, nothing heard
        await until(lambda: source.link.failures >= tried + 2, what="two more attempts")
        assert len(events) == before
        back = FlexRadio(port=port)
        back.set_slice(0, RF_frequency=28.025, tx=1)
        await back.start()
        try:
            await until(lambda: reports(events, (1, 1))[-1].rx_khz == pytest.approx(28025.0),
                        what="the radio back")
            assert source.connects == 2
        finally:
            await back.stop()
    finally:
        await source.close()
    text = caplog.text
    assert "frequency unknown until it is back" in text and "is back" in text


@pytest.mark.asyncio
async def test_keepalive_pings_keep_the_connection(radio: FlexRadio) -> None:
    radio.set_slice(0, RF_frequency=14.025, tx=1)
    events: list[SourceEvent] = []
    source = source_for(radio, events, ping_interval=0.05, silent_after=30.0)
    await source.start()
    try:
        await until(lambda: radio.commands.count("ping") >= 3, what="three pings")
        assert source.connects == 1 and radio.client_count == 1
    finally:
        await source.close()


@pytest.mark.asyncio
async def test_a_malformed_line_is_dropped_and_nothing_is_lost(radio: FlexRadio) -> None:
    radio.set_slice(0, RF_frequency=14.025, tx=1)
    events: list[SourceEvent] = []
    source = source_for(radio, events)
    await source.start()
    try:
        await until(lambda: reports(events, (1, 1)), what="the first report")
        radio.send_raw(b"garbage here\nS1|slice 0 RF_frequency=fourteen\n\xff\xfe\n")
        radio.set_slice(0, RF_frequency=10.125)
        await until(lambda: reports(events, (1, 1))[-1].rx_khz == pytest.approx(10125.0),
                    what="the next good line")
        assert source.bad.counts == {"not_flex": 2, "bad_frequency": 1}
        assert source.connects == 1
    finally:
        await source.close()


@pytest.mark.asyncio
async def test_a_peer_that_is_not_a_flexradio_is_refused_clearly(
        caplog: pytest.LogCaptureFixture) -> None:
    async def http(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        writer.write(b"HTTP/1.1 400 Bad Request\r\n\r\n")
        await writer.drain()
        writer.close()

    server = await asyncio.start_server(http, "127.0.0.1", 0)
    port = server.sockets[0].getsockname()[1]
    events: list[SourceEvent] = []
    source = FlexSource(f"127.0.0.1:{port}", SliceMap(), events.append, retry=0.05)
    await source.start()
    try:
        await until(lambda: source.refusals >= 3, what="three refusals")
    finally:
        await source.close()
        server.close()
        await server.wait_closed()
    errors = [r.getMessage() for r in caplog.records if r.levelno == logging.ERROR]
    assert len(errors) == 1  # said once, not at every attempt
    assert "is not a FlexRadio: it began with 'HTTP/1.1 400 Bad Request'" in errors[0]
    assert events == []


@pytest.mark.asyncio
async def test_a_radio_named_by_nickname_is_found_by_its_datagrams(radio: FlexRadio) -> None:
    radio.set_slice(0, RF_frequency=18.075, tx=1)
    port = free_port(socket.SOCK_DGRAM)
    events: list[SourceEvent] = []
    source = FlexSource("shack", SliceMap(), events.append, retry=0.05, timeout=2.0,
                        discovery_port=port)
    await source.start()
    try:
        async def announce() -> None:
            while True:
                radio.announce(("127.0.0.1", port))
                await asyncio.sleep(0.1)

        announcing = asyncio.get_running_loop().create_task(announce())
        await until(lambda: reports(events, (1, 1)), what="the radio found")
        announcing.cancel()
        assert source.found is not None and source.found.serial == radio.serial
        assert source.describe()[0].startswith('FlexRadio FLEX-6600 "Shack" (serial ')
    finally:
        await source.close()


@pytest.mark.asyncio
async def test_discovery_keeps_the_radios_heard_and_drops_the_rest() -> None:
    a = FlexRadio(serial="1111-2222", nickname="Alpha", port=4992)
    b = FlexRadio(serial="3333-4444", nickname="Bravo", host="127.0.0.2", port=4993)
    discovery = FlexDiscovery(port=0, host="127.0.0.1")
    port = await discovery.start()
    try:
        a.announce(("127.0.0.1", port))
        b.announce(("127.0.0.1", port))
        a.announce(("127.0.0.1", port))
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.sendto(b"not a radio", ("127.0.0.1", port))
        await until(lambda: len(discovery.radios()) == 2 and discovery.bad.total == 1,
                    what="two radios and one drop")
        assert [r.nickname for r in discovery.radios()] == ["Alpha", "Bravo"]
        found = discovery.find("3333-4444")
        assert found is not None and (found.ip, found.port) == ("127.0.0.2", 4993)
    finally:
        await discovery.close()


def test_a_flex_source_named_on_the_client_command_line() -> None:
    from moas_gui.sources.spec import make_source, parse_spec

    spec = parse_spec("flex:192.168.1.50:4992,b=2,a=1")
    assert spec.address == "192.168.1.50:4992" and spec.text() == "flex:192.168.1.50:4992,b=2,a=1"
    source = make_source(spec, 3, lambda event: None)
    assert isinstance(source, FlexSource)
    assert source.slices.by_letter == {"A": (3, 1), "B": (3, 2)}
    plain = make_source(parse_spec("flex:Shack,radio2=4"), 2, lambda event: None)
    assert isinstance(plain, FlexSource) and plain.address is None
    assert (plain.slices.first, plain.slices.second) == ((2, 1), (2, 4))
    for wrong, why in (("flex", "flex needs the radio"), ("flex:x,z=1", "not one of its"),
                       ("flex:x,a=one", "not a whole number")):
        with pytest.raises(ValueError, match=why):
            parse_spec(wrong)
