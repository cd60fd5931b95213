"""Talking to Hamlib's ``rotctld`` as a client, sans-IO (rotator-protocols.md 7).

Every command is sent in the extended form (``+`` prefix), so every answer,
whatever the command, ends with one ``RPRT <code>`` line: framing never
depends on knowing how many value lines a command has (7.8).  A command the
daemon does not know gets no answer at all, and an I/O error on its side
closes the connection; the link handles both with a timeout and a reconnect.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .ascii import is_digits

HAMLIB_PORT = 4533

ERROR_NAMES = {
    0: "ok", 1: "invalid parameter", 2: "invalid configuration", 3: "out of memory",
    4: "not implemented", 5: "communication timed out", 6: "I/O error",
    7: "internal Hamlib error", 8: "protocol error", 9: "command rejected by the device",
    10: "argument truncated", 11: "function not available", 12: "VFO not targetable",
    13: "bus error", 14: "bus collision", 15: "invalid pointer", 16: "invalid VFO",
    17: "argument out of domain", 18: "deprecated", 19: "security error",
    20: "device not powered", 21: "limit exceeded", 22: "access denied",
}


def error_text(code: int) -> str:
    """``RPRT -1 (invalid parameter)``."""
    return f"RPRT {code} ({ERROR_NAMES.get(abs(code), 'unknown error')})"


def encode_dump_state() -> bytes:
    return b"+\\dump_state\n"


def encode_get_pos() -> bytes:
    return b"+p\n"


def encode_set_pos(azimuth: float, elevation: float) -> bytes:
    return f"+P {azimuth:.2f} {elevation:.2f}\n".encode("ascii")


def encode_stop() -> bytes:
    return b"+S\n"


@dataclass(frozen=True, slots=True)
class ExtendedReply:
    header: str
    records: tuple[tuple[str, str], ...]
    """(label, value) per record; ``key=value`` lines count as records too;
    a line with neither has the label ``""``."""
    code: int

    def value(self, *labels: str) -> str | None:
        for label, value in self.records:
            if label in labels:
                return value
        return None

    def number(self, *labels: str) -> float | None:
        text = self.value(*labels)
        if text is None:
            return None
        try:
            number = float(text.replace(",", "."))
        except ValueError:
            return None
        return number if math.isfinite(number) else None


class ReplyAssembler:
    """Lines in (without their LF), whole :class:`ExtendedReply` out."""

    def __init__(self) -> None:
        self._lines: list[str] = []

    def add(self, line: str) -> ExtendedReply | None:
        line = line.rstrip("\r\n")
        if line.startswith("RPRT"):
            code_text = line[4:].strip()
            lines, self._lines = self._lines, []
            body = code_text[1:] if code_text[:1] == "-" else code_text
            code = int(code_text) if is_digits(body) else -8
            header = lines[0].rstrip(":") if lines else ""
            return ExtendedReply(header, tuple(_record(text) for text in lines[1:]), code)
        if line:
            self._lines.append(line)
        return None


def _record(line: str) -> tuple[str, str]:
    if ": " in line:
        label, value = line.split(": ", 1)
        return label.strip(), value.strip()
    if "=" in line:
        key, value = line.split("=", 1)
        return key.strip(), value.strip()
    return "", line.strip()


@dataclass(frozen=True, slots=True)
class Limits:
    min_az: float = -180.0
    max_az: float = 540.0


def limits_of(reply: ExtendedReply) -> Limits | None:
    """The azimuth limits in a ``dump_state`` answer (protocol 0 or 1), if any."""
    low = reply.number("Minimum Azimuth", "min_az")
    high = reply.number("Maximum Azimuth", "max_az")
    if low is None or high is None or high <= low:
        return None
    return Limits(low, high)


__all__ = [
    "ERROR_NAMES", "HAMLIB_PORT", "ExtendedReply", "Limits", "ReplyAssembler", "encode_dump_state",
    "encode_get_pos", "encode_set_pos", "encode_stop", "error_text", "limits_of",
]
