"""The RadioInfo parser: N1MM's documented packets, its 10 Hz unit, and every kind of bad datagram."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from moas_gui.errors import ProtocolError
from moas_gui.sources import n1mm_packet
from moas_gui.sources.n1mm_packet import (
    MAX_PACKET_BYTES,
    REASONS,
    N1MMPacketError,
    RadioInfo,
    parse_radio_info,
    radio_info_packet,
)

# The three sample packets of shared/specs/logger-network.md 1.8, byte for byte in form.
SINGLE_RADIO_80M = b"""<?xml version="1.0" encoding="utf-8"?>
<RadioInfo>
\t<app>N1MM</app>
\t<StationName>CW-80m</StationName>
\t<RadioNr>1</RadioNr>
\t<Freq>352211</Freq>
\t<TXFreq>352211</TXFreq>
\t<Mode>CW</Mode>
\t<OpCall>W1ABC</OpCall>
\t<IsRunning>False</IsRunning>
\t<FocusEntry>204626</FocusEntry>
\t<EntryWindowHwnd>275678</EntryWindowHwnd>
\t<Antenna>8</Antenna>
\t<Rotors></Rotors>
\t<FocusRadioNr>1</FocusRadioNr>
\t<IsStereo>False</IsStereo>
\t<IsSplit>False</IsSplit>
\t<ActiveRadioNr>1</ActiveRadioNr>
\t<IsTransmitting>False</IsTransmitting>
\t<FunctionKeyCaption></FunctionKeyCaption>
\t<RadioName></RadioName>
\t<AuxAntSelected>-1</AuxAntSelected>
\t<AuxAntSelectedName></AuxAntSelectedName>
\t<IsConnected></IsConnected>
</RadioInfo>
"""

SO2R_RADIO2_SPLIT_TRANSMITTING = b"""<?xml version="1.0" encoding="utf-8"?>
<RadioInfo>
\t<app>N1MM</app>
\t<StationName>SO2R-PC</StationName>
\t<RadioNr>2</RadioNr>
\t<Freq>2102500</Freq>
\t<TXFreq>2102800</TXFreq>
\t<Mode>CW</Mode>
\t<OpCall>K1ABC</OpCall>
\t<IsRunning>True</IsRunning>
\t<FocusEntry>264342</FocusEntry>
\t<EntryWindowHwnd>264342</EntryWindowHwnd>
\t<Antenna>3</Antenna>
\t<Rotors>TH6</Rotors>
\t<FocusRadioNr>1</FocusRadioNr>
\t<IsStereo>True</IsStereo>
\t<IsSplit>True</IsSplit>
\t<ActiveRadioNr>2</ActiveRadioNr>
\t<IsTransmitting>True</IsTransmitting>
\t<FunctionKeyCaption>F1 CQ</FunctionKeyCaption>
\t<RadioName>IC-7610</RadioName>
\t<AuxAntSelected>-1</AuxAntSelected>
\t<AuxAntSelectedName></AuxAntSelectedName>
\t<IsConnected>True</IsConnected>
</RadioInfo>
"""

MANUAL_RADIO_20M = b"""<?xml version="1.0" encoding="utf-8"?>
<RadioInfo>
\t<app>N1MM</app>
\t<StationName>STATION1</StationName>
\t<RadioNr>1</RadioNr>
\t<Freq>1405946</Freq>
\t<TXFreq>1405946</TXFreq>
\t<Mode>USB</Mode>
\t<Antenna>-1</Antenna>
\t<Rotors>-1</Rotors>
\t<IsSplit>False</IsSplit>
\t<ActiveRadioNr>1</ActiveRadioNr>
\t<IsTransmitting>False</IsTransmitting>
\t<RadioName>Manual</RadioName>
\t<AuxAntSelected>1</AuxAntSelected>
\t<AuxAntSelectedName>OCF</AuxAntSelectedName>
\t<IsConnected>False</IsConnected>
</RadioInfo>
"""


def packet(*elements: str, root: str = "RadioInfo") -> bytes:
    body = "".join(elements)
    return f'<?xml version="1.0" encoding="utf-8"?><{root}>{body}</{root}>'.encode()


def refused(data: bytes) -> str:
    with pytest.raises(N1MMPacketError) as caught:
        parse_radio_info(data)
    assert str(caught.value), "every refusal says what was wrong"
    return caught.value.reason


def test_documented_single_radio_packet_reads_as_3522_11_khz_idle() -> None:
    info = parse_radio_info(SINGLE_RADIO_80M)
    assert info == RadioInfo(
        radio_nr=1, khz=3522.11, tx_khz=3522.11, station_name="CW-80m", app="N1MM", mode="CW",
        is_split=False, is_transmitting=False, is_connected=None, is_running=False, active_radio_nr=1,
        focus_radio_nr=1, antenna=8, radio_name="")


def test_so2r_split_packet_gives_radio_2_its_own_tx_frequency_and_transmit_state() -> None:
    info = parse_radio_info(SO2R_RADIO2_SPLIT_TRANSMITTING)
    assert (info.radio_nr, info.khz, info.tx_khz) == (2, 21025.0, 21028.0)
    assert info.is_split is True and info.is_transmitting is True and info.is_running is True
    assert (info.active_radio_nr, info.focus_radio_nr) == (2, 1)
    assert info.is_connected is True and info.radio_name == "IC-7610"


def test_manual_radio_packet_keeps_its_frequency_and_says_not_connected() -> None:
    info = parse_radio_info(MANUAL_RADIO_20M)
    assert info.khz == 14059.46 and info.tx_khz == 14059.46
    assert info.is_connected is False and info.antenna == -1 and info.radio_name == "Manual"


def test_frequency_is_read_in_units_of_10_hz() -> None:
    info = parse_radio_info(packet("<RadioNr>1</RadioNr>", "<Freq>1420000</Freq>"))
    assert info.khz == 14200.0


def test_missing_or_zero_tx_frequency_means_transmitting_on_the_receive_frequency() -> None:
    missing = parse_radio_info(packet("<RadioNr>1</RadioNr>", "<Freq>702500</Freq>"))
    zero = parse_radio_info(packet("<RadioNr>1</RadioNr>", "<Freq>702500</Freq>",
                                   "<TXFreq>0</TXFreq>"))
    assert missing.tx_khz == zero.tx_khz == 7025.0


def test_zero_frequency_means_the_logger_has_none_for_that_radio() -> None:
    info = parse_radio_info(packet("<RadioNr>2</RadioNr>", "<Freq>0</Freq>",
                                   "<TXFreq>0</TXFreq>"))
    assert info.radio_nr == 2 and info.khz is None and info.tx_khz is None


def test_unknown_elements_are_ignored_and_names_are_case_sensitive() -> None:
    info = parse_radio_info(packet(
        "<uNICORNbLOOD>yes</uNICORNbLOOD>", "<RadioNr>1</RadioNr>", "<Freq>1800000</Freq>",
        "<txfreq>1900000</txfreq>", "<istransmitting>True</istransmitting>"))
    assert info.tx_khz == 18000.0
    assert info.is_transmitting is None


def test_windows_1252_bytes_in_text_do_not_spoil_the_packet() -> None:
    data = SINGLE_RADIO_80M.replace(b"<OpCall>W1ABC", b"<OpCall>J\xf6rg \x93W1ABC\x94")
    data = data.replace(b"<StationName>CW-80m", b"<StationName>K\xf6ln")
    info = parse_radio_info(data)
    assert info.khz == 3522.11
    assert info.station_name == "K\ufffdln"


def test_byte_order_mark_and_whitespace_around_numbers_are_accepted() -> None:
    data = b"\xef\xbb\xbf" + packet("<RadioNr> 1 </RadioNr>", "<Freq>\r\n 1400000\t</Freq>")
    assert parse_radio_info(data).khz == 14000.0


def test_informative_fields_that_are_garbage_read_as_unknown() -> None:
    info = parse_radio_info(packet("<RadioNr>1</RadioNr>", "<Freq>1400000</Freq>",
                                   "<ActiveRadioNr>two</ActiveRadioNr>", "<IsSplit>maybe</IsSplit>"))
    assert info.active_radio_nr is None and info.is_split is None and info.khz == 14000.0


def test_other_n1mm_packet_types_are_refused_as_not_ours() -> None:
    contact = packet("<rxfreq>1420000</rxfreq>", "<call>W1AW</call>", root="contactinfo")
    assert refused(contact) == "not_radio_info"
    assert refused(packet("<program>N1MM</program>", root="AppInfo")) == "not_radio_info"


@pytest.mark.parametrize("data", [
    b"", b"\x00\xff\xfe garbage", b"<RadioInfo><RadioNr>1</RadioNr>",
    b"RadioNr=1 Freq=1400000", b"<RadioInfo></RadioInf>", b"<a/><b/>",
])
def test_what_is_not_xml_is_refused(data: bytes) -> None:
    assert refused(data) == "not_xml"


def test_entity_declarations_are_refused_before_anything_expands() -> None:
    laughs = (b'<?xml version="1.0"?><!DOCTYPE RadioInfo [<!ENTITY a "aaaaaaaaaa">'
              b'<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;">]>'
              b"<RadioInfo><RadioNr>1</RadioNr><Freq>&c;</Freq></RadioInfo>")
    assert refused(laughs) == "doctype"
    external = (b'<?xml version="1.0"?><!DOCTYPE RadioInfo SYSTEM "file:///etc/passwd">'
                b"<RadioInfo><RadioNr>1</RadioNr><Freq>1400000</Freq></RadioInfo>")
    assert refused(external) == "doctype"


def test_disguised_document_type_declarations_never_reach_an_entity() -> None:
    lowercase = b'<!doctype a [<!ENTITY x "y">]><RadioInfo><RadioNr>1</RadioNr><Freq>&x;</Freq></RadioInfo>'
    utf16 = '<?xml version="1.0" encoding="utf-16"?><!DOCTYPE a [<!ENTITY x "1400000">]>' \
            "<RadioInfo><RadioNr>1</RadioNr><Freq>&x;</Freq></RadioInfo>"
    assert refused(lowercase) == "not_xml"
    assert refused(utf16.encode("utf-16")) == "not_xml"


def test_packets_over_the_size_limit_are_refused_unread() -> None:
    filler = "<Pad>" + "x" * MAX_PACKET_BYTES + "</Pad>"
    assert refused(packet("<RadioNr>1</RadioNr>", "<Freq>1400000</Freq>", filler)) == "too_large"


@pytest.mark.parametrize("elements", [
    ("<Freq>1400000</Freq>",),
    ("<RadioNr>1</RadioNr>",),
    ("<radionr>1</radionr>", "<Freq>1400000</Freq>"),
])
def test_a_radio_info_without_radio_number_or_frequency_is_refused(elements: tuple[str, ...]) -> None:
    assert refused(packet(*elements)) == "missing_field"


@pytest.mark.parametrize("radio_nr, freq", [
    ("0", "1400000"), ("100", "1400000"), ("one", "1400000"), ("", "1400000"),
    ("1", "-1400000"), ("1", "14.2"), ("1", "30000000001"), ("1", "9" * 400), ("1", "1e7"),
    ("1", "30000000000"), ("1", "1_402_500"), ("1", "+1402500"), ("1", "\u0661\u0664\u0660\u0662"),
    ("1", "\uff11\uff14\uff10\uff10\uff10\uff10\uff10"), ("+1", "1400000"), ("\u0661", "1400000"),
    ("1_0", "1400000"), ("1", "1400000 1"),
])
def test_absurd_numbers_are_refused(radio_nr: str, freq: str) -> None:
    assert refused(packet(f"<RadioNr>{radio_nr}</RadioNr>", f"<Freq>{freq}</Freq>")) == "bad_value"


def test_the_highest_frequency_below_300_ghz_is_read() -> None:
    info = parse_radio_info(packet("<RadioNr>1</RadioNr>", "<Freq>29999999999</Freq>"))
    assert info.khz == 299_999_999.99


def test_an_absurd_tx_frequency_refuses_the_packet_rather_than_guess() -> None:
    data = packet("<RadioNr>1</RadioNr>", "<Freq>1400000</Freq>", "<TXFreq>-5</TXFreq>")
    assert refused(data) == "bad_value"


def test_every_refusal_is_a_protocol_error_with_a_known_reason() -> None:
    assert issubclass(N1MMPacketError, ProtocolError)
    assert set(REASONS) == {"too_large", "not_xml", "doctype", "not_radio_info",
                            "missing_field", "bad_value", "bad_date"}


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=300))
def test_random_bytes_are_refused_never_crash(data: bytes) -> None:
    try:
        parse_radio_info(data)
    except N1MMPacketError as exc:
        assert exc.reason in REASONS


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 2), st.integers(1, 29_999_999_999), st.integers(1, 29_999_999_999),
       st.booleans(),
       st.text(st.characters(min_codepoint=32, max_codepoint=0xFFFD, exclude_categories=("Cs",)),
               max_size=15))
def test_packets_written_like_n1mm_read_back_the_same(
    radio_nr: int, freq: int, tx: int, transmitting: bool, name: str
) -> None:
    data = radio_info_packet(radio_nr, freq / 100, tx / 100, station_name=name,
                             is_transmitting=transmitting)
    info = parse_radio_info(data)
    assert (info.radio_nr, info.khz, info.tx_khz) == (radio_nr, freq / 100, tx / 100)
    assert info.is_transmitting is transmitting and info.is_split is (freq != tx)
    assert info.station_name == name.strip()


def test_the_value_is_frozen_and_the_public_names_do_not_drift() -> None:
    info = parse_radio_info(SINGLE_RADIO_80M)
    with pytest.raises(dataclasses.FrozenInstanceError):
        info.khz = 7000.0  # type: ignore[misc]
    assert sorted(n1mm_packet.__all__) == sorted([
        "MAX_KHZ", "MAX_PACKET_BYTES", "MAX_RADIO_NR", "N1MMPacketError", "REASONS", "RadioInfo",
        "parse_radio_info", "radio_info_packet"])


# -- the flat scanner: N1MM's own shape read without the XML parser, the same fields ------

def xml_fields(data: bytes) -> dict[str, str] | None:
    """What the XML parser makes of ``data``: its fields when it is a RadioInfo
    document, None when the parser refuses it or its root is another."""
    try:
        root = n1mm_packet._parse_xml(data)
    except N1MMPacketError:
        return None
    return n1mm_packet._fields(root) if root.tag == "RadioInfo" else None


@pytest.mark.parametrize("data", [
    SINGLE_RADIO_80M, SO2R_RADIO2_SPLIT_TRANSMITTING, MANUAL_RADIO_20M,
    radio_info_packet(2, 14025.0, 14030.0, station_name="SO2R PC", is_transmitting=True),
    b"\xef\xbb\xbf" + radio_info_packet(1, 3522.11),
    b"<RadioInfo><RadioNr>1</RadioNr><Freq>352211</Freq><RadioName/><Mode /></RadioInfo>\n",
])
def test_packets_of_n1mms_own_shape_are_read_without_the_xml_parser(data: bytes) -> None:
    flat = n1mm_packet._flat_fields(data)
    assert flat is not None, "N1MM's packet takes the scanner, not the XML parser"
    assert flat == xml_fields(data)


@pytest.mark.parametrize("data", [
    b' <?xml version="1.0"?><RadioInfo><RadioNr>1</RadioNr></RadioInfo>',  # not at the start
    b"<RadioInfo><Freq>1&#52;</Freq></RadioInfo>",                      # a reference
    b"<RadioInfo><Freq>1]]>4</Freq></RadioInfo>",                        # never in text
    b"<RadioInfo><Freq>14\r\n00</Freq></RadioInfo>",                     # line ends normalised
    b"<RadioInfo><Freq>1\x014</Freq></RadioInfo>",                       # a control character
    b"<RadioInfo><Freq>14</freq></RadioInfo>",                           # end tag of another
    b"<RadioInfo><a:Freq>14</a:Freq></RadioInfo>",                       # a prefix
    b'<RadioInfo v="1"><Freq>14</Freq></RadioInfo>',                     # an attribute
    b"<RadioInfo><Freq>14</Freq>tail</RadioInfo>",                       # text beside elements
    b"<RadioInfo><Freq><x/>14</Freq></RadioInfo>",                       # a second level
    b"<RadioInfo><!-- c --><Freq>14</Freq></RadioInfo>",                 # a comment
    b"<RadioInfo><Freq>14</Freq></RadioInfo><RadioInfo/>",               # two roots
    b"<contactinfo><Freq>14</Freq></contactinfo>",                       # another message
])
def test_anything_else_goes_to_the_xml_parser(data: bytes) -> None:
    assert n1mm_packet._flat_fields(data) is None


DECLARATIONS = ["", '<?xml version="1.0" encoding="utf-8"?>', '<?xml version="1.0"?>',
                '<?xml version="1.0" encoding="UTF-8"?>', '<?xml version="1.1"?>',
                '<?xml version="1.0" encoding="latin-1"?>', " <?xml version=\"1.0\"?>"]
ROOTS = ["<RadioInfo>", "<RadioInfo >", "<radioinfo>", '<RadioInfo a="1">', "<contactinfo>"]
NAMES = ["RadioNr", "Freq", "TXFreq", "_x.y-z", "a:Freq", "1x", "xml", "Freq "]
SPACES = ["", " ", "\t", "\n", "\r\n", "x", "<!-- -->"]
TEXTS = ["1", "14", " 7 ", "1\r4", "\x0b", "&amp;", "&#x41;", "&bogus;", ">", "]]>", "\r", "\t", "\x01", "\x7f",
         "\x85", "\u00e9", "\ufffe", "\U0001f600", "\xa0", "<![CDATA[1]]>", "<x/>", "True",
         "-1", '"', "'", "="]


@st.composite
def nearly_flat(draw: st.DrawFn) -> bytes:
    """Documents of N1MM's shape with a piece changed here and there: in the scanner's
    reach, and just outside it."""
    def element() -> str:
        name = draw(st.sampled_from(NAMES))
        if draw(st.integers(0, 5)) == 0:
            return f"<{name}{draw(st.sampled_from(['/>', ' />', ' / >']))}"
        text = "".join(draw(st.lists(st.sampled_from(TEXTS), max_size=4)))
        end = name if draw(st.integers(0, 7)) else draw(st.sampled_from(NAMES))
        return f"<{name}>{text}</{end}>"
    children = "".join(draw(st.sampled_from(SPACES)) + element()
                       for _ in range(draw(st.integers(0, 6))))
    root = draw(st.sampled_from(ROOTS))
    end = "</" + root[1:].split()[0].rstrip(">") + ">"
    return (draw(st.sampled_from(DECLARATIONS)) + draw(st.sampled_from(SPACES)) + root
            + children + draw(st.sampled_from(SPACES)) + end
            + draw(st.sampled_from(SPACES))).encode()


@settings(max_examples=250, deadline=None)
@given(nearly_flat())
def test_the_scanner_never_reads_what_the_xml_parser_would_read_otherwise(data: bytes) -> None:
    """Whatever the scanner accepts, the XML parser reads as the same RadioInfo fields; so
    a packet it does not accept takes the parser's path as before, and every refusal and
    its reason stay the parser's."""
    flat = n1mm_packet._flat_fields(data)
    if flat is not None:
        assert flat == xml_fields(data)
