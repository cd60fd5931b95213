"""The Phidget encoder knob of manual 4.4 and 5.18, with no Qt (docs/client.md).

With the optional extra ``moas-gui[knob]`` (PyPI's ``phidget22``, which carries
its native library; ``libusb-1.0`` is its one outside need) the client opens a
Phidget ``Encoder`` channel: the 1052 USB encoder with its knob, or a VINT
dial (HIN1101 Phidget Dial, ENC1000/ENC1001 encoder interfaces).  When the
encoder attaches, the push button of the same device (its ``DigitalInput``
channel, by serial number and hub port) is opened too.

What the knob does, as the manual's Knob client (6.7: one row, right is the
next item, left the previous, wrapping past the ends), with its button:

==============================  ==============================================
turn right / left               the cursor to the next / previous antenna of the
                                layout (``counts_per_step`` encoder counts, 4 by
                                default: one detent of the usual knobs)
press and release               select the antenna under the cursor alone: a knob
                                item is a whole choice (7.3 lists each combination
                                of a stack as an item of its own)
turn while holding the button   move the cursor; on release the antenna under it is
                                *added* to what is selected (press-and-turn: a
                                combination of additive antennas without an item)
==============================  ==============================================

The library calls its handlers on a thread of its own; :class:`PhidgetKnob`
hands every event to ``post``, which must run it on the client's thread (the
window's Qt thread).  :class:`KnobGesture` is the arithmetic, tested alone.
"""

from __future__ import annotations

import importlib
import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Final, Protocol

log = logging.getLogger(__name__)

COUNTS_PER_STEP: Final = 4
"""Encoder counts of one step: a quadrature encoder counts four edges per detent of the
usual mechanical knobs (not yet checked on a 1052 or a HIN1101)."""
INSTALL_HINT: Final = "pip install 'moas-gui[knob]'"


class KnobActions(Protocol):
    """What the knob drives (the window's :class:`~moas_gui.ui.knob.KnobControl`)."""

    def step(self, steps: int) -> object: ...

    def press(self, exclusive: bool = False) -> bool: ...

    def knob_attached(self, name: str) -> None: ...

    def knob_detached(self, name: str) -> None: ...


@dataclass(slots=True)
class KnobGesture:
    """Counts to steps, and a press to *alone* or *added* (see the module notes)."""

    counts_per_step: int = COUNTS_PER_STEP
    reverse: bool = False
    held: bool = False
    turned_while_held: bool = False
    _counts: int = 0

    def turned(self, counts: int) -> int:
        """The whole steps ``counts`` more encoder counts make (right is positive)."""
        self._counts += -counts if self.reverse else counts
        steps = int(self._counts / self.counts_per_step)  # towards zero: a part stays
        self._counts -= steps * self.counts_per_step
        if steps and self.held:
            self.turned_while_held = True
        return steps

    def pressed(self) -> None:
        self.held = True
        self.turned_while_held = False

    def released(self) -> bool | None:
        """None when no press was seen; else True to select alone, False to add."""
        if not self.held:
            return None
        self.held = False
        return not self.turned_while_held


class PhidgetLibrary(Protocol):
    """The two channel classes of ``phidget22`` used (a stand-in gives its own)."""

    @property
    def Encoder(self) -> Callable[[], Any]: ...  # the library's class names

    @property
    def DigitalInput(self) -> Callable[[], Any]: ...


@dataclass(frozen=True, slots=True)
class _Library:
    Encoder: Callable[[], Any]
    DigitalInput: Callable[[], Any]


_TOLD: set[str] = set()


def _once(key: str, message: str, *args: object) -> None:
    if key not in _TOLD:
        _TOLD.add(key)
        log.info(message, *args)


def load_library() -> PhidgetLibrary | None:
    """``phidget22``'s classes, or None (said once) when the extra is not installed or its
    native library cannot be loaded."""
    try:
        encoder = importlib.import_module("Phidget22.Devices.Encoder")
        digital = importlib.import_module("Phidget22.Devices.DigitalInput")
    except ImportError:
        _once("missing", "The Phidget knob is not used: phidget22 is not installed (%s); "
              "the wheel and keys work as before", INSTALL_HINT)
        return None
    except OSError as exc:  # its native library refused to load
        _once("native", "The Phidget knob is not used: phidget22 cannot load its library "
              "(%s; it needs libusb-1.0); the wheel and keys work as before", exc)
        return None
    return _Library(encoder.Encoder, digital.DigitalInput)


class PhidgetKnob:
    """One Phidget encoder and its button, driving ``actions`` (see the module notes)."""

    def __init__(self, actions: KnobActions, post: Callable[[Callable[[], None]], None], *,
                 library: PhidgetLibrary | None = None, counts_per_step: int = COUNTS_PER_STEP,
                 reverse: bool = False) -> None:
        self.actions = actions
        self.post = post
        self.library = library
        self.gesture = KnobGesture(counts_per_step, reverse)
        self.encoder: Any = None
        self.button: Any = None
        self.name = ""
        """The device's name while attached (``Phidget Dial (HIN1101)``)."""
        self.attached = False
        self.started = False

    def start(self) -> bool:
        """Opens the encoder channel (attachment comes later, or never); False when the
        library is not there or refuses."""
        library = self.library if self.library is not None else load_library()
        if library is None:
            return False
        self.library = library
        try:
            encoder = library.Encoder()
            encoder.setOnAttachHandler(self._encoder_attached)
            encoder.setOnDetachHandler(self._encoder_detached)
            encoder.setOnPositionChangeHandler(self._position_changed)
            encoder.setOnErrorHandler(self._error)
            encoder.open()
        except Exception as exc:  # noqa: BLE001 - PhidgetException: the knob is optional
            _once("open", "The Phidget knob cannot be opened (%s); the wheel and keys work "
                  "as before", exc)
            return False
        self.encoder = encoder
        self.started = True
        return True

    def say_if_absent(self) -> None:
        """Called a while after :meth:`start`: says once that no encoder attached."""
        if self.started and not self.attached:
            _once("absent", "No Phidget encoder is attached; the wheel and keys work as "
                  "before (one is used when it is plugged in)")

    def close(self) -> None:
        for channel in (self.button, self.encoder):
            if channel is not None:
                try:
                    channel.close()
                except Exception:
                    log.debug("closing a Phidget channel failed", exc_info=True)
        self.button = self.encoder = None
        self.started = False

    # -- the library's thread: everything is posted to the client's ---------------------------
    def _encoder_attached(self, channel: Any) -> None:
        name = _device_name(channel)
        self._open_button(channel)
        self.post(lambda: self._attached(name))

    def _encoder_detached(self, channel: Any) -> None:
        self.post(self._detached)

    def _position_changed(self, channel: Any, change: int, elapsed: float,
                          index: bool) -> None:
        self.post(lambda: self._turned(int(change)))

    def _button_changed(self, channel: Any, state: bool | int) -> None:
        self.post(self._pressed if state else self._released)

    def _error(self, channel: Any, code: object, description: str) -> None:
        log.debug("Phidget knob: %s (%s)", description, code)

    def _open_button(self, encoder: Any) -> None:
        """The push button of the device the encoder is on, once."""
        if self.button is not None or self.library is None:
            return
        try:
            button = self.library.DigitalInput()
            button.setDeviceSerialNumber(encoder.getDeviceSerialNumber())
            port = _hub_port(encoder)
            if port >= 0:  # a VINT dial: its button is on the same hub port
                button.setHubPort(port)
            button.setOnStateChangeHandler(self._button_changed)
            button.open()
        except Exception as exc:  # noqa: BLE001 - a knob without a button still turns
            log.debug("Phidget knob: no push button opened (%s)", exc)
            return
        self.button = button

    # -- the client's thread -----------------------------------------------------------------------
    def _attached(self, name: str) -> None:
        self.attached = True
        self.name = name
        self.actions.knob_attached(name)

    def _detached(self) -> None:
        self.attached = False
        self.gesture.held = False
        self.actions.knob_detached(self.name or "the Phidget encoder")

    def _turned(self, counts: int) -> None:
        steps = self.gesture.turned(counts)
        if steps:
            self.actions.step(steps)

    def _pressed(self) -> None:
        self.gesture.pressed()

    def _released(self) -> None:
        alone = self.gesture.released()
        if alone is not None:
            self.actions.press(exclusive=alone)


def _hub_port(channel: Any) -> int:
    """The VINT hub port of ``channel``; -1 for a USB device such as the 1052."""
    try:
        return int(channel.getHubPort())
    except Exception:  # noqa: BLE001 - PhidgetException: not on a hub
        return -1


def _device_name(channel: Any) -> str:
    try:
        return f"{channel.getDeviceName()} ({channel.getDeviceSKU()})"
    except Exception:  # noqa: BLE001 - a name is only for the status line
        return "a Phidget encoder"


__all__ = ["COUNTS_PER_STEP", "INSTALL_HINT", "KnobActions", "KnobGesture", "PhidgetKnob",
           "PhidgetLibrary", "load_library"]
