"""The switch link against an emulated box served on a real pseudo-terminal
and opened with pyserial, on the real clock: loading, differences, a port
that goes and comes back, a box that stops answering (the real timers, end to
end) or is reset behind the link's back, errors, Reset, Save Switch Data.
The timers' own cases (pings, silence, retries, garbage, Stop/Start) run on a
fake clock in ``test_moas2_link_clock.py``."""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator, Mapping
from dataclasses import replace
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until
from switch_support import Heard

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.emulator.box import EmulatedBox, Traffic
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, remove_link, serve
from moas_gui.hw.moas2.link import LinkOptions, LinkStatus, LinkTiming, SwitchLink
from moas_gui.hw.moas2.sync import initialise
from moas_gui.hw.moas2.transport import EmulatorTransport, SerialTransport

pytestmark = pytest.mark.realtime

FAST = LinkTiming(ping_interval=0.05, answer_timeout=2.0, retry_first=0.05, retry_max=0.2)
"""Quick pings and retries; a patient answer timeout, for a busy test machine."""
PINGED = replace(FAST, answer_timeout=1.0)
"""For watching real pings keep a link alive, and their silence noticed, in real time."""
IDLE = StationAntennas()


def band(slot: int, relays: set[int]) -> StationAntennas:
    return StationAntennas(tx=slot, tx_relays=frozenset(relays), rx=slot,
                           rx_relays=frozenset(relays))


def wanted(*stations: StationAntennas, **more: object) -> SwitchState:
    padded = tuple(stations) + (IDLE,) * (6 - len(stations))
    return SwitchState(stations=padded, conflicts=frozenset({(a, a) for a in range(10)}),
                       **more)  # type: ignore[arg-type]


STATE_A = wanted(band(1, {1, 2}), band(2, {8}))
STATE_B = wanted(band(3, {5}), band(2, {8}))


class Served:
    """An emulated box on a pseudo-terminal, reachable at a stable link path."""

    def __init__(self, link: Path, unit_id: int = 0) -> None:
        self.link = link
        self.unit_id = unit_id
        self.box: EmulatedBox
        self.endpoint: PtyEndpoint
        self.received = bytearray()

    def start(self) -> None:
        self.box = EmulatedBox(EmulatorModel(unit_id=self.unit_id))
        self.endpoint = PtyEndpoint()
        serve(self.box, self.endpoint, asyncio.get_running_loop())
        self.box.add_listener(self._traffic)
        make_link(self.endpoint.path, self.link)

    def _traffic(self, kind: Traffic, data: bytes) -> None:
        if kind is Traffic.RECEIVED:
            self.received += data

    def stop(self) -> None:
        # The link goes first: a link retrying it must not reach the next pseudo-terminal
        # that takes this one's number (another test's box, in this or another process).
        remove_link(self.link, self.endpoint.path)
        self.box.close()
        self.endpoint.close()

    @property
    def relays(self) -> frozenset[int]:
        return self.box.view().relays


@pytest_asyncio.fixture
async def served(tmp_path: Path) -> AsyncIterator[Served]:
    s = Served(tmp_path / "moas1")
    s.start()
    yield s
    s.stop()


def make_link_to(served: Served, echo: int | None = None, **kw: object) -> tuple[SwitchLink, list]:
    statuses: list[LinkStatus] = []
    hooks = {name: kw.pop(f"on_{name}") for name in ("tr", "error") if f"on_{name}" in kw}
    timing = kw.pop("timing", FAST)
    link = SwitchLink(1, str(served.link), echo, options=LinkOptions(timing=timing),  # type: ignore[arg-type]
                      listener=Heard(status=statuses.append, **hooks),  # type: ignore[arg-type]
                      **kw)  # type: ignore[arg-type]
    return link, statuses


# --------------------------------------------------------------------------- loading and changes


@pytest.mark.asyncio
async def test_link_loads_the_box_and_then_sends_only_differences(served: Served) -> None:
    link, statuses = make_link_to(served)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        assert statuses == [LinkStatus.OK]
        await until(lambda: served.relays == {1, 2, 8})
        # the unit id, a ping behind it (any other unit's id would come before its
        # answer), then what the box holds and who transmits, then the load as values:
        # never a reset, which would open every relay at once
        assert served.received.startswith(b":;';';" + b'"B;"I;|;%0;%C')
        assert b"*0;" not in served.received
        before = len(served.received)
        written = link.apply(STATE_B)
        assert written == len(b"!1B35;")
        await until(lambda: served.relays == {5, 8})
        assert bytes(served.received[before:]).startswith(b"!1B35;")
        assert await link.ask_relays() == {5, 8}
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_apply_writes_before_returning() -> None:
    link = SwitchLink(1, "emulator", options=LinkOptions(timing=FAST))
    link.connect()
    try:
        await until(lambda: link.ready)
        assert link.emulator is not None
        link.apply(STATE_A)
        assert link.emulator.view().relays == {1, 2, 8}  # no await in between
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_transmit_and_receive_reach_the_callback(served: Served) -> None:
    events: list[tuple[int, bool]] = []
    link, _ = make_link_to(served, on_tr=lambda s, t: events.append((s, t)))
    served.box.set_tr(3, True)
    link.connect()
    try:
        # every station's state from the box status, station 3 keyed once the box is
        # active (an inactive box reports every station receiving)
        await until(lambda: (3, True) in events and (1, False) in events)
        events.clear()
        served.box.set_tr(3, False)
        served.box.set_tr(1, True)
        # Station 3 was keyed when the box was activated: it finishes its
        # activation inhibit before it can go back to receive.
        await until(lambda: sorted(events) == [(1, True), (3, False)])
    finally:
        await link.close()


# --------------------------------------------------------------------------- unit id


@pytest.mark.asyncio
async def test_a_box_with_another_unit_id_is_not_driven(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    other = Served(tmp_path / "moas2", unit_id=2)
    other.start()
    link, statuses = make_link_to(other, echo=1)
    link.apply(STATE_A)
    caplog.set_level(logging.DEBUG, "moas_gui.hw.moas2")
    link.connect()
    try:
        await until(lambda: statuses == [LinkStatus.UNRESPONSIVE])
        # However slow the machine (a question answered too late for one session, or
        # not at all, only delays this): the refusal, then two more sessions, and no
        # question answered late is ever taken as the answer of a later one
        await until(lambda: any(r.levelno == logging.ERROR for r in caplog.records)
                    or b"*0;" in other.received, timeout=30, what="the refusal")
        asked = other.received.count(b":;")
        await until(lambda: other.received.count(b":;") >= asked + 2
                    or b"*0;" in other.received, timeout=30, what="two more sessions")
        assert b"*0;" not in other.received
        assert other.relays == frozenset()
        errors = [r for r in caplog.records if r.levelno == logging.ERROR]
        assert len(errors) == 1, "the refusal is logged once, not at every retry"
        assert "unit 2" in errors[0].message and "Echo is 1" in errors[0].message
    finally:
        await link.close()
        other.stop()


@pytest.mark.asyncio
async def test_a_box_with_the_expected_unit_id_is_driven(tmp_path: Path) -> None:
    right = Served(tmp_path / "moas7", unit_id=7)
    right.start()
    link, _ = make_link_to(right, echo=7)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: right.relays == {1, 2, 8})
    finally:
        await link.close()
        right.stop()


# --------------------------------------------------------------------------- ports that go away


@pytest.mark.asyncio
async def test_a_port_that_cannot_be_opened_is_named_and_retried(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    later = Served(tmp_path / "not-yet")
    link, statuses = make_link_to(later)
    link.apply(STATE_A)
    caplog.set_level(logging.WARNING, "moas_gui.hw.moas2")
    link.connect()
    try:
        await until(lambda: statuses == [LinkStatus.UNRESPONSIVE])
        message = caplog.records[0].message
        assert "not-yet" in message and "cannot open the port" in message
        assert "No such file" in message
        later.start()
        await until(lambda: link.status is LinkStatus.OK)
        await until(lambda: later.relays == {1, 2, 8})
    finally:
        await link.close()
        later.stop()


@pytest.mark.asyncio
async def test_port_closed_and_reopened_mid_stream_ends_in_the_latest_relays(
    served: Served,
) -> None:
    link, statuses = make_link_to(served)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: served.relays == {1, 2, 8})
        await until(lambda: link.status is LinkStatus.OK)  # checked, after the relays
        served.stop()  # the pseudo-terminal vanishes, as a USB cable pulled
        await until(lambda: link.status is LinkStatus.UNRESPONSIVE)
        assert link.apply(STATE_B) == 0  # remembered, not written
        served.start()  # a new, freshly powered box at the same path
        await until(lambda: link.status is LinkStatus.OK)
        await until(lambda: served.relays == {5, 8})
        assert statuses == [LinkStatus.OK, LinkStatus.UNRESPONSIVE, LinkStatus.OK]
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_a_box_that_stops_answering_is_unresponsive_and_reloaded_when_back(
    served: Served,
) -> None:
    link, statuses = make_link_to(served, timing=PINGED)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: served.relays == {1, 2, 8})
        await until(lambda: link.status is LinkStatus.OK)  # checked, after the relays
        served.box.attach(None)  # it hears but says nothing
        await until(lambda: link.status is LinkStatus.UNRESPONSIVE)
        link.apply(STATE_B)
        served.box.model.feed(b"*0;", served.box.now())  # and it lost power meanwhile
        served.box.attach(served.endpoint.write)
        await until(lambda: link.status is LinkStatus.OK)
        await until(lambda: served.relays == {5, 8})
        assert statuses == [LinkStatus.OK, LinkStatus.UNRESPONSIVE, LinkStatus.OK]
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_a_box_reset_behind_the_links_back_is_loaded_again(
    served: Served, caplog: pytest.LogCaptureFixture
) -> None:
    link, statuses = make_link_to(served)
    link.apply(STATE_A)
    caplog.set_level(logging.WARNING, "moas_gui.hw.moas2")
    link.connect()
    try:
        await until(lambda: served.relays == {1, 2, 8})
        served.box.receive(b"*0;")  # power dipped: the box is back in power-on state
        assert served.relays == frozenset()
        await until(lambda: served.relays == {1, 2, 8})
        await until(lambda: link.status is LinkStatus.OK)  # checked, after the relays
        assert statuses == [LinkStatus.OK]
        assert any("reset or lost power" in r.message for r in caplog.records)
    finally:
        await link.close()


# --------------------------------------------------------------------------- errors


@pytest.mark.asyncio
async def test_an_error_from_the_box_names_the_command_that_caused_it(
    served: Served, caplog: pytest.LogCaptureFixture
) -> None:
    errors: list[str] = []

    def refuse_interlocks(kind: Traffic, data: bytes) -> None:
        if kind is Traffic.RECEIVED and b"~12;" in data:
            served.endpoint.write(b"?T;")

    served.box.add_listener(refuse_interlocks)
    link, _ = make_link_to(served, on_error=errors.append)
    caplog.set_level(logging.ERROR, "moas_gui.hw.moas2")
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        others = (frozenset({2}),) + (frozenset(),) * 5
        link.apply(wanted(band(1, {1}), band(2, {2}), inhibit_others=others))
        await until(lambda: bool(errors))
        assert "refused ~12;" in errors[0]
        assert "?T" in errors[0] and "itself" in errors[0]
        assert caplog.records[-1].levelno == logging.ERROR
    finally:
        await link.close()


# --------------------------------------------------------------------------- the File menu


@pytest.mark.asyncio
async def test_reset_reloads_the_box_with_the_current_state(served: Served) -> None:
    link, _ = make_link_to(served)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: served.relays == {1, 2, 8})
        served.box.receive(b"!1B9z;")  # someone meddled
        await until(lambda: served.relays == {8, 61})
        before = len(served.received)
        link.reset()
        await until(lambda: served.relays == {1, 2, 8})
        assert bytes(served.received[before:]).startswith(b"*0;")
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_save_switch_data_writes_every_status_reply_and_the_tables(
    served: Served, tmp_path: Path
) -> None:
    link, _ = make_link_to(served)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: served.relays == {1, 2, 8})
        path = await link.save_data(tmp_path / "switch1.txt")
        text = path.read_text()
        for expected in (":1000;", '"BRRRRRR', '"I;', "|00000000046;", "';     -> !;",
                         "%C00112233445566778899;", "conflict pairs", "Recent errors"):
            assert expected in text, expected
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_save_switch_data_without_a_switch_says_no_answer(tmp_path: Path) -> None:
    link = SwitchLink(4, str(tmp_path / "absent"), options=LinkOptions(timing=FAST))
    path = await link.save_data(tmp_path / "s4.txt")
    text = path.read_text()
    assert "MOAS II switch 4" in text and "no answer" in text


# --------------------------------------------------------------------------- more than one, threads


@pytest.mark.asyncio
async def test_two_switches_at_once(tmp_path: Path) -> None:
    one, two = Served(tmp_path / "a"), Served(tmp_path / "b")
    one.start()
    two.start()
    link1, _ = make_link_to(one)
    link2 = SwitchLink(2, str(two.link), options=LinkOptions(timing=FAST))
    link1.apply(STATE_A)
    link2.apply(STATE_B)
    link1.connect()
    link2.connect()
    try:
        await until(lambda: one.relays == {1, 2, 8} and two.relays == {5, 8})
    finally:
        await link1.close()
        await link2.close()
        one.stop()
        two.stop()


@pytest.mark.asyncio
async def test_the_reader_thread_works_as_well_as_add_reader(served: Served) -> None:
    link = SwitchLink(1, str(served.link), options=LinkOptions(timing=FAST),
                      transport=SerialTransport(str(served.link), use_thread=True))
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        await until(lambda: served.relays == {1, 2, 8})
        served.stop()
        await until(lambda: link.status is LinkStatus.UNRESPONSIVE)
        served.start()
        link.apply(STATE_B)
        await until(lambda: served.relays == {5, 8})
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_the_emulator_port_name_gives_an_in_process_box_to_show() -> None:
    link = SwitchLink(3, "emulator", echo=12, options=LinkOptions(timing=FAST))
    assert link.emulator is not None
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: link.emulator is not None and link.emulator.view().relays == {1, 2, 8})
        assert link.emulator.view().unit_id == 12
        # the relays are on before the link has checked the box: OK follows
        await until(lambda: link.status is LinkStatus.OK, what="the link OK")
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_a_failing_callback_is_logged_and_the_link_carries_on(
    served: Served, caplog: pytest.LogCaptureFixture
) -> None:
    def broken(station: int, transmitting: bool) -> None:
        raise RuntimeError("server bug")

    link, statuses = make_link_to(served, on_tr=broken)
    link.apply(STATE_A)
    caplog.set_level(logging.ERROR, "moas_gui.hw.moas2")
    link.connect()
    try:
        await until(lambda: served.relays == {1, 2, 8})
        served.box.set_tr(1, True)
        await until(lambda: any("callback failed" in r.getMessage() for r in caplog.records))
        served.box.set_tr(1, False)  # (a transmitting station would hold its change)
        link.apply(STATE_B)
        await until(lambda: served.relays == {5, 8})
        assert statuses == [LinkStatus.OK]
    finally:
        await link.close()


def test_the_debug_log_describes_box_messages_in_words() -> None:
    from moas_gui.hw.moas2.link import describe
    from moas_gui.hw.moas2.messages import AntennaEvent, AntennaStatus, InhibitReply, UnitIdReply

    assert describe(AntennaEvent(station=1, status=AntennaStatus.TX_FAST, antenna=3)) == \
        "antenna event: station 1, status tx fast (F), antenna 3"
    assert describe(UnitIdReply(version="100", unit=0)) == "unit id reply: version 100, unit 0"
    assert describe(InhibitReply(stations=frozenset({2, 1}))) == "inhibit reply: stations 1, 2"
    assert describe(InhibitReply(stations=frozenset())) == "inhibit reply: stations none"


@pytest.mark.asyncio
async def test_after_adopting_the_link_reconciles_to_the_engines_state_it_asks_for() -> None:
    # The box holds B under a keyed station 1; the saved state says A.  The engine takes
    # station 1's antennas (on_adopt) without calling the link back; the link asks the
    # engine for its state then (wanted) and reconciles the box to it: nothing stale
    # is sent for station 1 to land at its receive.
    model = EmulatorModel()
    model.feed(initialise(STATE_B).encode(), 0.0)
    model.set_tr(1, True, 0.0)
    box = EmulatedBox(model)
    adopted: list[tuple[dict[int, tuple[int, int, int]], frozenset[int]]] = []
    engine = {"state": STATE_A}

    def adopt(held: Mapping[int, tuple[int, int, int]], transmitting: frozenset[int]) -> None:
        adopted.append((dict(held), transmitting))
        engine["state"] = STATE_B  # what the engine decides; it does not call apply

    link = SwitchLink(1, "emulator", transport=EmulatorTransport(box),
                      options=LinkOptions(timing=FAST, held=STATE_A, seen=[
                          (1, 1, 63), (2, 2, 63)] + [(63, 63, 63)] * 4),
                      listener=Heard(adopt=adopt, wanted=lambda: engine["state"]))
    link.apply(STATE_A)  # the engine's state before it knew what the box holds
    link.connect()
    try:
        await until(lambda: link.ready, what="the link ready")
        assert adopted == [({1: (3, 3, 63)}, frozenset({1}))]
        assert link.sent == STATE_B and link.session.desired == STATE_B
        assert not model.stations[1].pending  # nothing waits for station 1's receive
        box.set_tr(1, False)
        assert await link.ask_relays() == {5, 8}
    finally:
        await link.close()
