"""A Yaesu GS-232A or GS-232B with an az/el rotator, as a pure model.

Answers, per the manuals and real units:

=========  =====================  ==========================
command    GS-232A                GS-232B
=========  =====================  ==========================
C          ``+0aaa\\r\\n``          ``AZ=aaa\\r\\n``
C2         ``+0aaa+0eee\\r\\n``     ``AZ=aaa  EL=eee\\r\\n`` (two spaces)
B          ``+0eee\\r\\n``          ``EL=eee\\r\\n``
M W S A E  ``\\r``                  nothing
R L U D X
bad/empty  ``?>\\r\\n``             ``?>\\r\\n``
=========  =====================  ==========================

Commands end with CR; LF is ignored; letters may be in either case.
Azimuth runs 0-450 from the counter-clockwise stop, elevation 0-180; ``X1``
to ``X4`` set the azimuth speed (``X4``, the fastest, is ``speed``).
"""

from __future__ import annotations

from .base import DEFAULT_SPEED, Axis

ERROR = b"?>\r\n"
SPEED_STEPS = {b"1": 0.4, b"2": 0.6, b"3": 0.8, b"4": 1.0}
"""Fractions of the top speed for ``X1``-``X4``."""
ELEVATION_SPEED = 2.0
"""Degrees per second of a typical elevation rotator (a G-5500 takes about a minute for 180)."""


def _three_digits(text: bytes) -> int | None:
    return int(text) if len(text) == 3 and text.isdigit() else None


class YaesuEmulator:
    """A GS-232A (``variant="A"``) or GS-232B (``variant="B"``); see the module docstring."""

    def __init__(self, azimuth: float = 0.0, variant: str = "B", speed: float = DEFAULT_SPEED,
                 now: float = 0.0, maximum: float = 450.0) -> None:
        if variant not in ("A", "B"):
            raise ValueError(f"GS-232 variant must be 'A' or 'B', not {variant!r}")
        self._variant = variant
        self._top_speed = speed
        self._az = Axis(azimuth, 0.0, maximum, speed, now)
        self._el = Axis(0.0, 0.0, 180.0, ELEVATION_SPEED, now)
        self._buffer = b""

    @property
    def azimuth(self) -> float:
        return self._az.position

    @property
    def elevation(self) -> float:
        return self._el.position

    @property
    def busy(self) -> bool:
        return self._az.moving or self._el.moving

    def receive(self, data: bytes, now: float) -> bytes:
        self.advance(now)
        self._buffer += data.replace(b"\n", b"")
        out = b""
        while b"\r" in self._buffer:
            line, _, self._buffer = self._buffer.partition(b"\r")
            out += self._obey(line.strip().upper(), now)
        if len(self._buffer) > 128:  # the unit's input buffer overflows: it starts again
            self._buffer = b""
            out += ERROR
        return out

    def advance(self, now: float) -> bytes:
        self._az.advance(now)
        self._el.advance(now)
        return b""

    def turn_by_hand(self, azimuth: float, now: float) -> None:
        self._az.place(azimuth, now)

    # -- answers ----------------------------------------------------------------------------

    def _angle(self, axis: Axis, label: bytes) -> bytes:
        value = int(axis.position + 0.5)
        return b"+0%03d" % value if self._variant == "A" else label + b"=%03d" % value

    def _done(self) -> bytes:
        return b"\r" if self._variant == "A" else b""

    def _obey(self, line: bytes, now: float) -> bytes:
        if line == b"C":
            return self._angle(self._az, b"AZ") + b"\r\n"
        if line == b"C2":
            gap = b"" if self._variant == "A" else b"  "
            return self._angle(self._az, b"AZ") + gap + self._angle(self._el, b"EL") + b"\r\n"
        if line == b"B":
            return self._angle(self._el, b"EL") + b"\r\n"
        if line.startswith(b"M"):
            target = _three_digits(line[1:])
            if target is None or target > self._az.maximum:
                return ERROR
            self._az.go_to(target, now)
            return self._done()
        if line.startswith(b"W"):
            parts = line[1:].split(b" ")
            if len(parts) != 2:
                return ERROR
            az, el = _three_digits(parts[0]), _three_digits(parts[1])
            if az is None or el is None or az > self._az.maximum or el > 180:
                return ERROR
            self._az.go_to(az, now)
            self._el.go_to(el, now)
            return self._done()
        return self._simple(line, now)

    def _simple(self, line: bytes, now: float) -> bytes:
        if line == b"S":
            self._az.stop(now)
            self._el.stop(now)
        elif line == b"A":
            self._az.stop(now)
        elif line == b"E":
            self._el.stop(now)
        elif line in (b"R", b"L"):
            self._az.run(line == b"R", now)
        elif line in (b"U", b"D"):
            self._el.run(line == b"U", now)
        elif line[:1] == b"X" and line[1:] in SPEED_STEPS:
            self._az.advance(now)
            self._az.speed = self._top_speed * SPEED_STEPS[line[1:]]
        else:
            return ERROR
        return self._done()


__all__ = ["ERROR", "YaesuEmulator"]
