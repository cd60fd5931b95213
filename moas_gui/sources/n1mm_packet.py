"""N1MM Logger+ ``<RadioInfo>`` packets: bytes in, a frozen :class:`RadioInfo` out.

Sans-IO: no sockets, no clock.  :func:`parse_radio_info` takes the bytes of one
UDP datagram and returns what the packet says about one radio, or raises
:class:`N1MMPacketError` whose :attr:`~N1MMPacketError.reason` says which kind
of bad packet it was (the listener counts them by reason)::

    ProtocolError (moas_gui.errors)
     +-- N1MMPacketError  reason: too_large | not_xml | doctype | not_radio_info
                                  | missing_field | bad_value

Facts the parser relies on (``shared/specs/logger-network.md`` section 1):

- one XML document per datagram; the root element names the message.  Only
  ``RadioInfo`` is ours; ``contactinfo``, ``AppInfo``, ``spot`` and the others
  are refused with reason ``not_radio_info`` (not an error of the sender);
- element names are case-sensitive; unknown elements are ignored, missing
  optional ones tolerated; only ``RadioNr`` and ``Freq`` are required;
- ``Freq`` and ``TXFreq`` are integers in units of 10 Hz (``1420000`` is
  14,200.00 kHz), written in ASCII digits and nothing else; 300 GHz and above
  is refused as absurd; :class:`RadioInfo` holds kHz;
- booleans are ``True``/``False``; an empty element means "unknown" (``None``);
- text may hold Windows-1252 bytes although the declaration says UTF-8, so the
  bytes are decoded as UTF-8 with replacement characters.

Safety: a document type declaration is refused before any entity in it is
read (no entity expansion of any kind), and packets over
:data:`MAX_PACKET_BYTES` are refused without being parsed.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Final

from moas_gui.errors import ProtocolError
from moas_gui.sources.base import MAX_KHZ

MAX_PACKET_BYTES: Final = 16 * 1024
"""A real RadioInfo packet is about 900 bytes; anything over 16 KiB is refused unread."""


_DIGITS: Final = re.compile(r"[0-9]{1,20}")
_SIGNED: Final = re.compile(r"-?[0-9]{1,20}")
"""How N1MM writes a number: ASCII digits alone (no sign, no ``_``, no other
script's digits, all of which Python's ``int`` would read)."""

MAX_RADIO_NR: Final = 99
"""N1MM sends 1 or 2; the parser accepts 1-99 and leaves the mapping to the listener."""

REASONS: Final = (
    "too_large", "not_xml", "doctype", "not_radio_info", "missing_field", "bad_value",
    "bad_date",
)
"""Every value :attr:`N1MMPacketError.reason` can take."""


class N1MMPacketError(ProtocolError):
    """A datagram that is not a usable RadioInfo packet; :attr:`reason` is one of :data:`REASONS`."""

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


@dataclass(frozen=True, slots=True)
class RadioInfo:
    """What one RadioInfo packet says about one radio.

    ``khz`` is the receive frequency, ``tx_khz`` the transmit frequency
    (``TXFreq``; equal to ``khz`` when the packet has no usable ``TXFreq``).
    ``khz`` is ``None`` when the logger has no frequency for the radio
    (``Freq`` of 0, as a logger without a CAT connection may send).
    Booleans are ``None`` when the packet leaves them empty or out.
    """

    radio_nr: int
    khz: float | None
    tx_khz: float | None
    station_name: str = ""
    app: str = ""
    mode: str = ""
    is_split: bool | None = None
    is_transmitting: bool | None = None
    is_connected: bool | None = None
    is_running: bool | None = None
    """Run (calling CQ) rather than search and pounce."""
    active_radio_nr: int | None = None
    """Transmit focus: the radio that will transmit next (the same in every radio's packet)."""
    focus_radio_nr: int | None = None
    """Receive focus: the radio the operator listens to."""
    antenna: int | None = None
    """The row of N1MM's own Antennas table; unrelated to this server's antenna IDs."""
    radio_name: str = ""


def _decode(data: bytes) -> str:
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    return data.decode("utf-8", errors="replace")


def _parse_xml(data: bytes) -> ET.Element:
    text = _decode(data)
    # Entities can only be declared inside a document type declaration, and the
    # text is already decoded (no declared encoding can disguise the keyword),
    # so refusing "<!DOCTYPE" refuses every entity before the parser sees it.
    start = text.find("<!DOCTYPE")
    if start >= 0:
        raise N1MMPacketError(
            "doctype", f"refused a document type declaration ({text[start:start + 30]!r}...): "
                       "N1MM packets never have one and it could declare entities")
    try:
        root: ET.Element = ET.fromstring(text)
    except ET.ParseError as exc:
        raise N1MMPacketError("not_xml", f"not XML: {exc}") from None
    return root


_SPACE: Final = r"[ \t\n\r]*"
_TEXT: Final = r"[^<>&\x00-\x1f\x7f-\x9f\ufffe\uffff]*"
"""Character data the scanner takes as it stands: no markup, no reference, no control
character (a tab, a line end or a C1 control inside a value sends the packet to the
XML parser, which normalises or refuses them), no ``>`` (so never ``]]>``)."""
_NAME: Final = r"[A-Za-z_][A-Za-z0-9_.-]*"
_FLAT: Final = re.compile(
    rf'(?:<\?xml version="1\.0"(?: encoding="(?:utf|UTF)-8")?\?>)?{_SPACE}<RadioInfo>'
    rf"((?:{_SPACE}<({_NAME})(?:>{_TEXT}</\2>|{_SPACE}/>))*){_SPACE}</RadioInfo>{_SPACE}")
"""A whole packet of N1MM's flat shape: its declaration (only at the very start, as XML
wants it), the root, and elements of plain text or empty, each end tag matching its
start tag; group 1 is the elements."""
_CHILD: Final = re.compile(rf"<({_NAME})(?:>({_TEXT})<|{_SPACE}/>)")
"""An element's name and text, in what :data:`_FLAT` matched (an end tag never matches:
``/`` starts no name)."""


def _flat_fields(data: bytes) -> dict[str, str] | None:
    """The fields of a packet of exactly N1MM's flat shape (:data:`_FLAT`), read
    without an XML parser; ``None`` for anything else, which :func:`_parse_xml` then
    reads or refuses with its reason.  What it returns is what :func:`_fields` gives
    for the same packet (the first of a repeated name wins, the text stripped); the
    XML parser costs a packet three times as much, more when the caches are cold."""
    whole = _FLAT.fullmatch(_decode(data))
    if whole is None:
        return None
    return {name: text.strip() for name, text in reversed(_CHILD.findall(whole.group(1)))}


def _fields(root: ET.Element) -> dict[str, str]:
    """The text of each direct child; the first wins when a name repeats."""
    fields: dict[str, str] = {}
    for child in root:
        if isinstance(child.tag, str) and child.tag not in fields:
            fields[child.tag] = (child.text or "").strip()
    return fields


def _int(fields: dict[str, str], name: str, *, signed: bool = False) -> int | None:
    """The integer in element ``name``; ``None`` when absent or empty.  Only
    ``signed`` ones may start with ``-`` (N1MM writes ``<Antenna>-1</Antenna>``)."""
    text = fields.get(name, "")
    if not text:
        return None
    if len(text) > 20:
        raise N1MMPacketError("bad_value", f"<{name}> is too long to be a number: {text[:20]!r}...")
    if (_SIGNED if signed else _DIGITS).fullmatch(text) is None:
        raise N1MMPacketError(
            "bad_value", f"<{name}> is not a whole number written in digits 0-9: {text!r}")
    return int(text)


def _khz(fields: dict[str, str], name: str) -> float | None:
    """``name`` in 10 Hz units as kHz; ``None`` when absent, empty or 0."""
    units = _int(fields, name)
    if units is None or units == 0:
        return None
    khz = units / 100.0
    if khz >= MAX_KHZ:
        raise N1MMPacketError(
            "bad_value", f"<{name}>{fields[name]}</{name}> is {khz:,.2f} kHz, not a radio frequency")
    return khz


def _bool(fields: dict[str, str], name: str) -> bool | None:
    text = fields.get(name, "").lower()
    if text in ("true", "1"):
        return True
    if text in ("false", "0"):
        return False
    return None


def parse_radio_info(data: bytes) -> RadioInfo:
    """Read one datagram; raise :class:`N1MMPacketError` when it is not a usable RadioInfo."""
    if len(data) > MAX_PACKET_BYTES:
        raise N1MMPacketError(
            "too_large", f"packet of {len(data)} bytes is over the {MAX_PACKET_BYTES}-byte limit")
    fields = _flat_fields(data)
    if fields is None:  # not N1MM's own flat shape: the XML parser reads it, or says why not
        root = _parse_xml(data)
        if root.tag != "RadioInfo":
            raise N1MMPacketError("not_radio_info",
                                  f"<{str(root.tag)[:40]}> packet is not RadioInfo")
        fields = _fields(root)
    for name in ("RadioNr", "Freq"):
        if name not in fields:
            raise N1MMPacketError("missing_field", f"RadioInfo without <{name}>")
    radio_nr = _int(fields, "RadioNr")
    if radio_nr is None or not 1 <= radio_nr <= MAX_RADIO_NR:
        raise N1MMPacketError(
            "bad_value", f"<RadioNr>{fields['RadioNr']}</RadioNr> is not a radio number 1-{MAX_RADIO_NR}")
    khz = _khz(fields, "Freq")
    tx_khz = _khz(fields, "TXFreq") if khz is not None else None
    if khz is not None and tx_khz is None:
        tx_khz = khz
    return RadioInfo(
        radio_nr=radio_nr,
        khz=khz,
        tx_khz=tx_khz,
        station_name=fields.get("StationName", ""),
        app=fields.get("app", ""),
        mode=fields.get("Mode", ""),
        is_split=_bool(fields, "IsSplit"),
        is_transmitting=_bool(fields, "IsTransmitting"),
        is_connected=_bool(fields, "IsConnected"),
        is_running=_bool(fields, "IsRunning"),
        active_radio_nr=_optional_int(fields, "ActiveRadioNr"),
        focus_radio_nr=_optional_int(fields, "FocusRadioNr"),
        antenna=_optional_int(fields, "Antenna"),
        radio_name=fields.get("RadioName", ""),
    )


def _optional_int(fields: dict[str, str], name: str) -> int | None:
    """An informative integer: a bad one is read as unknown rather than refusing the packet."""
    try:
        return _int(fields, name, signed=True)
    except N1MMPacketError:
        return None


def radio_info_packet(
    radio_nr: int,
    khz: float,
    tx_khz: float | None = None,
    *,
    station_name: str = "STATION1",
    is_transmitting: bool = False,
    active_radio_nr: int | None = None,
    focus_radio_nr: int | None = None,
    is_running: bool = False,
    mode: str = "CW",
    app: str = "N1MM",
) -> bytes:
    """A RadioInfo datagram as N1MM Logger+ (and not1mm, DXLog.net) write it (the fake logger used by tests and
    benchmarks, and a way to feed the server by hand)."""
    tx = khz if tx_khz is None else tx_khz
    active = radio_nr if active_radio_nr is None else active_radio_nr
    focus = active if focus_radio_nr is None else focus_radio_nr
    lines = [
        '<?xml version="1.0" encoding="utf-8"?>',
        "<RadioInfo>",
        f"\t<app>{_escape(app)}</app>",
        f"\t<StationName>{_escape(station_name)}</StationName>",
        f"\t<RadioNr>{radio_nr}</RadioNr>",
        f"\t<Freq>{round(khz * 100)}</Freq>",
        f"\t<TXFreq>{round(tx * 100)}</TXFreq>",
        f"\t<Mode>{_escape(mode)}</Mode>",
        "\t<OpCall></OpCall>",
        f"\t<IsRunning>{is_running}</IsRunning>",
        "\t<Antenna>0</Antenna>",
        f"\t<FocusRadioNr>{focus}</FocusRadioNr>",
        f"\t<IsSplit>{tx != khz}</IsSplit>",
        f"\t<ActiveRadioNr>{active}</ActiveRadioNr>",
        f"\t<IsTransmitting>{is_transmitting}</IsTransmitting>",
        "\t<FunctionKeyCaption></FunctionKeyCaption>",
        "\t<RadioName></RadioName>",
        "\t<AuxAntSelected>-1</AuxAntSelected>",
        "\t<AuxAntSelectedName></AuxAntSelectedName>",
        "\t<IsConnected>True</IsConnected>",
        "</RadioInfo>",
    ]
    return ("\r\n".join(lines) + "\r\n").encode("utf-8")


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


__all__ = [
    "MAX_KHZ",
    "MAX_PACKET_BYTES",
    "MAX_RADIO_NR",
    "REASONS",
    "N1MMPacketError",
    "RadioInfo",
    "parse_radio_info",
    "radio_info_packet",
]
