"""The attacks of issue 38 on the contest report and the antenna journal, against a real
``moas-server --headless`` process: a view of the whole history
(``/report?from=1000-01-01&to=3000-01-01``), and a contact dated 9999 followed by a plain
``/report``.  Each is answered at once, with an error naming the bounds or with a report
clamped to the journal; the journal keeps no contact its retention could not expire (one
an earlier version let in is removed when the journal opens); and the server obeys
SIGTERM while reports are being made."""

from __future__ import annotations

import asyncio
import shutil
import signal
import socket
import sqlite3
import time
import urllib.error
import urllib.request
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from antenna_log_support import headless_server
from helpers import until

from moas_gui.antenna_log.journal import Journal, journal_path, open_reader
from moas_gui.antenna_log.records import Period
from moas_gui.sources.n1mm_contact import contact_packet

pytestmark = [pytest.mark.realtime]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAR = 253_402_214_400.0
"""9999-12-31 00:00 UTC."""


class Server:
    def __init__(self, process: asyncio.subprocess.Process, udp: int, web: int,
                 config: Path) -> None:
        self.process, self.udp, self.web, self.config = process, udp, web, config
        self.lines: list[str] = []

    async def get(self, target: str) -> tuple[int, str]:
        """A page of the browser's web server, as this computer asks for it (no token)."""
        def fetch() -> tuple[int, str]:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{self.web}{target}",
                                            timeout=30) as answer:
                    return answer.status, answer.read().decode()
            except urllib.error.HTTPError as error:
                return error.code, error.read().decode()
        return await asyncio.to_thread(fetch)

    def send(self, *packets: bytes) -> None:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            for packet in packets:
                sock.sendto(packet, ("127.0.0.1", self.udp))


def seed(path: Path, now: float) -> None:
    """A journal as an earlier version could leave it: a month of a busy station, and a
    contact dated 9999 (which it took and never expired)."""
    journal = Journal(path, clock=lambda: now)
    for i in range(30_000):
        at = now - 29 * 86400 + i * 80
        journal.keyed(1, 1 + i % 2, i % 4 < 2, at=at)
        if i % 10 == 0:
            journal.antenna(1, 1 + i % 2, "tx", f"Antenna {i % 7}", at=at)
        if i % 5_000 == 0:
            assert journal.flush(60)
    journal.close()
    db = sqlite3.connect(path)
    db.execute("INSERT INTO contacts VALUES ('f9999', ?, 'ZZ9ZZ', '14', 'CW', 1, 1, '', '', "
               "NULL, NULL, 0, '', 1, ?)", (FAR, now))
    db.commit()
    db.close()


@pytest_asyncio.fixture
async def server(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> AsyncIterator[Server]:
    config = tmp_path / "station.moas"
    shutil.copy(EXAMPLES / "small-station.moas", config)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))  # the reader's, the server's
    seed(journal_path(config), time.time())
    async with headless_server(config, tmp_path,
                               lambda process, udp, web: Server(process, udp, web, config)
                               ) as running:
        yield running


def contact_dated(contact_id: str, when: str) -> bytes:
    return contact_packet("contactinfo", contact_id, 0.0, "DL1ABC").replace(
        b"1970-01-01 00:00:00", when.encode())


@pytest.mark.asyncio
@pytest.mark.timeout(180)
async def test_the_report_attacks_are_answered_at_once_and_sigterm_obeyed(
        server: Server) -> None:
    # the whole history asked for: refused, naming the bounds
    status, text = await server.get("/report?from=1000-01-01&to=3000-01-01")
    assert status == 400, text
    assert "the period 1000-01-01 00:00 UTC to 3000-01-01 00:00 UTC" in text
    assert "a report covers at most 366 days; the journal holds " in text
    # one datagram dated 9999 (and one of 1999): refused; a contact of now is kept
    now = time.time()
    server.send(contact_dated("a9999", "9999-12-31 23:59:59"),
                contact_dated("a1999", "1999-12-31 23:59:59"),
                contact_packet("contactinfo", "anow", now, "OH2BH"))
    reader = open_reader(server.config)
    try:
        everything = Period(0.0, 4e11)
        await until(lambda: [c.contact_id for c in reader.contacts(everything)] == ["anow"],
                    timeout=20, what="the contact of now alone in the journal")
        extent = reader.extent()
        assert extent is not None and extent.end < now + 86400  # the 9999 row went at open
        assert extent.start >= now - 31 * 86400
    finally:
        reader.close()
    # and the plain report afterwards: the journal's month, not eight thousand years
    status, page = await server.get("/report")
    assert status == 200 and page.count("<svg") == 4, page[:500]
    assert "1 QSO" in page
    # several reports at once: each made in turn or told busy; SIGTERM obeyed meanwhile
    asked = [asyncio.ensure_future(server.get(f"/report?hours={h}")) for h in (700, 600, 500)]
    await asyncio.sleep(0.2)
    server.process.send_signal(signal.SIGTERM)
    assert await asyncio.wait_for(server.process.wait(), 15) == 0, "".join(server.lines)
    answers = await asyncio.gather(*asked, return_exceptions=True)
    for answer in answers:  # answered before the stop, or cut by it
        assert not isinstance(answer, tuple) or answer[0] in (200, 503), answer
    assert any("Stopping" in line for line in server.lines)
