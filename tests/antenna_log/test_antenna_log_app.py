"""The antenna log in the running server (in process, the built-in emulator): what the
box confirmed is recorded when it lands, key events from the switch's T/R line, settled
headings, the loggers' contacts over a real UDP socket, and the switch to turn it off."""

from __future__ import annotations

import socket
import time
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until

from moas_gui.antenna_log.journal import journal_path
from moas_gui.antenna_log.records import Period
from moas_gui.app import ServerApp, ServerOptions
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.hw.rotators.base import Timing
from moas_gui.sources.n1mm_contact import contact_packet
from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.status import ServerState

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SMALL = EXAMPLES / "small-station.moas"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)
QUICK = Timing(test_speed=400.0, test_tick=0.02)
EVER = Period(0.0, 4e9)


def options(**more: object) -> ServerOptions:
    return ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0, udp_bind="127.0.0.1",
                         start_rotator_program=False, switch_timing=FAST,
                         rotator_timing=QUICK, **more)  # type: ignore[arg-type]


@pytest_asyncio.fixture
async def app() -> AsyncIterator[ServerApp]:
    server = ServerApp(options())
    yield server
    await server.close()


def send(app: ServerApp, *packets: bytes) -> None:
    address = app.n1mm_address
    assert address is not None
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        for packet in packets:
            udp.sendto(packet, address)


def tx_spans(app: ServerApp) -> list[tuple[int, int, str]]:
    journal = app.antenna_journal
    assert journal is not None and journal.flush()
    return [(s.station, s.radio, s.antenna) for s in journal.antenna_spans(EVER)
            if s.role == "tx"]


def name_of(app: ServerApp, antenna: int | None) -> str:
    assert app.engine is not None and antenna is not None
    (view,) = [a for a in app.engine.antenna_views() if a.id == antenna]
    return view.long or view.short


async def opened(app: ServerApp) -> None:
    assert (await app.open(SMALL)).ok
    await until(lambda: app.status.state is ServerState.NORMAL)


@pytest.mark.asyncio
async def test_a_band_change_is_recorded_when_the_box_confirms_it(app: ServerApp) -> None:
    await opened(app)
    journal = app.antenna_journal
    assert journal is not None and journal.path == journal_path(SMALL)
    before = time.time()
    send(app, radio_info_packet(1, 14025.0))
    await until(lambda: app.engine is not None and app.engine.radio_view(1, 1).tx is not None)
    tribander = name_of(app, app.engine.radio_view(1, 1).tx)  # type: ignore[union-attr]
    await until(lambda: (1, 1, tribander) in tx_spans(app))
    (span,) = [s for s in journal.antenna_spans(EVER) if s.role == "tx" and s.radio == 1
               and s.antenna == tribander]
    assert span.start >= before  # timed when it landed, not when the config opened
    send(app, radio_info_packet(1, 7025.0))
    await until(lambda: app.engine.radio_view(1, 1).tx != app.engine.radio_view(1, 1).rx  # type: ignore[union-attr]
                or name_of(app, app.engine.radio_view(1, 1).tx) != tribander)  # type: ignore[union-attr]
    dipole = name_of(app, app.engine.radio_view(1, 1).tx)  # type: ignore[union-attr]
    await until(lambda: [a for s, r, a in tx_spans(app) if (s, r) == (1, 1)][-1:] == [dipole])
    # one row per change: a repeated RadioInfo heartbeat records nothing more
    send(app, radio_info_packet(1, 7025.0), radio_info_packet(1, 7026.0))
    assert journal.flush()
    changes = [s for s in journal.antenna_spans(EVER) if s.role == "tx" and s.radio == 1]
    assert [s.antenna for s in changes][-2:] == [tribander, dipole]


@pytest.mark.asyncio
async def test_key_events_from_the_switch_and_a_contact_joined_to_them(app: ServerApp) -> None:
    await opened(app)
    send(app, radio_info_packet(1, 14025.0))
    await until(lambda: app.engine is not None and app.engine.radio_view(1, 1).tx is not None)
    tribander = name_of(app, app.engine.radio_view(1, 1).tx)  # type: ignore[union-attr]
    await until(lambda: (1, 1, tribander) in tx_spans(app))
    box = app.emulators()[1]
    box.set_tr(1, True)
    await until(lambda: app.engine.radio_view(1, 1).transmitting)  # type: ignore[union-attr]
    box.set_tr(1, False)
    await until(lambda: not app.engine.radio_view(1, 1).transmitting)  # type: ignore[union-attr]
    journal = app.antenna_journal
    assert journal is not None and journal.flush()
    (key,) = journal.key_spans(EVER)
    assert (key.station, key.radio, key.antenna) == (1, 1, tribander) and key.end > key.start
    # the band changes after the QSO; the contact is logged later still
    send(app, radio_info_packet(1, 7025.0))
    await until(lambda: name_of(app, app.engine.radio_view(1, 1).tx) != tribander)  # type: ignore[union-attr]
    logged = contact_packet("contactinfo", "0123abcd", time.time(), "DL1ABC",
                            rx_khz=14025.0, station_name="ANY-PC")
    send(app, logged, logged)  # twice, as "All Computers" repeats it
    await until(lambda: journal.flush() and len(journal.contacts(EVER)) == 1)
    (qso,) = journal.contacts(EVER)
    assert (qso.station, qso.radio, qso.call, qso.tx_antenna) == (1, 1, "DL1ABC", tribander)
    assert qso.switch_path.startswith("switch 1 port 1 slot ")
    send(app, contact_packet("contactdelete", "0123abcd", time.time(), "DL1ABC"))
    await until(lambda: journal.flush() and journal.contacts(EVER) == [])


@pytest.mark.asyncio
async def test_a_settled_heading_is_recorded_once(app: ServerApp) -> None:
    await opened(app)
    manager = app.rotator_manager
    assert manager is not None
    await until(lambda: manager.view(1).heading is not None)
    journal = app.antenna_journal
    assert journal is not None
    manager.start_rotate(1, 90.0)
    await until(lambda: manager.view(1).heading == 90 and not manager.view(1).moving)
    await until(lambda: journal.flush() and [m.heading for m in journal.headings(EVER)][-1:]
                == [90.0])
    marks = journal.headings(EVER)
    assert all(m.rotator == "Tribander" for m in marks)
    # nothing between: the turn's intermediate headings are not settled ones
    assert len(marks) <= 2
    assert journal.flush()


@pytest.mark.asyncio
async def test_no_antenna_log_writes_nothing_and_it_turns_on_at_run_time(tmp_path: Path) -> None:
    app = ServerApp(options(antenna_log=False))
    try:
        await opened(app)
        assert app.antenna_journal is None and not app.antenna_log_on
        assert not journal_path(SMALL).exists()
        send(app, radio_info_packet(1, 14025.0))
        await until(lambda: app.engine is not None and app.engine.radio_view(1, 1).tx is not None)
        await app.set_antenna_log(True)
        journal = app.antenna_journal
        assert journal is not None and journal_path(SMALL).is_file()
        # what the box holds when it is turned on is recorded at once
        tribander = name_of(app, app.engine.radio_view(1, 1).tx)  # type: ignore[union-attr]
        await until(lambda: (1, 1, tribander) in tx_spans(app))
        await app.set_antenna_log(False)
        assert app.antenna_journal is None
    finally:
        await app.close()


@pytest.mark.asyncio
async def test_stop_switches_leaves_no_antenna_in_force_until_start(app: ServerApp) -> None:
    await opened(app)
    send(app, radio_info_packet(1, 14025.0))
    await until(lambda: app.engine is not None and app.engine.radio_view(1, 1).tx is not None)
    tribander = name_of(app, app.engine.radio_view(1, 1).tx)  # type: ignore[union-attr]
    await until(lambda: (1, 1, tribander) in tx_spans(app))

    def last_tx() -> str:
        return [a for s, r, a in tx_spans(app) if (s, r) == (1, 1)][-1]
    app.stop_switches()
    assert last_tx() == ""
    journal = app.antenna_journal
    assert journal is not None
    before = [s for s in journal.antenna_spans(EVER) if (s.radio, s.role) == (1, "tx")]
    assert [s.antenna for s in before][-2:] == [tribander, ""]
    app.start_switches()
    await until(lambda: last_tx() == tribander)
    after = [s for s in journal.antenna_spans(EVER) if (s.radio, s.role) == (1, "tx")]
    assert after[-2].antenna == "" and after[-2].end == after[-1].start  # the stop's span


@pytest.mark.asyncio
async def test_a_journal_that_cannot_be_opened_leaves_the_server_running(
        app: ServerApp, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        caplog: pytest.LogCaptureFixture) -> None:
    blocker = tmp_path / "not-a-directory"
    blocker.write_text("a file where the data directory would be")
    monkeypatch.setenv("XDG_DATA_HOME", str(blocker))
    await opened(app)
    assert app.antenna_journal is None
    assert "cannot be opened" in caplog.text and "runs without it" in caplog.text
    send(app, radio_info_packet(1, 14025.0))  # the station works as ever
    await until(lambda: app.engine is not None and app.engine.radio_view(1, 1).tx is not None)
