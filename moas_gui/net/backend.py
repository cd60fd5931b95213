"""The seam between the client protocol server and the rest of the product.

The server (:mod:`moas_gui.net.server`) never imports the engine.  It asks a
:class:`ClientBackend` for everything a request needs, and the application
tells it about changes through the :class:`EventSink` calls the server offers::

      clients --JSON lines-->  ClientServer  --ClientBackend calls-->  EngineBackend --> ServerApp.act
      clients <--JSON lines--  ClientServer  <--EventSink calls-----   the app (after each change)

(``EngineBackend`` is :mod:`moas_gui.engine_backend`, the real server's backend.)

A backend answers with plain JSON-ready values (``dict``, ``list``, ``str``,
numbers, ``bool``, ``None``) in the shapes of the client protocol
(``docs/client-protocol.md``): the server adds the ``event`` key and the reply
envelope, nothing else.  When it refuses a request it raises
:class:`RequestError` with one of the protocol's error codes and a sentence
saying what was wrong; any other exception becomes an ``internal`` error reply
and a log line, and the connection carries on.

Every call is synchronous and is made on the event loop's thread: the engine is
pure and fast, so there is nothing to await.
:class:`moas_gui.testing.fake_backend.FakeBackend` is a small, complete backend for
tests and demos.
"""

from __future__ import annotations

from collections.abc import Mapping
from enum import StrEnum
from typing import Any, Literal, Protocol

from moas_gui.errors import RequestRefused

JSONObject = dict[str, Any]
"""A JSON object as :func:`json.loads` returns it."""

Target = Literal["both", "tx", "rx"]
LogLevel = Literal["error", "info", "debug"]
SwitchAction = Literal["stop", "start", "reset"]
"""The admin commands on the switches: ``stop_switches``, ``start_switches``,
``reset_switches``."""
FocusKind = Literal["active", "focus"]
"""Transmit focus (``active``) or receive focus (``focus``) of a station's radio."""


class ErrorCode(StrEnum):
    """The error codes of the client protocol, and nothing else."""

    BAD_REQUEST = "bad_request"
    """The request is malformed, or an argument is missing or of the wrong type."""
    UNKNOWN_CMD = "unknown_cmd"
    """No such command."""
    NOT_FOUND = "not_found"
    """No such station, radio, antenna, function, rotator or layout."""
    UNAVAILABLE = "unavailable"
    """It exists but cannot be used now (conflict, frequency, TX-only, not applicable)."""
    NOT_RUNNING = "not_running"
    """No configuration is loaded, or the switches are stopped."""
    FORBIDDEN = "forbidden"
    """The one asking may not do this: no operator's token where one is needed, or a
    role that does not allow it (docs/security.md)."""
    INTERNAL = "internal"
    """The server failed; the log says why."""


class RequestError(RequestRefused):
    """A request the backend refuses: ``code`` for programs, ``message`` for people."""

    code: ErrorCode

    def __init__(self, code: ErrorCode | str, message: str) -> None:
        try:
            self.code = ErrorCode(code)
        except ValueError:
            raise ValueError(
                f"{code!r} is not a client protocol error code; use one of "
                + ", ".join(c.value for c in ErrorCode)
            ) from None
        self.message = message
        super().__init__(f"{self.code.value}: {message}")


class ClientBackend(Protocol):
    """What the client protocol server needs from the product.

    Numbers are the configuration file's numbers; frequencies are in kHz;
    headings in degrees.  Each call raises :class:`RequestError` when refused.
    """

    def snapshot(self) -> JSONObject:
        """The whole state: ``config``, ``radios``, ``antennas``, ``rotators``, ``switches``."""
        ...

    def frequency(self, station: int, radio: int, khz: float, tx_khz: float | None) -> None:
        """A radio's frequency (``tx_khz`` when split); runs antenna selection for it."""
        ...

    def set_focus(self, station: int, radio: int, kind: FocusKind) -> None:
        """The station's transmit focus (``"active"``) or receive focus (``"focus"``) is on
        ``radio``; the radio entries of that station then carry ``active`` / ``focus``."""
        ...

    def select(
        self, station: int, radio: int, antenna: int, target: Target, exclusive: bool
    ) -> JSONObject:
        """A button press; returns ``{"tx": ID or None, "rx": ID or None}`` after it."""
        ...

    def function(self, station: int, radio: int, function: int) -> None:
        """Runs the configuration's function ``function`` for that radio."""
        ...

    def relative(
        self, station: int, radio: int, step: int | None, index: int | None
    ) -> JSONObject:
        """Next (+1) / previous (-1) relative antenna, or the one at ``index``;
        returns ``{"tx": ..., "rx": ...}``.  Exactly one of ``step`` and ``index`` is given."""
        ...

    def release(self, station: int, radio: int) -> None:
        """Releases the hold on the radio's antennas (whoever set it): they follow its
        frequency again.  Nothing to do when it is not held."""
        ...

    def layout(self, station: int, radio: int, rows: int, columns: int) -> JSONObject:
        """The closest layout: ``station``, ``radio``, ``rows``, ``columns``, ``buttons``."""
        ...

    def rotate(self, rotator: int, heading: float) -> None:
        """Starts turning ``rotator`` towards ``heading``."""
        ...

    def stop(self, rotator: int) -> None:
        """Stops ``rotator`` where it is."""
        ...

    def switches(self, action: SwitchAction, force: bool = False) -> None:
        """Stops (every relay off), starts or resets every switch (admin only).  A stop
        or a reset while a radio transmits is refused (``unavailable``, naming it)
        unless ``force``."""
        ...


class EventSink(Protocol):
    """What the application calls after a change; :class:`~moas_gui.net.server.ClientServer`
    is one.  Entries have the shapes of the snapshot's lists."""

    def publish_state(self) -> None:
        """A configuration was (re)loaded: every client gets a fresh snapshot."""
        ...

    def publish_radio(self, entry: Mapping[str, Any]) -> None:
        """A radio's frequency, antennas, transmit or inhibit state changed."""
        ...

    def publish_rotator(self, entry: Mapping[str, Any]) -> None:
        """A rotator's heading, target, moving or online changed."""
        ...

    def publish_switch(self, entry: Mapping[str, Any]) -> None:
        """A switch's status changed."""
        ...

    def layouts_may_have_changed(self) -> None:
        """Something that button states depend on changed; the server re-asks
        the backend for each layout a client follows and sends those that differ."""
        ...

    def publish_log(self, level: LogLevel, message: str) -> None:
        """A line for the clients that asked for the log."""
        ...


__all__ = [
    "ClientBackend",
    "ErrorCode",
    "EventSink",
    "JSONObject",
    "LogLevel",
    "RequestError",
    "SwitchAction",
    "Target",
]
