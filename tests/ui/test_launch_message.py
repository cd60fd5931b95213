"""The message window of a launch that cannot go on (moas_gui/ui/launch_message.py): a
second launch with a broken file says the running server goes on, and shows the file's
problems in the window itself, not behind "Show Details"."""

from __future__ import annotations

from typing import Any

from moas_gui.ui.launch_message import refusal_box


def test_a_broken_file_handed_to_a_running_server_shows_its_problems_in_the_window(
        qapp: Any) -> None:
    box = refusal_box("moas-server", "station.moas has 2 errors, so it was not opened; the "
                      "moas-server that is already running goes on untouched with what it "
                      "runs", "correct the file where the lines below say, then open it again",
                      "line 4, column 9: missing comma\nline 7, column 2: unknown key",
                      title="station.moas was not opened")
    assert box.windowTitle() == "station.moas was not opened"
    assert box.text().startswith("Station.moas has 2 errors") and "goes on" in box.text()
    assert "did not start" not in box.text()
    assert "line 4, column 9: missing comma" in box.informativeText()
    assert box.informativeText().endswith("then open it again.")
    assert box.detailedText() == ""  # nothing hidden behind Show Details
    box.deleteLater()


def test_other_refusals_still_say_the_program_did_not_start(qapp: Any) -> None:
    box = refusal_box("moas-server", "another moas-server is running but does not answer",
                      "end it", "")
    assert box.windowTitle() == "moas-server did not start"
    assert box.text() == ("moas-server did not start: another moas-server is running but "
                          "does not answer.")
    box.deleteLater()
