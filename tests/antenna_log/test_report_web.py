"""``/report`` on the browser client's web server, over real sockets on 127.0.0.1: the
contest report as one HTML page with the charts' SVG and the numbers per antenna, under
the page's access policy (a token of any role where one is needed)."""

from __future__ import annotations

import asyncio
import re
import threading
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

import aiohttp
import pytest
import pytest_asyncio
from antenna_log_support import T0, MemoryJournal, charts_loaded, contest_journal
from helpers import until
from multidict import CIMultiDict

from moas_gui.antenna_log.records import JournalReader, KeySpan, Period
from moas_gui.antenna_log.report import HOUR, REPORTS
from moas_gui.net.server import ClientServer
from moas_gui.net.web import WebServer
from moas_gui.operators import OperatorBook, Role
from moas_gui.testing.fake_backend import FakeBackend

HOST = "127.0.0.1"


@pytest.fixture(scope="module", autouse=True)
def _charts_loaded() -> None:
    charts_loaded()  # matplotlib, imported here and kept out of the collector (see there)


class Site:
    def __init__(self, clients: ClientServer, web: WebServer) -> None:
        self.clients = clients
        self.web = web
        self.session = aiohttp.ClientSession()
        self.journal: JournalReader | None = contest_journal()

    @property
    def base(self) -> str:
        return f"http://{HOST}:{self.web.port}"

    async def get(self, target: str, **headers: str) -> tuple[int, str, Any]:
        async with self.session.get(self.base + target, headers=headers) as response:
            return response.status, await response.text(), response.headers

    async def close(self) -> None:
        await self.session.close()
        await self.web.close()
        await self.clients.close()


async def make_site(**options: Any) -> Site:
    backend = FakeBackend()
    clients = ClientServer(backend, host=HOST, port=0, **options)
    backend.attach(clients)
    await clients.start()
    site: Site

    def journal() -> JournalReader | None:
        return site.journal

    web = WebServer(clients, host=HOST, port=0, journal=journal)
    site = Site(clients, web)
    await web.start()
    return site


@pytest_asyncio.fixture
async def site() -> AsyncIterator[Site]:
    made = await make_site()
    yield made
    await made.close()


@pytest.fixture(scope="module")
def lan_report() -> tuple[int, str, CIMultiDict[str]]:
    """``/report`` (the whole journal) asked once from the LAN of a site open to it
    without ``require_token``: status, page and headers.  The tests that only read that
    page share it (one report drawn for them, not one each)."""
    async def ask() -> tuple[int, str, CIMultiDict[str]]:
        made = await make_site(allow=["127.0.0.0/8"])
        made.clients.local_addresses = ()  # 127.0.0.1 counts as the LAN
        try:
            status, page, headers = await made.get("/report")
            return status, page, CIMultiDict(headers)
        finally:
            await made.close()
    return asyncio.run(ask())


def cells(page: str) -> list[list[str]]:
    rows = re.findall(r"<tr>(.*?)</tr>", page)
    return [re.findall(r"<t[dh]>(.*?)</t[dh]>", row) for row in rows]


def test_the_report_page_holds_the_charts_and_the_numbers(
        lan_report: tuple[int, str, CIMultiDict[str]]) -> None:
    status, page, headers = lan_report
    assert status == 200
    assert headers["Content-Type"] == "text/html; charset=utf-8"
    assert "script-src" not in headers["Content-Security-Policy"]
    assert headers["Content-Security-Policy"].startswith("default-src 'none'")
    svgs = re.findall(r'<figure id="(\w+)"><svg[^>]*>.*?</svg></figure>', page, re.DOTALL)
    assert svgs == ["qsos", "rate", "transmit", "timeline"]
    assert "<script" not in page and " src=" not in page
    assert sorted(cells(page)[1:]) == [
        ["4-Square", "6", "6", "0", "20.0"],
        ["Dipole 20", "2", "0", "2", "5.0"],
        ["Yagi 20", "7", "0", "7", "10.0"],
    ]
    assert "2026-11-18 11:00 – 2026-11-18 13:00 UTC: 15 QSOs" in page
    assert ">Station 1 radio 2 RX</text>" in page  # the timeline's rows, as SVG text


@pytest.mark.asyncio
async def test_a_period_by_from_and_to(site: Site) -> None:
    status, page, _ = await site.get("/report?from=2026-11-18T12:00Z&to=2026-11-18T13:00Z")
    assert status == 200
    assert sorted(cells(page)[1:]) == [
        ["4-Square", "2", "2", "0", "10.0"],
        ["Dipole 20", "2", "0", "2", "5.0"],
        ["Yagi 20", "1", "0", "1", "0.0"],
    ]


@pytest.mark.asyncio
@pytest.mark.parametrize(
    ("query", "message"),
    [
        ("?hours=0", "hours=0: give a number of hours from 1 to 744"),
        ("?hours=lots", "hours=lots: give a number of hours"),
        ("?from=soon", "from/to: 'soon' is not a time"),
        ("?from=2026-11-18T13:00Z&to=2026-11-18T12:00Z", "from is not before to"),
    ],
)
async def test_a_bad_period_is_a_400_that_says_why(site: Site, query: str, message: str) -> None:
    status, text, _ = await site.get("/report" + query)
    assert status == 400
    assert message in text


@pytest.mark.asyncio
async def test_the_last_hours_of_a_live_journal(site: Site) -> None:
    site.journal = MemoryJournal()  # nothing yet
    status, page, _ = await site.get("/report?hours=3")
    assert status == 200 and "The antenna journal is empty" in page


@pytest.mark.asyncio
async def test_a_period_of_more_than_a_year_is_refused_naming_the_bounds(site: Site) -> None:
    status, text, _ = await site.get("/report?from=1000-01-01&to=3000-01-01")
    assert status == 400
    assert "the period 1000-01-01 00:00 UTC to 3000-01-01 00:00 UTC is 730,485 days" in text
    assert "a report covers at most 366 days" in text
    assert "the journal holds 2026-11-18 11:00 UTC to 2026-11-18 13:00 UTC" in text
    status, text, _ = await site.get("/report?from=1000-01-01")  # to the journal's end
    assert status == 400 and "at most 366 days" in text


@pytest.mark.asyncio
async def test_a_period_beyond_the_journal_is_clamped_to_it(site: Site) -> None:
    status, page, _ = await site.get("/report?from=2026-01-01&to=2026-11-18T13:30Z")
    assert status == 200
    assert "2026-11-18 11:00 – 2026-11-18 13:29 UTC: 15 QSOs" in page  # not from January
    rate = re.search(r'<figure id="rate">(.*?)</figure>', page, re.DOTALL)
    assert rate is not None and rate.group(1).count("<path") < 60  # three hours, not 7,800


@pytest.mark.asyncio
async def test_a_period_outside_the_journal_says_what_it_holds(site: Site) -> None:
    status, page, _ = await site.get("/report?from=2020-01-01&to=2020-02-01")
    assert status == 200 and "<svg" not in page
    assert ("Nothing was recorded from 2020-01-01 00:00 UTC to 2020-02-01 00:00 UTC: the "
            "journal holds 2026-11-18 11:00 UTC to 2026-11-18 13:00 UTC.") in page


def one_transmission() -> MemoryJournal:
    """A journal of one transmission: a whole report (four charts) for the tests that read
    no more of it than that it came, the three charts without it cheap to draw."""
    return MemoryJournal(keys=[KeySpan(1, 1, "Yagi 20", T0, T0 + 60)])


class HeldJournal(MemoryJournal):
    """A journal whose reading waits until the test lets it go (a report in the making)."""

    def __init__(self) -> None:
        super().__init__(**vars(one_transmission()))
        self.go = threading.Event()

    def extent(self) -> Period | None:
        self.go.wait(30)
        return super().extent()


@pytest.mark.asyncio
async def test_one_report_at_a_time_a_second_is_told_busy(site: Site) -> None:
    held = HeldJournal()
    site.journal = held
    first = asyncio.ensure_future(site.get("/report"))
    try:
        await until(lambda: REPORTS.busy, timeout=20, what="the first report in the making")
        status, text, headers = await site.get("/report?hours=2")
        assert status == 503 and "another contest report is being made" in text
        assert headers["Retry-After"] == "5"
        assert (await site.get("/index.html"))[0] == 200  # the loop serves meanwhile
    finally:
        held.go.set()
    status, page, _ = await first
    assert status == 200 and page.count("<svg") == 4
    await until(lambda: not REPORTS.busy, timeout=20)
    assert (await site.get("/report?hours=2"))[0] == 200


@pytest.mark.asyncio
@pytest.mark.parametrize(
    ("journal", "text"),
    [
        (None, "The antenna journal is turned off"),
        (MemoryJournal(), "The antenna journal is empty"),
    ],
)
async def test_no_journal_says_so(site: Site, journal: Any, text: str) -> None:
    site.journal = journal
    status, page, _ = await site.get("/report")
    assert status == 200 and text in page and "<svg" not in page


@pytest.mark.asyncio
async def test_where_a_token_is_needed_a_view_token_shows_the_report(tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "operators.json")
    _op, viewer = book.add("wall display", Role.VIEW)
    made = await make_site(allow=["127.0.0.0/8"], require_token=True, operators=book)
    made.clients.local_addresses = ()  # 127.0.0.1 counts as the LAN, which needs a token
    made.journal = one_transmission()
    try:
        status, text, headers = await made.get("/report")
        assert status == 401 and "needs an operator's token" in text
        assert headers["WWW-Authenticate"].startswith("Bearer")
        status, _, _ = await made.get("/report", Authorization="Bearer " + viewer[:-3] + "xyz")
        assert status == 401
        status, page, _ = await made.get("/report", Authorization=f"Bearer {viewer}")
        assert status == 429 and "try again in 1 s" in page  # that id's back-off, 1 s
        while status == 429:
            await asyncio.sleep(0.1)
            status, page, _ = await made.get("/report", Authorization=f"Bearer {viewer}")
        assert status == 200 and page.count("<svg") == 4
    finally:
        await made.close()


def test_the_page_is_open_to_the_lan_without_require_token(
        lan_report: tuple[int, str, CIMultiDict[str]]) -> None:
    status, page, _ = lan_report  # asked from the LAN, no token
    assert status == 200 and page.count("<svg") == 4


@pytest.mark.asyncio
async def test_the_period_cuts_contacts_and_transmissions_at_its_edges(site: Site) -> None:
    assert T0 % HOUR == 0  # 11:00 UTC
    status, page, _ = await site.get("/report?from=2026-11-18T11:00Z&to=2026-11-18T11:10Z")
    assert status == 200
    assert cells(page)[0] == ["Antenna", "QSOs", "20m", "Minutes transmitted"]
    assert sorted(cells(page)[1:]) == [
        # G0BB comes at 11:10, just outside; 4-Square is keyed from 11:08:20 (100 s of it)
        ["4-Square", "0", "0", "1.7"],
        ["Yagi 20", "1", "1", "5.0"],
    ]
