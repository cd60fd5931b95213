"""A stand-in for phidget22's ``Encoder`` and ``DigitalInput`` channels, with the library's
own callback shape (checked against phidget22 1.26's classes): handlers are set with
``setOn...Handler`` before ``open()``, and called on another thread than the caller's, as
the library calls them on its own, with the channel first."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any


class _Channel:
    def __init__(self, library: StandInLibrary) -> None:
        self.library = library
        self.handlers: dict[str, Callable[..., Any]] = {}
        self.opened = False
        self.closed = False
        self.serial: int | None = None
        self.hub_port: int | None = None

    def setOnAttachHandler(self, handler: Callable[..., Any]) -> None:
        self.handlers["attach"] = handler

    def setOnDetachHandler(self, handler: Callable[..., Any]) -> None:
        self.handlers["detach"] = handler

    def setOnErrorHandler(self, handler: Callable[..., Any]) -> None:
        self.handlers["error"] = handler

    def setDeviceSerialNumber(self, serial: int) -> None:
        self.serial = serial

    def setHubPort(self, port: int) -> None:
        self.hub_port = port

    def getDeviceSerialNumber(self) -> int:
        return self.library.serial

    def getHubPort(self) -> int:
        if self.library.hub_port is None:
            raise RuntimeError("PhidgetException 0x14 (Unsupported)")  # a USB 1052
        return self.library.hub_port

    def getDeviceName(self) -> str:
        return self.library.name

    def getDeviceSKU(self) -> str:
        return self.library.sku

    def open(self) -> None:
        self.opened = True

    def close(self) -> None:
        self.closed = True

    def fire(self, event: str, *args: Any) -> None:
        """Calls the handler of ``event`` on another thread, and waits for it."""
        handler = self.handlers[event]
        thread = threading.Thread(target=handler, args=(self, *args))
        thread.start()
        thread.join(5)


class StandInEncoder(_Channel):
    def setOnPositionChangeHandler(self, handler: Callable[..., Any]) -> None:
        self.handlers["position"] = handler

    def turn(self, counts: int) -> None:
        """``positionChange``, ``timeChange`` (ms), ``indexTriggered``."""
        self.fire("position", counts, 8.0, False)


class StandInButton(_Channel):
    def setOnStateChangeHandler(self, handler: Callable[..., Any]) -> None:
        self.handlers["state"] = handler

    def push(self, down: bool) -> None:
        self.fire("state", 1 if down else 0)


class StandInLibrary:
    """``Encoder`` and ``DigitalInput`` as the library's classes are called."""

    def __init__(self, *, name: str = "Phidget Dial", sku: str = "HIN1101",
                 serial: int = 654321, hub_port: int | None = 3) -> None:
        self.name, self.sku, self.serial, self.hub_port = name, sku, serial, hub_port
        self.encoders: list[StandInEncoder] = []
        self.buttons: list[StandInButton] = []

    def Encoder(self) -> StandInEncoder:
        channel = StandInEncoder(self)
        self.encoders.append(channel)
        return channel

    def DigitalInput(self) -> StandInButton:
        channel = StandInButton(self)
        self.buttons.append(channel)
        return channel

    @property
    def encoder(self) -> StandInEncoder:
        return self.encoders[-1]

    @property
    def button(self) -> StandInButton:
        return self.buttons[-1]


PHIDGET22_METHODS = {
    "Encoder": {"setOnAttachHandler", "setOnDetachHandler", "setOnErrorHandler",
                "setOnPositionChangeHandler", "open", "close", "getDeviceSerialNumber",
                "getHubPort", "getDeviceName", "getDeviceSKU"},
    "DigitalInput": {"setOnStateChangeHandler", "setDeviceSerialNumber", "setHubPort",
                     "open", "close"},
}
"""The methods the knob calls, each present in phidget22 1.26.20260821's classes."""
