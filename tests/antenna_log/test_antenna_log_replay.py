"""A recorded hour, replayed: from a seed, an hour of band changes, transmissions and
logged contacts on the small station (two radios, the built-in emulator), driven through
the running server (frequencies into the engine, the box's T/R line, contact datagrams
over UDP), on a wall clock of the test's own.  Every QSO's antennas, as the journal
joins them, must be those the radio really transmitted on (what the script saw the box
confirm), and agree with the journal's own spans."""

from __future__ import annotations

import random
import socket
from collections.abc import AsyncIterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until

from moas_gui.antenna_log.journal import CLOCK_TOLERANCE, Journal
from moas_gui.antenna_log.records import Contact, Period
from moas_gui.app import ServerApp, ServerOptions
from moas_gui.engine.operations import SetFrequency
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.sources.n1mm_contact import contact_packet
from moas_gui.status import ServerState

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)
START = 1_795_000_000  # whole seconds: a logger's timestamps have no fraction
HOUR = 3600
BANDS = (7025.0, 14025.0, 21025.0, 28025.0)
RADIOS = ((1, 1), (1, 2))
SEED = 3404


class WallClock:
    def __init__(self) -> None:
        self.now = float(START)

    def __call__(self) -> float:
        return self.now


@dataclass
class Expected:
    call: str
    radio: tuple[int, int]
    tx: str
    rx: str
    arrived: float
    """When the server had its datagram (the wall clock of the test)."""


@pytest_asyncio.fixture
async def running() -> AsyncIterator[tuple[ServerApp, WallClock]]:
    clock = WallClock()
    app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                  udp_bind="127.0.0.1", start_rotator_program=False,
                                  switch_timing=FAST, antenna_log_clock=clock))
    assert (await app.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: app.status.state is ServerState.NORMAL)
    yield app, clock
    await app.close()


def names(app: ServerApp) -> dict[int, str]:
    assert app.engine is not None
    return {a.id: a.long or a.short for a in app.engine.antenna_views()}


def in_force(app: ServerApp, radio: tuple[int, int]) -> tuple[str, str]:
    assert app.engine is not None
    view = app.engine.radio_view(*radio)
    table = names(app)
    return (table.get(view.tx, "") if view.tx is not None else "",
            table.get(view.rx, "") if view.rx is not None else "")


def journal_of(app: ServerApp) -> Journal:
    journal = app.antenna_journal
    assert journal is not None
    return journal


def recorded(app: ServerApp, radio: tuple[int, int], clock: WallClock) -> tuple[str, str]:
    """The transmit and receive antennas the journal has for ``radio`` now."""
    journal = journal_of(app)
    assert journal.flush()
    spans = journal.antenna_spans(Period(clock.now, clock.now + 1))
    found = {s.role: s.antenna for s in spans if (s.station, s.radio) == radio}
    return found.get("tx", ""), found.get("rx", "")


async def band_change(app: ServerApp, clock: WallClock, radio: tuple[int, int],
                      khz: float) -> None:
    app.act(SetFrequency(*radio, khz))
    # the box confirms (the relay dwell, the emulator's answer): recorded as it lands
    await until(lambda: recorded(app, radio, clock) == in_force(app, radio), timeout=10,
                what=f"radio {radio}'s antennas at {khz} kHz in the journal")


async def transmission(app: ServerApp, clock: WallClock, radio: tuple[int, int],
                       seconds: int) -> tuple[str, str]:
    box = app.emulators()[1]
    port = radio[1]  # small-station: radio N on switch port N
    assert app.engine is not None
    antennas = in_force(app, radio)
    box.set_tr(port, True)
    await until(lambda: app.engine is not None and app.engine.radio_view(*radio).transmitting)
    clock.now += seconds
    box.set_tr(port, False)
    await until(lambda: app.engine is not None
                and not app.engine.radio_view(*radio).transmitting)
    return antennas


async def log_contact(app: ServerApp, when: float, call: str, radio: tuple[int, int],
                      khz: float) -> None:
    """The logger's datagram, over UDP; returns once the server has it (the wall clock
    stands still until then: it is stamped with the time it arrived)."""
    address, sources = app.n1mm_address, app.sources
    assert address is not None and sources is not None and sources.n1mm is not None
    listener = sources.n1mm
    before = listener.stats().contacts
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.sendto(contact_packet("contactinfo", f"q{call}", when, call, rx_khz=khz,
                                  radio_nr=radio[1], station_name="RUN-PC"), address)
    await until(lambda: listener.stats().contacts == before + 1, what=f"contact {call}")


async def the_hour(app: ServerApp, clock: WallClock) -> dict[str, Expected]:
    """The seeded hour; returns what each QSO was really made on."""
    rng = random.Random(SEED)
    expected: dict[str, Expected] = {}
    khz = dict.fromkeys(RADIOS, 0.0)
    for radio in RADIOS:
        khz[radio] = rng.choice(BANDS)
        await band_change(app, clock, radio, khz[radio])
    number = 0
    while clock.now < START + HOUR:
        clock.now += rng.randint(5, 40)
        radio = rng.choice(RADIOS)
        roll = rng.random()
        if roll < 0.15:
            khz[radio] = rng.choice([b for b in BANDS if b != khz[radio]])
            await band_change(app, clock, radio, khz[radio])
            continue
        number += 1
        call = f"T{number}X"
        if roll < 0.9:  # a QSO made on a transmission, logged a few seconds later
            tx, rx = await transmission(app, clock, radio, rng.randint(2, 9))
            clock.now += rng.randint(1, 15)
            if rng.random() < 0.3:  # and the band changes before it is logged
                khz[radio] = rng.choice([b for b in BANDS if b != khz[radio]])
                await band_change(app, clock, radio, khz[radio])
                clock.now += 1
        else:  # logged with no transmission of its radio near it: the antennas at its time
            clock.now += int(CLOCK_TOLERANCE) + 5  # past the last transmission's reach
            tx, rx = in_force(app, radio)
        # the logging computer's clock, off by up to the tolerance either way
        skew = rng.choice((0, 0, 0, -100, -30, 60, 110))
        await log_contact(app, clock.now + skew, call, radio, khz[radio])
        expected[call] = Expected(call, radio, tx, rx, clock.now)
    return expected


def agrees_with_spans(journal: Journal, qso: Contact, arrived: float) -> None:
    """The journal's own spans say the same: the radio's last transmission before the
    QSO arrived (else that moment) falls in spans of its antennas."""
    keys = [k for k in journal.key_spans(Period(arrived - 2 * CLOCK_TOLERANCE, arrived + 1))
            if (k.station, k.radio) == (qso.station, qso.radio)
            and k.start <= arrived and k.end >= arrived - CLOCK_TOLERANCE]
    at = keys[-1].start if keys else arrived
    spans = journal.antenna_spans(Period(at, at + 0.5))
    in_force = {s.role: s.antenna for s in spans if (s.station, s.radio) == (qso.station,
                                                                             qso.radio)}
    assert (qso.tx_antenna, qso.rx_antenna) == (in_force.get("tx", ""),
                                                in_force.get("rx", "")), qso
    if keys:
        assert keys[-1].antenna == qso.tx_antenna, (keys[-1], qso)


@pytest.mark.realtime  # the switch link and the box run on the loop's real clock: each of the
# hour's band changes and transmissions is waited for as the box confirms it (seconds)
@pytest.mark.asyncio
@pytest.mark.timeout(300)
async def test_every_qso_of_a_seeded_hour_gets_the_antennas_it_was_made_on(
        running: tuple[ServerApp, WallClock]) -> None:
    app, clock = running
    expected = await the_hour(app, clock)
    journal = journal_of(app)
    assert len(expected) > 60  # an hour's worth

    def all_logged() -> bool:
        assert journal.flush()
        return len(journal.contacts(Period(START - HOUR, START + 3 * HOUR))) == len(expected)
    await until(all_logged, timeout=20, what="every contact in the journal")
    qsos = journal.contacts(Period(START - HOUR, START + 3 * HOUR))
    bands_used = {q.tx_antenna for q in qsos}
    assert len(bands_used) >= 3, bands_used  # the hour moved between antennas
    for qso in qsos:
        truth = expected[qso.call]
        assert (qso.station, qso.radio) == truth.radio, qso
        assert (qso.tx_antenna, qso.rx_antenna) == (truth.tx, truth.rx), (qso, truth)
        assert qso.switch_path.startswith(f"switch 1 port {qso.radio} slot ") or not truth.tx
        agrees_with_spans(journal, qso, truth.arrived)
