"""The Phidget knob in a real window against the protocol server (fake backend): the
encoder's events come on another thread, as phidget22 calls them, through a stand-in with
the library's callback shape."""

from __future__ import annotations

from typing import Any

from client_support import LiveServer, run_on_qt
from helpers import until
from phidget_standin import StandInLibrary
from test_client_window import button, open_window

from moas_gui.ui.qt import QApplication


def test_the_encoder_steps_presses_alone_and_press_and_turn_adds(qapp: QApplication,
                                                                 qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            library = StandInLibrary()
            assert window.knob.start_phidget(library)
            encoder = library.encoder
            encoder.fire("attach")
            await until(lambda: "Knob: Phidget Dial (HIN1101) attached" in window.status_text(),
                        what="the attach shown")
            tribander = button(window, "Tribander").view.id
            stack = button(window, "20 Stack").view.id
            encoder.turn(4)  # one detent right: from the antenna in use to the next
            await until(lambda: window.knob.cursor == tribander, what="the cursor moved")
            assert live.calls("select") == [], "turning alone selects nothing"
            encoder.turn(2)
            encoder.turn(2)  # two half detents: one step, wrapping past the end
            await until(lambda: window.knob.cursor == stack, what="the cursor wrapped")
            encoder.turn(-4)
            await until(lambda: window.knob.cursor == tribander, what="one detent left")
            library.button.push(True)
            library.button.push(False)
            await until(lambda: (1, 1, tribander, "both", True) in live.calls("select"),
                        what="a press selecting the cursor's antenna alone")
            library.button.push(True)
            encoder.turn(4)  # press and turn: the cursor moves, the release adds
            library.button.push(False)
            await until(lambda: (1, 1, stack, "both", False) in live.calls("select"),
                        what="press-and-turn adding the antenna")
            encoder.fire("detach")
            await until(lambda: "Knob: Phidget Dial (HIN1101) detached" in window.status_text(),
                        what="the detach shown")
            window.knob.close()
            assert encoder.closed and library.button.closed

    run_on_qt(qapp, scenario())
