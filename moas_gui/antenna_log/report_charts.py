"""The contest report drawn with matplotlib: four charts, as PNG or as one HTML page.

::

    draw_chart("qsos", figure, report)          # onto any Figure (the window's Qt canvas)
    Path("report.png").write_bytes(report_png(report))
    Path("report.html").write_text(report_html(report), encoding="utf-8")

The four charts (:data:`CHARTS`): contacts per antenna per band (stacked bars), the
rate per clock hour per antenna (steps), minutes transmitted per antenna (bars), and
each radio's antennas over time (one row per radio and role).  An antenna keeps its
colour in every chart; a band keeps its colour in every report (:data:`BAND_COLOURS`).
Counts are whole numbers on their axes; antennas at the same rate are told apart by
line style, marker and a small nudge.  The HTML page's charts are compact (legends
under them) so that they read on a phone.  Times are UTC.

Only matplotlib's object API is used (no pyplot, no display): the PNG comes from the
Agg canvas, the SVG from the SVG canvas with text kept as text, so the HTML page is
one file that needs nothing else (no script, no font, no image file).  Each figure is
drawn once: the canvas's own ``print_png``/``print_svg``, whose one draw runs the
constrained layout first, not ``savefig``, which with a layout engine draws the whole
figure a second time (without output) only to lay it out (the same bytes, about a
fifth less of the processor time).
"""

from __future__ import annotations

import errno
import html
import io
import os
import zlib
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Literal

import matplotlib.dates as mdates
import numpy
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.backends.backend_svg import FigureCanvasSVG
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator
from matplotlib.transforms import ScaledTranslation

from moas_gui import __version__
from moas_gui.files import write_atomic, write_text_atomic

from .report import ContestReport

__all__ = [
    "BAND_COLOURS",
    "CHARTS",
    "band_colour",
    "chart_figure",
    "draw_chart",
    "period_text",
    "report_figure",
    "report_html",
    "report_png",
    "report_svgs",
    "save_html",
    "save_png",
]

CHARTS: dict[str, str] = {
    "qsos": "QSOs per antenna per band",
    "rate": "Rate per hour per antenna",
    "transmit": "Transmit time per antenna",
    "timeline": "Antennas per radio",
}
"""The charts, by key, with their titles (in the order shown)."""

_ROLE_NAMES = {"tx": "TX", "rx": "RX", "alt": "Alt", "sub": "Sub RX"}


def period_text(report: ContestReport) -> str:
    """``2026-11-28 00:00 – 2026-11-29 23:59 UTC`` for the report's period."""
    start = datetime.fromtimestamp(report.period.start, UTC)
    end = datetime.fromtimestamp(report.period.end - 1, UTC)
    return f"{start:%Y-%m-%d %H:%M} – {end:%Y-%m-%d %H:%M} UTC"


def _colours(report: ContestReport) -> dict[str, tuple[float, float, float, float]]:
    names = set(report.antennas)
    for timeline in report.timelines:
        for spans in timeline.spans.values():
            names.update(span.antenna for span in spans)
    # ten strong colours first, then the paler ones (tab20's odd entries)
    palette = [colormaps["tab10"](i) for i in range(10)]
    palette += [colormaps["tab20"](2 * i + 1) for i in range(10)]
    return {name: palette[i % len(palette)] for i, name in enumerate(sorted(names))}


BAND_COLOURS: dict[str, str] = {
    "2190m": "#5b4a3f", "630m": "#7b6a5e", "560m": "#9c8b7f",
    "160m": "#8c564b", "80m": "#d62728", "60m": "#e377c2", "40m": "#ff7f0e",
    "30m": "#bcbd22", "20m": "#1f77b4", "17m": "#17becf", "15m": "#2ca02c",
    "12m": "#9467bd", "10m": "#393b79", "8m": "#ad494a", "6m": "#e7ba52",
    "5m": "#8ca252", "4m": "#637939", "2m": "#98df8a", "1.25m": "#6b6ecf",
    "70cm": "#c5b0d5", "33cm": "#f7b6d2", "23cm": "#c49c94", "13cm": "#9edae5",
    "9cm": "#dbdb8d", "6cm": "#ff9896", "3cm": "#aec7e8",
}
"""Each band's colour, the same in every report whatever other bands it has (ADIF's
band names)."""
_OTHER_BANDS = ("#7f7f7f", "#a5a5a5", "#595959", "#c7c7c7")
"""A band ADIF does not name: a grey, chosen by its name (so it too keeps it)."""


def band_colour(band: str) -> str:
    """The colour of ``band`` in every report (:data:`BAND_COLOURS`)."""
    known = BAND_COLOURS.get(band)
    if known is not None:
        return known
    return _OTHER_BANDS[zlib.crc32(band.encode("utf-8")) % len(_OTHER_BANDS)]


def _nothing(ax: Axes, text: str) -> None:
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, color="0.35")
    ax.set_xticks([])
    ax.set_yticks([])


def _when(seconds: float) -> float:
    """matplotlib's date number for POSIX seconds (the axes' unit for times)."""
    return _EPOCH + seconds / 86400.0


# matplotlib.dates has no type annotations; its date number counts days from its epoch
_EPOCH = float(mdates.date2num(datetime.fromtimestamp(0.0, UTC)))  # type: ignore[no-untyped-call]
DOTS_UP_TO = 400
"""The most hours the rate chart marks with a dot each (a longer period: lines only)."""


def _time_axis(ax: Axes) -> None:
    locator = mdates.AutoDateLocator(tz=UTC)  # type: ignore[no-untyped-call]
    ax.xaxis.set_major_locator(locator)
    formatter = mdates.ConciseDateFormatter(locator, tz=UTC)  # type: ignore[no-untyped-call]
    ax.xaxis.set_major_formatter(formatter)
    ax.set_xlabel("UTC")


def _draw_qsos(ax: Axes, report: ContestReport, compact: bool = False) -> None:
    antennas = sorted(report.qsos, key=lambda name: (-report.antenna_qsos(name), name))
    if not antennas:
        _nothing(ax, "No contacts in this period")
        return
    bottoms = [0] * len(antennas)
    for band in report.bands:
        counts = [report.qsos[name].get(band, 0) for name in antennas]
        ax.bar(antennas, counts, bottom=bottoms, label=band, color=band_colour(band))
        bottoms = [b + c for b, c in zip(bottoms, counts, strict=True)]
    for x, total in enumerate(bottoms):
        ax.annotate(str(total), (x, total), ha="center", va="bottom", fontsize="small")
    ax.set_ylabel("QSOs")
    ax.set_ylim(0, max(bottoms) * 1.15)
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))  # counts: whole numbers
    _legend(ax, compact, title="Band", outside=False)
    ax.tick_params(axis="x", labelrotation=20)


_STYLES: tuple[Literal["-", "--", "-.", ":"], ...] = ("-", "--", "-.", ":")
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")
_NUDGE_POINTS = 2.0
"""How far apart (in points, up and right) lines of equal rate are drawn."""


def _draw_rate(ax: Axes, report: ContestReport, compact: bool = False) -> None:
    if not report.rate:
        _nothing(ax, "No contacts in this period")
        return
    colours = _colours(report)
    edges = [*report.hours, report.hours[-1] + 3600.0]
    times = [_when(t) for t in edges]
    middles = [_when(t + 1800.0) for t in report.hours]
    order = sorted(report.rate, key=lambda n: (-sum(report.rate[n]), n))
    middle = (len(order) - 1) / 2
    for number, name in enumerate(order):
        counts = report.rate[name]
        # equal rates stay told apart: a line style and a marker each, and each line
        # nudged a little from the others (in points: the numbers read the same); the
        # marks only for a contest's length (a year's hours would cost their drawing)
        nudge = (number - middle) * _NUDGE_POINTS
        shifted = ax.transData + ScaledTranslation(nudge / 72, nudge / 72,
                                                   ax.figure.dpi_scale_trans)
        ax.step(times, [*counts, counts[-1]], where="post", color=colours[name], label=name,
                linestyle=_STYLES[number % len(_STYLES)], linewidth=1.8, transform=shifted)
        if len(middles) <= DOTS_UP_TO:
            ax.plot(middles, counts, linestyle="", marker=_MARKERS[number % len(_MARKERS)],
                    color=colours[name], markersize=5, transform=shifted)
    ax.set_ylabel("QSOs per hour")
    # nudged lines are not counted in the data limits: the axes get them here
    most = max(max(counts) for counts in report.rate.values())
    ax.set_xlim(times[0], times[-1])
    ax.set_ylim(0, max(most * 1.12, most + 0.5))
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))  # no half QSOs
    _time_axis(ax)
    _legend(ax, compact, handles=[
        Line2D([], [], color=colours[name], linestyle=_STYLES[i % len(_STYLES)],
               marker=_MARKERS[i % len(_MARKERS)], markersize=5, label=name)
        for i, name in enumerate(order)])


def _legend(ax: Axes, compact: bool, *, title: str | None = None,
            handles: list[Any] | None = None, outside: bool = True) -> None:
    """The legend: beside the axes, or under them on a compact (narrow) chart."""
    extra: dict[str, Any] = {"fontsize": "small", "title": title}
    if handles is not None:
        extra["handles"] = handles
    if compact:
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=3, **extra)
    elif outside:
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), **extra)
    else:
        ax.legend(**extra)


def _draw_transmit(ax: Axes, report: ContestReport, compact: bool = False) -> None:
    if not report.transmit:
        _nothing(ax, "No transmissions in this period")
        return
    colours = _colours(report)
    names = sorted(report.transmit, key=lambda n: (report.transmit[n], n))
    minutes = [report.transmit[name] / 60 for name in names]
    ax.barh(names, minutes, color=[colours[name] for name in names])
    for y, value in enumerate(minutes):
        ax.annotate(
            f"{value:.1f}",
            (value, y),
            xytext=(3, 0),
            textcoords="offset points",
            va="center",
            fontsize="small",
        )
    ax.set_xlabel("Minutes transmitted")
    ax.set_xlim(0, max(minutes) * 1.2 or 1)


def _draw_timeline(ax: Axes, report: ContestReport, compact: bool = False) -> None:
    rows = [
        (f"{timeline.label} {_ROLE_NAMES[role]}", spans)
        for timeline in report.timelines
        for role, spans in timeline.spans.items()
    ]
    if not rows:
        _nothing(ax, "No antenna in use in this period")
        return
    colours = _colours(report)
    used: dict[str, bool] = {}
    for y, (_label, spans) in enumerate(reversed(rows)):
        bars = [(_when(s.start), (s.end - s.start) / 86400.0) for s in spans]
        ax.broken_barh(bars, (y - 0.4, 0.8), facecolors=[colours[s.antenna] for s in spans])
        used.update((s.antenna, True) for s in spans)
    ax.set_yticks(range(len(rows)), [label for label, _spans in reversed(rows)])
    ax.set_xlim(_when(report.period.start), _when(report.period.end))
    _time_axis(ax)
    _legend(ax, compact, handles=[Patch(color=colours[name], label=name)
                                  for name in sorted(used)])


_DRAW: dict[str, Callable[[Axes, ContestReport, bool], None]] = {
    "qsos": _draw_qsos,
    "rate": _draw_rate,
    "transmit": _draw_transmit,
    "timeline": _draw_timeline,
}


def draw_chart(kind: str, figure: Figure, report: ContestReport,
               compact: bool = False) -> None:
    """Clears ``figure`` and draws the chart ``kind`` (a key of :data:`CHARTS`) on it;
    ``compact`` puts the legend under the chart (for a narrow screen)."""
    figure.clear()
    ax = figure.add_subplot()
    _DRAW[kind](ax, report, compact)
    ax.set_title(CHARTS[kind])
    figure.set_layout_engine("constrained")


def chart_figure(kind: str, report: ContestReport, size: tuple[float, float] = (8, 4.2),
                 compact: bool = False) -> Figure:
    """A new figure (``size`` in inches) with the chart ``kind``."""
    from matplotlib import rc_context

    figure = Figure(figsize=size)
    # a compact chart is shown small (a phone): its text is drawn larger to read there
    with rc_context({"font.size": 12.5} if compact else {}):
        draw_chart(kind, figure, report, compact)
    return figure


def report_figure(report: ContestReport, dpi: float = 100) -> Figure:
    """The four charts in one figure, two by two, titled with the period (16 by 9 inches
    of ``dpi`` pixels each)."""
    figure = Figure(figsize=(16, 9), dpi=dpi, layout="constrained")
    subs = figure.subfigures(2, 2, squeeze=False)
    assert isinstance(subs, numpy.ndarray)
    for sub, kind in zip(subs.flat, CHARTS, strict=True):
        ax = sub.add_subplot()
        _DRAW[kind](ax, report, False)
        ax.set_title(CHARTS[kind])
    figure.suptitle(f"Contest report, {period_text(report)}")
    return figure


def _folder_ready(path: Path) -> None:
    """Raises the error writing ``path`` would end in when its folder is missing (or is
    not a folder), before the report is drawn for nothing."""
    folder = path.parent
    if not folder.is_dir():
        code = errno.ENOTDIR if folder.exists() else errno.ENOENT
        raise OSError(code, os.strerror(code), str(folder))


def save_png(report: ContestReport, path: Path) -> None:
    """Writes :func:`report_png` to ``path`` (whole or not at all)."""
    _folder_ready(path)
    write_atomic(path, report_png(report))


def save_html(report: ContestReport, path: Path) -> None:
    """Writes :func:`report_html` to ``path`` (whole or not at all)."""
    _folder_ready(path)
    write_text_atomic(path, report_html(report))


def report_png(report: ContestReport, dpi: int = 100) -> bytes:
    """The four charts as one PNG image."""
    buffer = io.BytesIO()
    # one draw, the layout in it (savefig would draw twice: see the module's docstring)
    FigureCanvasAgg(report_figure(report, dpi)).print_png(buffer)  # type: ignore[no-untyped-call]
    return buffer.getvalue()


def _svg(figure: Figure) -> str:
    from matplotlib import rc_context

    buffer = io.StringIO()
    # one draw, the layout in it; the text as text: searchable, no glyph paths
    with rc_context({"svg.fonttype": "none"}):
        FigureCanvasSVG(figure).print_svg(buffer)  # type: ignore[no-untyped-call]
    text = buffer.getvalue()
    return text[text.index("<svg") :].strip()  # the element alone, for an HTML page


COMPACT_SIZE = (5.0, 4.4)
"""The page's charts, in inches: drawn narrow (legends under them) so that scaled to a
phone's width (390 px) their text still reads."""


def report_svgs(report: ContestReport) -> dict[str, str]:
    """Each chart as an ``<svg>`` element, by key (compact: they scale to a phone)."""
    return {kind: _svg(chart_figure(kind, report, COMPACT_SIZE, compact=True))
            for kind in CHARTS}


_STYLE = """
body { font-family: sans-serif; margin: 1em auto; max-width: 60em; padding: 0 1em; }
.numbers { overflow-x: auto; max-width: 100%; }
table { border-collapse: collapse; margin: 1em 0; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.6em; text-align: right; }
th:first-child, td:first-child { text-align: left; }
figure { margin: 1.5em 0; }
figure svg { width: 100%; max-width: 36em; height: auto; }
@media (max-width: 30em) {
  body { padding: 0 0.5em; }
  th, td { padding: 0.2em 0.3em; font-size: 0.9em; }
}
"""


def _table(report: ContestReport) -> str:
    bands = report.bands
    head = "".join(f"<th>{html.escape(band)}</th>" for band in bands)
    rows = []
    for name in report.antennas:
        per_band = "".join(f"<td>{report.qsos.get(name, {}).get(band, 0)}</td>" for band in bands)
        minutes = report.transmit.get(name, 0.0) / 60
        rows.append(
            f"<tr><td>{html.escape(name)}</td><td>{report.antenna_qsos(name)}</td>{per_band}"
            f"<td>{minutes:.1f}</td></tr>"
        )
    return (  # in a box of its own that scrolls sideways when a phone is too narrow
        '<div class="numbers"><table id="antennas"><thead><tr><th>Antenna</th><th>QSOs</th>'
        f"{head}<th>Minutes transmitted</th></tr></thead>"
        f"<tbody>{''.join(rows)}</tbody></table></div>"
    )


def report_html(report: ContestReport, title: str = "Contest report") -> str:
    """The report as one self-contained HTML page: the numbers as a table, the four
    charts as inline SVG."""
    figures = "".join(
        f'<figure id="{kind}">{svg}</figure>' for kind, svg in report_svgs(report).items()
    )
    summary = (
        f"{report.contacts} QSO{'s' if report.contacts != 1 else ''}"
        if not report.empty
        else "Nothing was recorded in this period."
    )
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head><body>"
        f"<h1>{html.escape(title)}</h1>"
        f'<p id="period">{html.escape(period_text(report))}: {summary}</p>'
        f"{_table(report)}{figures}"
        f"<footer><small>moas-gui {html.escape(__version__)}</small></footer>"
        "</body></html>\n"
    )
