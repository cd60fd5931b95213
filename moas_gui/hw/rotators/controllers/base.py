"""What every rotator controller codec and emulator has in common.

A *codec* is the driver's side of one controller model, without any I/O:

- commands in, bytes out: ``poll``, ``rotate`` and ``stop`` return the
  :class:`Send` items to write, in order;
- bytes in, events out: ``receive`` turns whatever the controller sent into
  :class:`Heading`, :class:`Notice` and :class:`Garbage` events (and, for the
  few models that must ask something first, further :class:`Send` items);
- no clock of its own: ``now`` (seconds, any monotonic origin) is passed in,
  and ``deadline``/``tick`` let a codec that has no position readback (the
  DCU-1) announce a heading when a turn should be over.

An *emulator* is the controller's side, also pure: ``receive(data, now)``
returns the controller's answer, ``advance(now)`` returns what it sends on its
own, and the :class:`Axis` below moves the antenna at a realistic speed.

Errors::

    ControllerError            anything this package refuses
    +-- UnknownModel           a model number or name no codec knows (the user's configuration)
    +-- OutOfRange             a heading the controller cannot be asked for
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Generic, Protocol, TypeVar

from moas_gui.errors import ProtocolError


class ControllerError(ProtocolError):
    """Something a controller codec refuses to do."""


class UnknownModel(ControllerError):
    """A model number or name that no codec knows."""


class OutOfRange(ControllerError):
    """A heading outside what the controller accepts."""


@dataclass(frozen=True, slots=True)
class Send:
    """Bytes to write to the controller, then at least ``pause`` seconds of quiet."""

    data: bytes
    pause: float = 0.0
    expects_reply: bool = False
    """True when the controller answers these bytes (the driver then waits for it)."""


@dataclass(frozen=True, slots=True)
class Heading:
    """The controller's azimuth, in its own degrees."""

    degrees: float
    estimated: bool = False
    """True when the controller cannot report and the codec worked it out (DCU-1)."""


@dataclass(frozen=True, slots=True)
class Notice:
    """Something the controller said that is not a heading and not an error of ours."""

    text: str


@dataclass(frozen=True, slots=True)
class Ack:
    """The controller answered, with nothing to report (an acknowledgement, another axis)."""


@dataclass(frozen=True, slots=True)
class Garbage:
    """Bytes that fit no reply of this controller, with the reason."""

    data: bytes
    reason: str


Event = Heading | Notice | Ack | Garbage
Output = Send | Heading | Notice | Ack | Garbage


@dataclass(frozen=True, slots=True)
class SerialSettings:
    """How the port is set up (always 8 data bits, 1 stop bit here; parity "N")."""

    baudrate: int
    bytesize: int = 8
    parity: str = "N"
    stopbits: int = 1


@dataclass(frozen=True, slots=True)
class ModelInfo:
    """Facts about one controller model that the driver needs."""

    number: int | None
    """The MOAS model number (None for names this project adds, like "GS-232A")."""
    name: str
    description: str
    serial: SerialSettings
    minimum: float
    """Lowest heading the controller can be sent."""
    maximum: float
    """Highest heading the controller can be sent."""
    write_gap: float
    """Seconds of quiet the controller needs after each command."""
    reply_timeout: float
    """Seconds to wait for an answer to a poll."""
    has_readback: bool = True
    unsolicited: bool = False
    """True when the controller reports changes by itself (the poll time is then ignored)."""


class ControllerCodec(Protocol):
    """The driver's side of one controller model (see the module docstring)."""

    info: ModelInfo

    def opening(self) -> list[Send]:
        """Bytes to send once, right after the port is opened."""
        ...

    def poll(self, now: float) -> list[Output]:
        """Ask for the heading (empty when the controller cannot be asked)."""
        ...

    def rotate(self, degrees: float, now: float) -> list[Output]:
        """Turn to ``degrees``; raises :class:`OutOfRange` outside the model's range."""
        ...

    def stop(self, now: float) -> list[Output]:
        """Stop turning."""
        ...

    def receive(self, data: bytes, now: float) -> list[Output]:
        """Bytes from the controller, in any pieces."""
        ...

    def deadline(self) -> float | None:
        """When ``tick`` has something to say, or None."""
        ...

    def tick(self, now: float) -> list[Output]:
        """Events that are due by ``now`` without any byte arriving."""
        ...


class ControllerEmulator(Protocol):
    """The controller's side of one model: what it answers and when it turns."""

    @property
    def azimuth(self) -> float:
        """Where the antenna points now (controller degrees), as of the last call."""
        ...

    @property
    def busy(self) -> bool:
        """True while something moves (the host then calls ``advance`` often)."""
        ...

    def receive(self, data: bytes, now: float) -> bytes:
        """Bytes from the computer; returns the controller's answer."""
        ...

    def advance(self, now: float) -> bytes:
        """Lets time pass; returns what the controller sends on its own."""
        ...

    def turn_by_hand(self, azimuth: float, now: float) -> None:
        """Moves the antenna as an operator at the front panel would (at once)."""
        ...


def check_range(info: ModelInfo, degrees: float) -> float:
    """``degrees`` if the model accepts it, else :class:`OutOfRange` saying why."""
    if not math.isfinite(degrees):
        raise OutOfRange(f"{info.name}: heading {degrees!r} is not a number")
    if not info.minimum <= degrees <= info.maximum:
        raise OutOfRange(
            f"{info.name}: heading {degrees:g} is outside {info.minimum:g}..{info.maximum:g}"
        )
    return degrees


def whole(degrees: float) -> int:
    """Rounds half away from zero (``round`` would send 0.5 to 0 and 2.5 to 2)."""
    return math.floor(abs(degrees) + 0.5) * (1 if degrees >= 0 else -1)


# ----------------------------------------------------------------------------------------------
# Framing: one scanner, with a small matcher per protocol.

T = TypeVar("T")

NEED_MORE = 0
"""A matcher's answer when the bytes so far could still become a frame."""
NO_FRAME = -1
"""A matcher's answer when no frame starts at this byte."""

class FrameScanner(Generic[T]):
    """Cuts a byte stream into frames; bytes that start no frame become :class:`Garbage`.

    ``match(buffer)`` looks at the start of ``buffer`` and answers
    ``(n, value)``: ``n > 0`` when a complete frame of ``n`` bytes is there
    (``value`` None means "skip quietly", for example a line end),
    :data:`NEED_MORE` when more bytes could complete one, :data:`NO_FRAME`
    when none starts here.  Partial frames wait for the next ``feed``; runs of
    bad bytes come out as one :class:`Garbage` each, in stream order.
    """

    __slots__ = ("_buffer", "_limit", "_match", "_what")

    def __init__(self, match: Callable[[bytes], tuple[int, T | None]], what: str,
                 limit: int = 256) -> None:
        self._buffer = b""
        self._match = match
        self._what = what
        self._limit = limit

    @property
    def pending(self) -> bytes:
        """Bytes kept because they may begin a frame."""
        return self._buffer

    def feed(self, data: bytes) -> list[T | Garbage]:
        buffer = self._buffer + data
        out: list[T | Garbage] = []
        junk = bytearray()
        i = 0
        while i < len(buffer):
            n, value = self._match(buffer[i : i + self._limit])
            if n == NEED_MORE and len(buffer) - i < self._limit:
                break
            if n <= 0:
                junk.append(buffer[i])
                i += 1
                continue
            if junk:
                out.append(Garbage(bytes(junk), f"not a {self._what}"))
                junk.clear()
            if value is not None:
                out.append(value)
            i += n
        if junk:
            out.append(Garbage(bytes(junk), f"not a {self._what}"))
        self._buffer = buffer[i:]
        return out


def split_line(buffer: bytes, limit: int = 80) -> tuple[int, bytes | None]:
    """Matcher helper for CR/LF-terminated text: ``(length, line)``.

    A line ends at the first CR or LF; the terminator is part of the length.
    A lone CR or LF is ``(1, None)``.  No terminator yet: :data:`NEED_MORE`,
    unless the line is already longer than ``limit`` (then :data:`NO_FRAME`).
    """
    for i, byte in enumerate(buffer):
        if byte in (0x0D, 0x0A):
            if i == 0:
                return 1, None
            return i + 1, buffer[:i]
        if i >= limit:
            return NO_FRAME, None
    return NEED_MORE, None


# ----------------------------------------------------------------------------------------------
# Movement, for the emulators.


class Axis:
    """One rotator axis turning at a steady speed between two end stops.

    Positions are the controller's own degrees.  Time is passed in; nothing
    moves between calls, and every call first brings the position up to
    ``now``.
    """

    __slots__ = ("_time", "maximum", "minimum", "position", "speed", "target")

    def __init__(self, position: float, minimum: float, maximum: float, speed: float,
                 now: float = 0.0) -> None:
        if speed <= 0:
            raise ValueError(f"turning speed must be positive, not {speed}")
        self.position = min(max(position, minimum), maximum)
        self.minimum = minimum
        self.maximum = maximum
        self.speed = speed
        self.target: float | None = None
        self._time = now

    @property
    def moving(self) -> bool:
        return self.target is not None

    def advance(self, now: float) -> None:
        elapsed = max(0.0, now - self._time)
        self._time = max(self._time, now)
        if self.target is None:
            return
        step = self.speed * elapsed
        distance = self.target - self.position
        if abs(distance) <= step:
            self.position = self.target
            self.target = None
        else:
            self.position += math.copysign(step, distance)

    def go_to(self, target: float, now: float) -> None:
        self.advance(now)
        target = min(max(target, self.minimum), self.maximum)
        self.target = None if target == self.position else target

    def run(self, clockwise: bool, now: float) -> None:
        """Turns until stopped or until the end stop."""
        self.go_to(self.maximum if clockwise else self.minimum, now)

    def stop(self, now: float) -> None:
        self.advance(now)
        self.target = None

    def place(self, position: float, now: float) -> None:
        """Puts the antenna at ``position`` at once (hand turning, power-on)."""
        self.advance(now)
        self.position = min(max(position, self.minimum), self.maximum)
        self.target = None

    def arrival(self, now: float) -> float | None:
        """When the current turn ends, or None when standing still."""
        self.advance(now)
        if self.target is None:
            return None
        return now + abs(self.target - self.position) / self.speed


DEFAULT_SPEED = 6.0
"""Degrees per second: a Hy-Gain HAM-IV or a Yaesu G-1000 turns 360 degrees in about a minute."""



class ScannedCodec:
    """What the codecs of line-framed controllers share: their replies come through a
    :class:`FrameScanner`, they send nothing on opening, and they keep no timer."""

    _scanner: FrameScanner[Any]

    def opening(self) -> list[Send]:
        return []

    def receive(self, data: bytes, now: float) -> list[Output]:
        return list(self._scanner.feed(data))

    def deadline(self) -> float | None:
        return None

    def tick(self, now: float) -> list[Output]:
        return []

__all__ = [
    "DEFAULT_SPEED",
    "NEED_MORE",
    "NO_FRAME",
    "Ack",
    "Axis",
    "ControllerCodec",
    "ControllerEmulator",
    "ControllerError",
    "Event",
    "FrameScanner",
    "Garbage",
    "Heading",
    "ModelInfo",
    "Notice",
    "OutOfRange",
    "Output",
    "ScannedCodec",
    "Send",
    "SerialSettings",
    "UnknownModel",
    "check_range",
    "split_line",
    "whole",
]
