"""Why, where people look: the built-in client's display line tooltip and its "Why?" action,
the client model reading ``why``, and View > Station plan in the server window (a real
server on the example file, its built-in switch, a real client connection)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from client_support import run_on_qt
from helpers import until
from test_server_window import EXAMPLES, Harness

from moas_gui.client.model import ProtocolError, WhyView, explain, parse_radio
from moas_gui.status import ServerState
from moas_gui.ui.plan_window import COLUMNS
from moas_gui.ui.qt import QApplication


@pytest.fixture
def harness(tmp_path: Path) -> Harness:
    return Harness(tmp_path)


def test_the_client_model_reads_why_and_words_it() -> None:
    radio = parse_radio({"station": 1, "radio": 2, "tx": 3, "rx": 3,
                         "why": {"rule": "f4_lowest", "text": "lowest-numbered antenna "
                                 "covering 7025 kHz",
                                 "passed_over": [{"antenna": 0, "reason": "does not cover "
                                                  "7025 kHz"}]}})
    assert radio.why == WhyView("f4_lowest", "lowest-numbered antenna covering 7025 kHz",
                                ((0, "does not cover 7025 kHz"),))
    assert explain(radio, None) == ("Lowest-numbered antenna covering 7025 kHz\n"
                                    "  Antenna 0: does not cover 7025 kHz")
    assert parse_radio({"station": 1, "radio": 1}).why is None   # an older server
    with pytest.raises(ProtocolError, match="passed_over"):
        parse_radio({"station": 1, "radio": 1, "why": {"rule": "x", "text": "y",
                                                        "passed_over": 3}})


def test_the_client_shows_why_on_the_display_line_and_by_its_why_action(
        qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        app = harness.app
        assert app is not None
        await until(lambda: app.status.state is ServerState.NORMAL)
        window.action_client.trigger()
        (client,) = window.client_windows
        await until(lambda: client.snapshot is not None, timeout=10)
        app.apply_changes(app.engine.set_frequency(1, 1, 7025))
        await until(lambda: "covering 7025 kHz" in client.display.toolTip(),
                    what="the reason on the display line")
        tip = client.display.toolTip()
        assert "Lowest-numbered antenna covering 7025 kHz" in tip
        # an antenna that merely does not cover the frequency decides nothing: it is
        # left out of what the operator reads (it stays in the Debug log)
        assert "does not cover" not in tip
        client.grid.why_asked.emit(None)  # a right-click between buttons
        menu = QApplication.activePopupWidget()
        assert menu is not None and [a.text() for a in menu.actions()] == ["Why?"]
        menu.actions()[0].trigger()
        menu.close()
        assert "Lowest-numbered antenna covering 7025 kHz" in client.status_text()
        assert client.status_text().startswith("\u2139 ")
        assert any("40 m dipole (also 15 m) \u2014 lowest-numbered antenna covering 7025 kHz"
                   in line for line in window.log_view.shown_lines())
        client.close()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_view_station_plan_shows_the_plan_filtered_by_radio_and_band(
        qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        assert not window.action_plan.isEnabled()          # nothing open yet
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        app = harness.app
        assert app is not None
        await until(lambda: app.status.state is ServerState.NORMAL)
        box = app.emulators()[1]
        relays_before = box.view().relays
        window.action_plan.trigger()
        await window.idle()
        plan_window = window.plan_window
        assert plan_window is not None and plan_window.isVisible()
        plan = plan_window.plan
        # each radio alone at each frequency, and of the pair only what differs
        notes = [n for a, b, _m, s in plan.pairs for n in plan.pair_notes(a, b, s)]
        assert plan_window.table.rowCount() == len(plan.alone) + len(notes)
        assert len(notes) < sum(len(s) for _a, _b, _m, s in plan.pairs)
        assert plan_window.findings.rowCount() == len(plan.findings) > 0
        assert "Rule" not in COLUMNS
        band = plan_window.band_filter.findData("40 m")
        plan_window.band_filter.setCurrentIndex(band)
        rows = plan_window.visible_rows()
        assert rows and all("40 m" in row[1] or row[1] == "all" for row in rows)
        radio = next(i for i in range(plan_window.radio_filter.count())
                     if plan_window.radio_filter.itemText(i) == "Station 1 radio 2")
        plan_window.radio_filter.setCurrentIndex(radio)
        alone = [row for row in plan_window.visible_rows() if row[0] == "alone"]
        assert alone == [("alone", "40 m", khz, "Station 1 radio 2", "40 m dipole (also 15 m)",
                          "40 m dipole (also 15 m)",
                          f"lowest-numbered antenna covering {khz} kHz", "")
                         for khz in ("7025", "7200")]
        pair = [row for row in plan_window.visible_rows() if row[0] == "both on 40 m, with "
                "station 1 radio 1"]
        assert pair == [("both on 40 m, with station 1 radio 1", "40 m", "", "Station 1 radio 2",
                         "All-band vertical", "All-band vertical",
                         ("lowest-numbered antenna covering its frequency (alone: 40 m dipole "
                          "(also 15 m))"), "")]
        codes = {o.rule for o in plan.alone} | {f.kind for f in plan.findings}
        for table in (plan_window.table, plan_window.findings):
            texts = [table.item(r, c).text() for r in range(table.rowCount())
                     for c in range(table.columnCount()) if table.item(r, c) is not None]
            assert not [t for t in texts if any(code in t for code in codes)]
        assert box.view().relays == relays_before            # the switch was not touched
        assert app.engine.radio_view(1, 2).khz is None
        plan_window.close()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_the_plan_window_names_what_it_does_not_plan_and_fits_its_screen(qapp: Any) -> None:
    """An 80 m dipole cut for CW: the window says 3800 kHz phone is not planned; the window
    opens within the screen (tests/ui/test_screen_fit.py runs it at 1024x600)."""
    from moas_gui.config import parse_config
    from moas_gui.plan import build_plan
    from moas_gui.ui.plan_window import PlanWindow
    from moas_gui.ui.qt import QLabel

    def ant(ident: int, name: str, low: int, high: int) -> dict[str, Any]:
        return {"ID": ident, "ShortName": name, "LongName": name, "Conflicts": [ident],
                "Control": [{"LowerFrequency": low, "UpperFrequency": high,
                             "Stations": [{"Station": 1, "Radio": 1, "Relays": [ident]}]}]}

    text = json.dumps({"Antennas": [ant(0, "Tribander", 14000, 14350),
                                    ant(1, "CW dipole", 3500, 3600)],
                       "Radios": [{"Station": 1, "Radio": 1, "Switches": [{"Port": 1}]}],
                       "Switches": [{"ID": 1, "Port": "emulator"}]})
    plan = build_plan(parse_config(text, "cw.moas").unwrap(), "cw.moas", text)
    window = PlanWindow(plan)
    window.show()
    labels = [label.text() for label in window.findChildren(QLabel)]
    assert "Not planned (no antenna covers them): 80 m 3800 kHz phone" in labels
    assert [window.band_filter.itemData(i) for i in range(window.band_filter.count())] == [
        None, "80 m", "20 m"]
    area = window.screen().availableGeometry()
    assert area.contains(window.frameGeometry())
    window.close()


def test_the_plan_window_shows_every_column_and_every_name_whole_at_1024x600(
        qapp: Any) -> None:
    """big-station's long antenna names ("40 m 3 element rotatable yagi") at the size the
    window takes on a 1024x600 screen: no column beyond the table's width, no text cut
    (long texts wrap onto more lines; each row is as tall as its wrapped text)."""
    from moas_gui.config import load_config
    from moas_gui.plan import plan_of
    from moas_gui.ui.plan_window import SIZE, PlanWindow
    from moas_gui.ui.qt import Qt

    path = EXAMPLES / "big-station.moas"
    plan, error = plan_of(load_config(path).unwrap(), path)
    assert plan is not None, error
    window = PlanWindow(plan)
    window.resize(*SIZE)
    window.show()
    qapp.processEvents()
    table = window.table
    try:
        widths = [table.columnWidth(c) for c in range(len(COLUMNS))]
        assert sum(widths) <= table.viewport().width(), (widths, table.viewport().width())
        assert table.wordWrap() and table.textElideMode() is Qt.TextElideMode.ElideNone
        metrics = table.fontMetrics()
        names = 0
        for row in range(table.rowCount()):
            for column in range(len(COLUMNS)):
                item = table.item(row, column)
                text = item.text() if item is not None else ""
                if not text:
                    continue
                room = widths[column] - 8  # the cell's margins
                needed = metrics.boundingRect(0, 0, room, 10_000,
                                              int(Qt.TextFlag.TextWordWrap), text).height()
                assert needed <= table.rowHeight(row), (text, needed, table.rowHeight(row))
                names += "rotatable yagi" in text
        assert names > 0, "the long names were looked at"
    finally:
        window.close()
