"""The Phidget knob without a window: the gesture arithmetic, and PhidgetKnob driven
through a stand-in with phidget22's callback shape (handlers called on another thread)."""

from __future__ import annotations

import inspect
import logging
from collections.abc import Callable

import pytest
from phidget_standin import PHIDGET22_METHODS, StandInButton, StandInEncoder, StandInLibrary

from moas_gui.client import phidget
from moas_gui.client.phidget import KnobGesture, PhidgetKnob


def test_counts_become_detent_steps_and_a_part_stays() -> None:
    g = KnobGesture()
    assert g.turned(3) == 0 and g.turned(1) == 1  # four counts: one detent
    assert g.turned(9) == 2 and g.turned(-1) == 0  # one count over, then back
    assert g.turned(-8) == -2
    assert KnobGesture(reverse=True).turned(4) == -1
    assert KnobGesture(counts_per_step=1).turned(-3) == -3


def test_a_press_alone_selects_alone_and_press_and_turn_adds() -> None:
    g = KnobGesture()
    assert g.released() is None  # a release with no press seen
    g.pressed()
    assert g.released() is True
    g.pressed()
    g.turned(2)  # less than a detent: not a turn
    assert g.released() is True
    g.pressed()
    g.turned(4)
    assert g.released() is False
    g.turned(4)
    g.pressed()
    assert g.released() is True  # the turn before the press does not count


class Actions:
    def __init__(self) -> None:
        self.done: list[tuple[object, ...]] = []

    def step(self, steps: int) -> object:
        self.done.append(("step", steps))
        return None

    def press(self, exclusive: bool = False) -> bool:
        self.done.append(("press", exclusive))
        return True

    def knob_attached(self, name: str) -> None:
        self.done.append(("attached", name))

    def knob_detached(self, name: str) -> None:
        self.done.append(("detached", name))


def _knob(library: StandInLibrary) -> tuple[PhidgetKnob, Actions, list[Callable[[], None]]]:
    posted: list[Callable[[], None]] = []
    actions = Actions()
    return PhidgetKnob(actions, posted.append, library=library), actions, posted


def _run(posted: list[Callable[[], None]]) -> None:
    while posted:
        posted.pop(0)()


def test_a_vint_dial_attaches_its_button_turns_and_presses() -> None:
    library = StandInLibrary()
    knob, actions, posted = _knob(library)
    assert knob.start() and library.encoder.opened
    encoder = library.encoder
    encoder.fire("attach")
    button = library.button
    assert (button.serial, button.hub_port, button.opened) == (654321, 3, True)
    encoder.turn(4)
    encoder.turn(-8)
    assert actions.done == [], "nothing runs on the library's thread"
    _run(posted)
    assert actions.done == [("attached", "Phidget Dial (HIN1101)"), ("step", 1), ("step", -2)]
    actions.done.clear()
    button.push(True)
    button.push(False)
    button.push(True)
    encoder.turn(4)
    button.push(False)
    _run(posted)
    assert actions.done == [("press", True), ("step", 1), ("press", False)]
    encoder.fire("detach")
    _run(posted)
    assert actions.done[-1] == ("detached", "Phidget Dial (HIN1101)") and not knob.attached
    knob.close()
    assert encoder.closed and button.closed


def test_a_usb_1052_is_not_on_a_hub_and_its_button_is_found_by_serial() -> None:
    library = StandInLibrary(name="PhidgetEncoder", sku="1052", serial=98765, hub_port=None)
    knob, actions, posted = _knob(library)
    knob.start()
    library.encoder.fire("attach")
    assert (library.button.serial, library.button.hub_port) == (98765, None)
    _run(posted)
    assert actions.done == [("attached", "PhidgetEncoder (1052)")]


def test_no_device_and_no_library_are_said_once(caplog: pytest.LogCaptureFixture,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    caplog.set_level(logging.INFO, "moas_gui.client.phidget")
    monkeypatch.setattr(phidget, "_TOLD", set())
    knob, _, _ = _knob(StandInLibrary())
    knob.start()
    knob.say_if_absent()
    knob.say_if_absent()
    assert caplog.text.count("No Phidget encoder is attached") == 1

    def missing(name: str) -> object:
        raise ImportError(f"No module named {name!r}")

    monkeypatch.setattr(phidget.importlib, "import_module", missing)
    assert phidget.load_library() is None and phidget.load_library() is None
    assert caplog.text.count("phidget22 is not installed (pip install 'moas-gui[knob]')") == 1
    unstarted = PhidgetKnob(Actions(), lambda work: None)
    assert not unstarted.start()


def test_the_stand_in_has_the_methods_the_knob_calls_with_the_librarys_shape() -> None:
    for cls, names in ((StandInEncoder, PHIDGET22_METHODS["Encoder"]),
                       (StandInButton, PHIDGET22_METHODS["DigitalInput"])):
        assert names <= set(dir(cls)), names - set(dir(cls))
    source = inspect.getsource(phidget)
    every = set().union(*PHIDGET22_METHODS.values())
    assert {n for n in every if f".{n}(" in source} == every  # each is one the knob calls
