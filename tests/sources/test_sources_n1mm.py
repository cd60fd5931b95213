"""The N1MM Logger listener over real UDP on 127.0.0.1: mapping, change filter, bad packets."""

from __future__ import annotations

import asyncio
import logging
import socket
from collections.abc import AsyncIterator
from dataclasses import dataclass, field

import pytest
import pytest_asyncio

from moas_gui.config.model import Config, N1MMStation
from moas_gui.sources import n1mm
from moas_gui.sources.n1mm import N1MMListener, RadioUpdate, radio_info_packet

Call = tuple[int, int, float, float]


@dataclass
class Recorder:
    """Collects ``on_frequency`` and ``on_update`` calls."""

    calls: list[Call] = field(default_factory=list)
    updates: list[RadioUpdate] = field(default_factory=list)

    def on_frequency(self, station: int, radio: int, khz: float, tx_khz: float) -> None:
        self.calls.append((station, radio, khz, tx_khz))

    def on_update(self, update: RadioUpdate) -> None:
        self.updates.append(update)


class Logger:
    """A fake N1MM Logger: a UDP socket on 127.0.0.1 that sends datagrams to the listener."""

    def __init__(self, port: int) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.port = port

    def send(self, data: bytes) -> None:
        self.sock.sendto(data, ("127.0.0.1", self.port))

    def close(self) -> None:
        self.sock.close()


@dataclass
class Running:
    listener: N1MMListener
    recorder: Recorder
    logger: Logger

    async def send_and_settle(self, *datagrams: bytes) -> None:
        """Send the datagrams and wait until the listener has taken every one."""
        await send_all(self.listener, self.logger, datagrams)


async def send_all(listener: N1MMListener, logger: Logger, datagrams: tuple[bytes, ...]) -> None:
    target = listener.stats().received + len(datagrams)
    for data in datagrams:
        logger.send(data)
    async with asyncio.timeout(5):
        while listener.stats().received < target:
            await asyncio.sleep(0.005)


async def start(stations: dict[str, int]) -> Running:
    recorder = Recorder()
    listener = N1MMListener(stations, recorder.on_frequency, on_update=recorder.on_update)
    port = await listener.start(port=0, host="127.0.0.1")
    return Running(listener, recorder, Logger(port))


@pytest_asyncio.fixture
async def station3() -> AsyncIterator[Running]:
    running = await start({"127.0.0.1": 3})
    yield running
    running.logger.close()
    await running.listener.close()


@pytest.mark.asyncio
async def test_a_packet_from_a_listed_address_sets_that_stations_radio(station3: Running) -> None:
    await station3.send_and_settle(radio_info_packet(1, 14025.0))
    assert station3.recorder.calls == [(3, 1, 14025.0, 14025.0)]


@pytest.mark.asyncio
async def test_so2r_radio_2_and_its_split_tx_frequency_reach_radio_2(station3: Running) -> None:
    await station3.send_and_settle(radio_info_packet(1, 7010.0),
                                   radio_info_packet(2, 21025.0, 21028.0, is_transmitting=True))
    assert station3.recorder.calls == [(3, 1, 7010.0, 7010.0), (3, 2, 21025.0, 21028.0)]
    assert station3.recorder.updates[-1].info.is_transmitting is True


@pytest.mark.asyncio
async def test_heartbeats_with_the_same_frequency_are_not_passed_on(station3: Running) -> None:
    same = radio_info_packet(1, 3525.0)
    await station3.send_and_settle(same, same, same)
    assert station3.recorder.calls == [(3, 1, 3525.0, 3525.0)]
    assert [u.changed for u in station3.recorder.updates] == [True, False, False]
    await station3.send_and_settle(radio_info_packet(1, 3525.0, 3526.0))
    await station3.send_and_settle(same)
    assert station3.recorder.calls[1:] == [(3, 1, 3525.0, 3526.0), (3, 1, 3525.0, 3525.0)]


@pytest.mark.asyncio
async def test_a_burst_tells_each_radio_only_its_latest_frequency(station3: Running) -> None:
    """Packets waiting together are read together; a stale frequency is never acted on."""
    burst = [radio_info_packet(1, khz) for khz in (7000.0, 7010.0, 7020.0)] + [
        radio_info_packet(2, 1830.0), radio_info_packet(1, 7030.0)]
    for data in burst:  # all sent before the event loop runs again: they wait together
        station3.logger.send(data)
    async with asyncio.timeout(5):
        while station3.listener.stats().received < 5:
            await asyncio.sleep(0.005)
    assert sorted(station3.recorder.calls) == [(3, 1, 7030.0, 7030.0), (3, 2, 1830.0, 1830.0)]
    assert len(station3.recorder.updates) == 5, "every packet is still read and counted"
    stats = station3.listener.stats()
    assert stats.delivered == len(station3.recorder.calls) == 2, "delivered counts the calls"
    assert stats.superseded == 3, "the three older frequencies of radio 1 were skipped"
    assert stats.accepted == stats.delivered + stats.superseded


@pytest.mark.asyncio
async def test_a_change_of_transmit_state_alone_is_an_update_not_a_frequency(
    station3: Running,
) -> None:
    await station3.send_and_settle(radio_info_packet(1, 14000.0),
                                   radio_info_packet(1, 14000.0, is_transmitting=True))
    assert len(station3.recorder.calls) == 1
    assert [u.info.is_transmitting for u in station3.recorder.updates] == [False, True]


@pytest.mark.asyncio
async def test_forget_makes_the_next_heartbeat_count_again(station3: Running) -> None:
    same = radio_info_packet(2, 1830.0)
    await station3.send_and_settle(same)
    station3.listener.forget()
    await station3.send_and_settle(same)
    assert station3.recorder.calls == [(3, 2, 1830.0, 1830.0)] * 2


@pytest.mark.asyncio
async def test_packets_from_an_address_not_in_the_list_are_ignored_with_one_debug_line(
    caplog: pytest.LogCaptureFixture,
) -> None:
    running = await start({"192.0.2.7": 1})
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.n1mm")
    try:
        await send_all(running.listener, running.logger, (radio_info_packet(1, 14000.0),) * 5)
    finally:
        running.logger.close()
        await running.listener.close()
    assert running.recorder.calls == [] and running.recorder.updates == []
    assert running.listener.stats().unknown_sender == 5
    lines = [r.getMessage() for r in caplog.records if "not in N1MMLogger" in r.getMessage()]
    assert lines == ["N1MM packet from 127.0.0.1 ignored: that address is not in N1MMLogger"]


@pytest.mark.asyncio
async def test_bad_packets_are_counted_by_reason_and_the_next_good_one_still_works(
    station3: Running, caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.n1mm")
    await station3.send_and_settle(
        b"\x00\x01garbage",
        b"<RadioInfo><RadioNr>1</RadioNr>",
        b"<contactinfo><call>W1AW</call></contactinfo>",
        b"<RadioInfo><Freq>1400000</Freq></RadioInfo>",
        b"<RadioInfo><RadioNr>1</RadioNr><Freq>30000000000</Freq></RadioInfo>",
        b'<!DOCTYPE a [<!ENTITY x "y">]><RadioInfo><RadioNr>1</RadioNr><Freq>&x;</Freq></RadioInfo>',
        b"<RadioInfo>" + b" " * 20_000 + b"</RadioInfo>",
        radio_info_packet(1, 50100.0),
    )
    stats = station3.listener.stats()
    assert dict(stats.refused) == {"not_xml": 2, "not_radio_info": 1, "missing_field": 1,
                                   "bad_value": 1, "doctype": 1, "too_large": 1}
    assert stats.malformed == 6
    assert station3.recorder.calls == [(3, 1, 50100.0, 50100.0)]
    debug = [r for r in caplog.records if r.levelno == logging.DEBUG and "ignored" in r.getMessage()]
    # one line per reason: the second not-XML packet within the minute is only counted
    assert len(debug) == 6 and all("127.0.0.1 (station 3)" in r.getMessage() for r in debug)
    assert any("not a radio frequency" in r.getMessage() for r in debug)


@pytest.mark.asyncio
async def test_a_failing_callback_is_logged_and_counted_and_the_listener_carries_on(
    caplog: pytest.LogCaptureFixture,
) -> None:
    recorder = Recorder()
    seen: list[float] = []

    def broken(station: int, radio: int, khz: float, tx_khz: float) -> None:
        seen.append(khz)
        if len(seen) == 1:
            raise ValueError("engine refused")

    listener = N1MMListener({"127.0.0.1": 1}, broken, on_update=recorder.on_update)
    logger = Logger(await listener.start(port=0, host="127.0.0.1"))
    try:
        await send_all(listener, logger, (radio_info_packet(1, 7000.0),))
        await send_all(listener, logger, (radio_info_packet(1, 7001.0),))
    finally:
        logger.close()
        await listener.close()
    assert seen == [7000.0, 7001.0]
    assert listener.stats().callback_errors == 1
    assert any("engine refused" in r.getMessage() or r.exc_info for r in caplog.records)


@pytest.mark.asyncio
async def test_the_configuration_list_maps_addresses_and_host_names() -> None:
    config = Config(use_n1mm_logger=True, udp_port=12060,
                    n1mm_logger=(N1MMStation("10.0.0.9", 1), N1MMStation("localhost", 2)))
    recorder = Recorder()
    listener = N1MMListener.from_config(config, recorder.on_frequency, on_update=recorder.on_update)
    logger = Logger(await listener.start(port=0, host="127.0.0.1"))
    try:
        await send_all(listener, logger, (radio_info_packet(1, 28500.0),))
    finally:
        logger.close()
        await listener.close()
    assert recorder.calls == [(2, 1, 28500.0, 28500.0)]


def test_ipv4_mapped_ipv6_senders_are_the_same_station() -> None:
    calls: list[Call] = []
    listener = N1MMListener([N1MMStation("192.168.1.20", 4)],
                            lambda *args: calls.append(args))  # type: ignore[arg-type]
    listener.handle(radio_info_packet(2, 10110.0), "::ffff:192.168.1.20")
    assert calls == [(4, 2, 10110.0, 10110.0)]


def test_debug_lines_about_one_sender_are_limited_to_one_a_minute(
    caplog: pytest.LogCaptureFixture,
) -> None:
    now = [1000.0]
    listener = N1MMListener({"192.168.1.20": 1}, lambda *a: None, clock=lambda: now[0])
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.n1mm")
    for _ in range(100):
        listener.handle(b"junk", "192.168.1.20")
    now[0] += 61
    listener.handle(b"junk", "192.168.1.20")
    lines = [r.getMessage() for r in caplog.records]
    assert len(lines) == 2
    assert "(99 more like it since the last such line)" in lines[1]
    assert listener.stats().refused == {"not_xml": 101}


def test_last_heard_tells_when_each_radio_last_reported() -> None:
    now = [50.0]
    listener = N1MMListener({"192.168.1.20": 1}, lambda *a: None, clock=lambda: now[0])
    listener.handle(radio_info_packet(2, 0.0), "192.168.1.20")
    assert listener.last_heard(1, 2) == 50.0 and listener.last_heard(1, 1) is None
    assert listener.stats().no_frequency == 1 and listener.stats().delivered == 0


@pytest.mark.asyncio
async def test_a_port_held_by_another_program_is_reported_with_its_address() -> None:
    holder = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    holder.bind(("127.0.0.1", 0))
    port = holder.getsockname()[1]
    listener = N1MMListener({}, lambda *a: None)
    try:
        with pytest.raises(OSError, match=f"cannot bind UDP 127.0.0.1:{port}"):
            await listener.start(port=port, host="127.0.0.1")
    finally:
        holder.close()
    assert listener.port is None


@pytest.mark.asyncio
async def test_close_stops_listening_and_can_be_called_twice() -> None:
    listener = N1MMListener({}, lambda *a: None)
    port = await listener.start(port=0, host="127.0.0.1")
    assert listener.port == port
    await listener.close()
    await listener.close()
    assert listener.port is None


def test_the_public_names_do_not_drift() -> None:
    assert sorted(n1mm.__all__) == sorted([
        "DEFAULT_PORT", "ContactCallback", "FrequencyCallback", "N1MMListener",
        "N1MMPacketError", "N1MMStats",
        "RadioInfo", "RadioUpdate", "UpdateCallback", "parse_radio_info", "radio_info_packet"])
