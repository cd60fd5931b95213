"""N1MM Logger+'s rotor commands and heading reports (sans-IO).

N1MM's rotor window turns a rotator by sending one small XML document per UDP
datagram to its rotor program (port 12040 by default, N1MM's
``RotorStartPort``), and shows the headings that program sends back as plain
text to UDP 13010.  The format, as read alike by independent implementations
(see docs/sources.md; shared/specs/logger-network.md 1.9)::

    <N1MMRotor><rotor>TH6</rotor><goazi>55.0</goazi><offset>0.0</offset>
    <bidirectional>0</bidirectional><freqband>14.0</freqband></N1MMRotor>

    <N1MMRotor><stop><rotor>TH6</rotor><freqband>21.0</freqband></stop></N1MMRotor>

    TH6 @ 1460          (heading report: 146.0 degrees, in tenths)

``rotor`` is the "Rotor Description" of N1MM's Antennas table; ``*`` has been
seen from N1MM and means "the rotor" when only one is meant.  N1MM also sends
other datagrams to the rotor port; anything that is not ``<N1MMRotor>`` is
refused with reason ``not_rotor`` (not the sender's error).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Final

from moas_gui.errors import ProtocolError

DEFAULT_COMMAND_PORT: Final = 12040
DEFAULT_HEADING_PORT: Final = 13010
MAX_PACKET_BYTES: Final = 4096
MAX_NAME: Final = 64

REASONS: Final = ("too_large", "not_xml", "doctype", "not_rotor", "missing_field", "bad_value")

_DECIMAL: Final = re.compile(r"-?[0-9]{1,6}(\.[0-9]{1,6})?")


class N1MMRotorError(ProtocolError):
    """A datagram that is not a usable rotor command; :attr:`reason` is one of :data:`REASONS`."""

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


@dataclass(frozen=True, slots=True)
class RotorTurn:
    """Turn ``rotor`` to ``azimuth`` degrees."""

    rotor: str
    azimuth: float
    offset: float = 0.0
    bidirectional: bool = False
    band_mhz: float | None = None


@dataclass(frozen=True, slots=True)
class RotorStop:
    """Stop ``rotor``."""

    rotor: str
    band_mhz: float | None = None


RotorCommand = RotorTurn | RotorStop


def _decimal(text: str, name: str) -> float:
    if _DECIMAL.fullmatch(text) is None:
        raise N1MMRotorError("bad_value", f"<{name}>{text[:20]}</{name}> is not a number "
                                          "written in digits 0-9")
    return float(text)


def _text(root: ET.Element, name: str) -> str | None:
    child = root.find(name)
    return None if child is None else (child.text or "").strip()


def _rotor(root: ET.Element) -> str:
    name = _text(root, "rotor")
    if not name:
        raise N1MMRotorError("missing_field", "rotor command without a <rotor> name")
    if len(name) > MAX_NAME or not name.isprintable():
        raise N1MMRotorError("bad_value", f"<rotor> {name[:MAX_NAME]!r} is not a rotor name")
    return name


def _band(root: ET.Element) -> float | None:
    text = _text(root, "freqband")
    if not text:
        return None
    try:
        return _decimal(text, "freqband")
    except N1MMRotorError:
        return None  # informative only


def parse_rotor_command(data: bytes) -> RotorCommand:
    """Read one datagram; raise :class:`N1MMRotorError` when it is not a usable command."""
    if len(data) > MAX_PACKET_BYTES:
        raise N1MMRotorError(
            "too_large", f"packet of {len(data)} bytes is over the {MAX_PACKET_BYTES}-byte limit")
    text = data.decode("utf-8", errors="replace").lstrip("\ufeff")
    if "<!DOCTYPE" in text:
        raise N1MMRotorError("doctype", "refused a document type declaration: rotor commands "
                                        "never have one and it could declare entities")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise N1MMRotorError("not_xml", f"not XML: {exc}") from None
    if root.tag != "N1MMRotor":
        raise N1MMRotorError("not_rotor", f"<{str(root.tag)[:40]}> packet is not N1MMRotor")
    stop = root.find("stop")
    if stop is not None:
        return RotorStop(_rotor(stop), _band(stop))
    rotor = _rotor(root)
    azimuth_text = _text(root, "goazi")
    if not azimuth_text:
        raise N1MMRotorError("missing_field", f"rotor command for {rotor!r} without <goazi>")
    azimuth = _decimal(azimuth_text, "goazi")
    if not -360.0 <= azimuth <= 720.0:
        raise N1MMRotorError("bad_value", f"<goazi>{azimuth_text}</goazi> is not a heading")
    offset_text = _text(root, "offset")
    offset = 0.0
    if offset_text:
        offset = _decimal(offset_text, "offset")
    return RotorTurn(rotor, azimuth % 360.0, offset, _text(root, "bidirectional") == "1",
                     _band(root))


def heading_report(rotor: str, heading: float) -> bytes:
    """What N1MM's rotor window shows: ``name @ tenths`` (``TH6 @ 1460`` is 146.0 degrees)."""
    if not math.isfinite(heading):
        raise ValueError(f"heading {heading} is not a number of degrees")
    return f"{rotor} @ {round((heading % 360.0) * 10) % 3600}".encode()


def turn_command(rotor: str, azimuth: float, band_mhz: float = 14.0) -> bytes:
    """A turn command as N1MM sends it (one line, no declaration): the fake N1MM of the tests."""
    return (f"<N1MMRotor><rotor>{_escape(rotor)}</rotor><goazi>{azimuth:.1f}</goazi>"
            f"<offset>0.0</offset><bidirectional>0</bidirectional>"
            f"<freqband>{band_mhz:.1f}</freqband></N1MMRotor>").encode()


def stop_command(rotor: str, band_mhz: float = 14.0) -> bytes:
    return (f"<N1MMRotor><stop><rotor>{_escape(rotor)}</rotor>"
            f"<freqband>{band_mhz:.1f}</freqband></stop></N1MMRotor>").encode()


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


__all__ = [
    "DEFAULT_COMMAND_PORT", "DEFAULT_HEADING_PORT", "MAX_PACKET_BYTES", "REASONS",
    "N1MMRotorError", "RotorCommand", "RotorStop", "RotorTurn", "heading_report",
    "parse_rotor_command", "stop_command", "turn_command",
]
