"""``moas-server --headless`` with its antenna log, end to end: a separate process on the
built-in emulator, the loggers' datagrams over a real UDP socket (not1mm's captured ones
and N1MM Logger+'s documented ones, tests/antenna_log/fixtures), the journal read back
by another process's read-only reader while the server writes it.

The captured packets are replayed as they are but for their ``timestamp``, set to the
time of the replay (the journal knows the station only from the server's start on)."""

from __future__ import annotations

import asyncio
import contextlib
import html
import math
import re
import shutil
import socket
import sys
import time
import urllib.request
from collections.abc import AsyncIterator
from pathlib import Path

import adif_io
import pytest
import pytest_asyncio
from antenna_log_support import headless_server
from helpers import until

from moas_gui.antenna_log.journal import Journal, journal_path, open_reader
from moas_gui.antenna_log.records import Period
from moas_gui.config import load_config
from moas_gui.sources.n1mm_packet import radio_info_packet

pytestmark = [pytest.mark.realtime]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FIXTURES = Path(__file__).resolve().parent / "fixtures"
EVER = Period(0.0, 4e9)


def fixture(name: str, when: float) -> bytes:
    (path,) = FIXTURES.glob(f"{name}*.xml")
    stamp = time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(when)).encode()
    return re.sub(rb"<timestamp>[^<]*</timestamp>", b"<timestamp>" + stamp + b"</timestamp>",
                  path.read_bytes())


class Server:
    def __init__(self, process: asyncio.subprocess.Process, udp: int, config: Path,
                 web: int) -> None:
        self.process, self.udp, self.config, self.web = process, udp, config, web
        self.lines: list[str] = []

    async def report(self) -> str:
        """The browser's /report page, as this computer asks for it (no token)."""
        def fetch() -> str:
            with urllib.request.urlopen(f"http://127.0.0.1:{self.web}/report",
                                        timeout=30) as answer:
                return answer.read().decode()  # type: ignore[no-any-return]
        return await asyncio.to_thread(fetch)

    def send(self, *packets: bytes) -> None:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            for packet in packets:
                sock.sendto(packet, ("127.0.0.1", self.udp))


@pytest_asyncio.fixture
async def server(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> AsyncIterator[Server]:
    config = tmp_path / "station.moas"
    shutil.copy(EXAMPLES / "small-station.moas", config)
    async with serving(config, tmp_path, monkeypatch) as running:
        yield running


@pytest_asyncio.fixture
async def named_server(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> AsyncIterator[Server]:
    """small-station with its logger mapped by StationName, as docs/n1mm.md suggests."""
    config = tmp_path / "station.moas"
    text = (EXAMPLES / "small-station.moas").read_text(encoding="utf-8")
    listed = '"N1MMLogger": [{"Address": "127.0.0.1", "Station": 1}]'
    assert listed in text
    config.write_text(text.replace(listed, '"N1MMLogger": [{"StationName": "RUN", "Station": 1}]'),
                      encoding="utf-8")
    async with serving(config, tmp_path, monkeypatch) as running:
        yield running


@contextlib.asynccontextmanager
async def serving(config: Path, tmp_path: Path,
                  monkeypatch: pytest.MonkeyPatch) -> AsyncIterator[Server]:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))  # the reader's, the server's
    async with headless_server(config, tmp_path,
                               lambda process, udp, web: Server(process, udp, config, web)
                               ) as running:
        yield running


def names(config: Path) -> dict[int, str]:
    loaded = load_config(config).unwrap()
    return {a.id: a.long_name or a.short_name for a in loaded.antennas}


async def landed(reader: Journal, station: int, radio: int) -> str:
    """The radio's transmit antenna once the journal has its transmit and receive
    antennas and the clock is past the next whole second after they landed (a logger's
    timestamp has whole seconds: a contact stamped now then falls within both)."""
    def found() -> bool:
        spans = [s for s in reader.antenna_spans(EVER)
                 if (s.station, s.radio) == (station, radio) and s.antenna]
        return ({"tx", "rx"} <= {s.role for s in spans}
                and time.time() >= math.ceil(max(s.start for s in spans)))
    await until(found, timeout=20, what=f"radio {station}/{radio}'s antenna in the journal")
    return [s for s in reader.antenna_spans(EVER)
            if (s.station, s.radio, s.role) == (station, radio, "tx")][-1].antenna


@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_not1mm_and_n1mm_contacts_are_joined_to_the_journal(server: Server) -> None:
    server.send(radio_info_packet(1, 14025.12), radio_info_packet(2, 7025.30))
    await until(lambda: journal_path(server.config).is_file(), timeout=20)
    reader = open_reader(server.config)
    try:
        radio1 = await landed(reader, 1, 1)
        radio2 = await landed(reader, 1, 2)
        assert radio1 in names(server.config).values() and radio1 != radio2
        now = time.time()
        # not1mm: three QSOs logged, the second edited, the third deleted; every one
        # from radio 1 (not1mm's radionr), mapped by the sender's address to station 1
        server.send(*(fixture(f"not1mm-{i}-", now) for i in range(1, 6)))
        # N1MM: a QSO on radio 2, the same again from another computer, then edited
        server.send(fixture("n1mm-1-", now), fixture("n1mm-3-", now), fixture("n1mm-2-", now))

        def calls() -> list[str]:
            return [c.call for c in reader.contacts(EVER)]
        await until(lambda: sorted(calls()) == ["DL1ABC", "JA1XYW", "OH2BHX"], timeout=20,
                    what="the contacts in the journal")
        spans = reader.antenna_spans(EVER)
        for qso in reader.contacts(EVER):
            in_force = {s.role: s.antenna for s in spans
                        if (s.station, s.radio) == (qso.station, qso.radio)
                        and s.start <= qso.time < s.end}
            assert (qso.tx_antenna, qso.rx_antenna) == (in_force["tx"], in_force["rx"]), qso
            assert qso.tx_antenna == (radio1 if qso.radio == 1 else radio2), qso
            assert qso.switch_path.startswith(f"switch 1 port {qso.radio} slot "), qso
        (oh2bh,) = [c for c in reader.contacts(EVER) if c.call == "OH2BHX"]
        assert (oh2bh.station, oh2bh.radio, oh2bh.operator, oh2bh.rx_khz) == (1, 2, "N1OP",
                                                                           7025.30)
        server.send(fixture("n1mm-4-", now))  # N1MM deletes it
        await until(lambda: sorted(calls()) == ["DL1ABC", "JA1XYW"], timeout=20)
        # moas-server --adif reads the journal the running server writes (WAL), and a
        # real ADIF library reads the file back with each QSO's antennas
        out = server.config.parent / "contest.adi"
        export = await asyncio.create_subprocess_exec(
            sys.executable, "-m", "moas_gui.cli.server", "--antenna-log", str(server.config),
            "--adif", str(out), stderr=asyncio.subprocess.PIPE)
        _, said = await asyncio.wait_for(export.communicate(), 60)
        assert export.returncode == 0, said.decode()
        qsos, _ = adif_io.read_from_file(str(out))
        by_call = {q["CALL"]: q for q in qsos}
        assert sorted(by_call) == ["DL1ABC", "JA1XYW"]
        for qso in reader.contacts(EVER):
            assert by_call[qso.call]["MY_ANTENNA"] == qso.tx_antenna
            assert by_call[qso.call]["APP_MOAS_RXANT"] == qso.rx_antenna
        # the browser's contest report reads the running server's journal
        page = await server.report()
        assert "<svg" in page and html.escape(radio1) in page, page[:2000]
        assert "2 QSOs" in page, page[:2000]
    finally:
        reader.close()


@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_not1mm_contacts_named_for_their_host_find_the_station_of_their_radio_info(
        named_server: Server) -> None:
    """not1mm's real shapes: RadioInfo with its configured station name (RUN, in the
    file), contacts with its computer's host name (NOT1MM-PC, in no entry): both QSOs
    get the antennas of the station the sender's RadioInfo maps to."""
    server = named_server
    server.send(radio_info_packet(1, 14025.12, station_name="RUN", app="NOT1MM"))
    await until(lambda: journal_path(server.config).is_file(), timeout=20)
    reader = open_reader(server.config)
    try:
        radio1 = await landed(reader, 1, 1)
        now = time.time()
        server.send(fixture("not1mm-1-", now), fixture("not1mm-2-", now))
        await until(lambda: sorted(c.call for c in reader.contacts(EVER))
                    == ["DL1ABC", "JA1XYZ"], timeout=20, what="both QSOs in the journal")
        for qso in reader.contacts(EVER):
            assert (qso.station, qso.radio, qso.tx_antenna) == (1, 1, radio1), qso
    finally:
        reader.close()
