"""The contest report's charts (matplotlib, no display): one PNG, and one self-contained
HTML page with the charts as inline SVG and the numbers as a table.

matplotlib (and the charts module, which loads it) is imported in the tests, not at the
top: collecting the suite loads every test module in every worker, and matplotlib costs
about 0.4 s of processor time to load."""

from __future__ import annotations

import io
import re
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from typing import TYPE_CHECKING

import pytest
from antenna_log_support import T0, MemoryJournal, charts_loaded, contest_journal

from moas_gui.antenna_log.records import KeySpan, Period
from moas_gui.antenna_log.report import HOUR, contest_report

if TYPE_CHECKING:
    from matplotlib.figure import Figure

SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module", autouse=True)
def _charts_loaded() -> None:
    charts_loaded()  # matplotlib, imported here and kept out of the collector (see there)


@pytest.fixture(scope="module")
def report():
    return contest_report(contest_journal(), Period(T0, T0 + 2 * HOUR))


@pytest.fixture(scope="module")
def page(report) -> str:
    from moas_gui.antenna_log.report_charts import report_html

    return report_html(report)


class Page(HTMLParser):
    """The tags, attributes and table cells of a page."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict[str, str | None]]] = []
        self.rows: list[list[str]] = []
        self._cell: list[str] | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append((tag, dict(attrs)))
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th") and self._cell is not None:
            self.rows[-1].append("".join(self._cell))
            self._cell = None

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)


def parsed(text: str) -> Page:
    page = Page()
    page.feed(text)
    return page


def svg_texts(svg: str) -> list[str]:
    root = ET.fromstring(svg)
    return ["".join(node.itertext()) for node in root.iter(f"{SVG}text")]


def test_the_png_holds_the_four_charts(report) -> None:
    from matplotlib.image import imread

    from moas_gui.antenna_log.report_charts import report_png

    data = report_png(report)
    assert data.startswith(b"\x89PNG\r\n\x1a\n")
    image = imread(io.BytesIO(data))
    assert image.shape[:2] == (900, 1600)
    # drawn, not blank: the antennas' colours are there (tab10's blue, 4-Square's)
    colours = {
        tuple(round(float(v), 2) for v in pixel[:3])
        for pixel in image[::7, ::7].reshape(-1, image.shape[2])
    }
    assert len(colours) > 20
    assert (0.12, 0.47, 0.71) in colours


def test_the_page_needs_no_other_file(page: str) -> None:
    tags = parsed(page).tags
    names = [tag for tag, _ in tags]
    assert "script" not in names and "link" not in names and "img" not in names
    for _tag, attrs in tags:
        for name in ("src", "href"):
            assert not attrs.get(name), f"{name}={attrs.get(name)} refers elsewhere"
    assert "url(http" not in page and "@import" not in page


def test_the_page_holds_each_chart_as_svg_with_its_text(page: str, report) -> None:
    from moas_gui.antenna_log.report_charts import CHARTS

    figures = re.findall(r'<figure id="(\w+)">(<svg.*?</svg>)</figure>', page, re.DOTALL)
    assert [kind for kind, _ in figures] == list(CHARTS)
    texts = {kind: svg_texts(svg) for kind, svg in figures}  # each one well-formed XML
    for kind, title in CHARTS.items():
        assert title in texts[kind]
    assert {"Yagi 20", "Dipole 20", "4-Square"} <= set(texts["qsos"])
    assert {"20m", "40m", "7", "6", "2"} <= set(texts["qsos"])
    assert {"20.0", "10.0", "5.0"} <= set(texts["transmit"])
    assert {"Station 1 radio 1 TX", "Station 1 radio 2 RX", "Bev NE"} <= set(texts["timeline"])
    assert "QSOs per hour" in texts["rate"]


def test_the_page_gives_the_numbers_per_antenna(page: str, report) -> None:
    from moas_gui.antenna_log.report_charts import period_text

    rows = parsed(page).rows
    assert rows[0] == ["Antenna", "QSOs", "40m", "20m", "Minutes transmitted"]
    assert sorted(rows[1:]) == [
        ["4-Square", "6", "6", "0", "20.0"],
        ["Dipole 20", "2", "0", "2", "5.0"],
        ["Yagi 20", "7", "0", "7", "10.0"],
    ]
    assert f"{period_text(report)}: 15 QSOs" in page


def figures(page: str) -> dict[str, str]:
    """The page's charts (its ``report_svgs``), by key."""
    return dict(re.findall(r'<figure id="(\w+)">(<svg.*?</svg>)</figure>', page, re.DOTALL))


def test_the_charts_of_an_empty_period_say_so() -> None:
    from moas_gui.antenna_log.report_charts import CHARTS, report_html

    empty = contest_report(contest_journal(), Period(T0 - 2 * HOUR, T0 - HOUR))
    page = report_html(empty)  # the charts rendered once: read off the page
    svgs = figures(page)
    assert list(svgs) == list(CHARTS)
    assert "No contacts in this period" in svg_texts(svgs["qsos"])
    assert "No contacts in this period" in svg_texts(svgs["rate"])
    assert "No transmissions in this period" in svg_texts(svgs["transmit"])
    assert "No antenna in use in this period" in svg_texts(svgs["timeline"])
    assert "Nothing was recorded in this period." in page
    assert parsed(page).rows == [["Antenna", "QSOs", "Minutes transmitted"]]


def test_names_are_escaped_in_the_page() -> None:
    from moas_gui.antenna_log.report_charts import report_html

    # the name where the contest journal's first transmission has its antenna's, alone:
    # the charts without it draw only their "nothing in this period"
    journal = MemoryJournal(keys=[KeySpan(1, 1, "<b>Yagi</b> & Co", T0, T0 + 60)])
    page = report_html(contest_report(journal, Period(T0, T0 + 2 * HOUR)))
    assert "<b>Yagi" not in page
    assert "<td>&lt;b&gt;Yagi&lt;/b&gt; &amp; Co</td>" in page  # the table
    assert "<b>Yagi</b> & Co" in svg_texts(figures(page)["transmit"])  # the chart, as text


def test_a_chart_redraws_on_the_same_figure(report) -> None:
    from matplotlib.figure import Figure

    from moas_gui.antenna_log.report_charts import CHARTS, draw_chart

    figure = Figure()
    for kind in CHARTS:
        draw_chart(kind, figure, report)
        assert len(figure.axes) == 1
        assert figure.axes[0].get_title() == CHARTS[kind]


def test_the_period_in_words(report) -> None:
    from moas_gui.antenna_log.report_charts import period_text

    assert period_text(report) == "2026-11-18 11:00 – 2026-11-18 12:59 UTC"


def _made(qsos: dict[str, dict[str, int]], rate: dict[str, list[int]]):
    from moas_gui.antenna_log.report import ContestReport

    return ContestReport(period=Period(T0, T0 + 2 * HOUR), contacts=sum(map(sum, rate.values())),
                         qsos=qsos, hours=[T0, T0 + HOUR], rate=rate, transmit={})


def _bar_colours(figure: Figure) -> dict[str, tuple[float, ...]]:
    """Each band's bar colour, by the legend's label."""
    ax = figure.axes[0]
    return {str(label): tuple(container.patches[0].get_facecolor())
            for container, label in zip(ax.containers, [t.get_text() for t in
                                                        ax.get_legend().get_texts()],
                                        strict=True)}


def test_a_band_keeps_its_colour_in_every_report() -> None:
    from moas_gui.antenna_log.report_charts import band_colour, chart_figure

    alone = _bar_colours(chart_figure("qsos", _made({"Yagi": {"20m": 3}}, {"Yagi": [3, 0]})))
    both = _bar_colours(chart_figure("qsos", _made({"Yagi": {"20m": 3}, "Dipole": {"80m": 2}},
                                                   {"Yagi": [3, 0], "Dipole": [0, 2]})))
    assert alone["20m"] == both["20m"] != both["80m"]
    assert band_colour("20m") == band_colour("20m") and band_colour("odd") == band_colour("odd")


def test_counts_are_whole_numbers_on_their_axes() -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from moas_gui.antenna_log.report_charts import chart_figure

    few = _made({"Yagi": {"20m": 1}, "Dipole": {"20m": 1}}, {"Yagi": [1, 0], "Dipole": [1, 0]})
    for kind in ("qsos", "rate"):
        figure = chart_figure(kind, few)
        FigureCanvasAgg(figure).draw()
        ticks = [t for t in figure.axes[0].get_yticks()
                 if figure.axes[0].get_ylim()[0] <= t <= figure.axes[0].get_ylim()[1]]
        assert ticks and all(float(t).is_integer() for t in ticks), (kind, ticks)


def test_antennas_at_the_same_rate_draw_lines_told_apart() -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from moas_gui.antenna_log.report_charts import chart_figure

    same = _made({"Yagi": {"20m": 5}, "Dipole": {"20m": 5}}, {"Yagi": [3, 2], "Dipole": [3, 2]})
    figure = chart_figure("rate", same)
    FigureCanvasAgg(figure).draw()
    steps = [line for line in figure.axes[0].get_lines() if line.get_linestyle() != "None"]
    dots = [line for line in figure.axes[0].get_lines() if line.get_linestyle() == "None"]
    assert len(steps) == 2 and len(dots) == 2
    assert steps[0].get_linestyle() != steps[1].get_linestyle()
    assert dots[0].get_marker() != dots[1].get_marker()
    drawn = [line.get_transform().transform(line.get_xydata()) for line in steps]
    assert (drawn[0] != drawn[1]).all()  # not on top of each other on the screen
    assert list(steps[0].get_ydata()) == list(steps[1].get_ydata())  # the same numbers
