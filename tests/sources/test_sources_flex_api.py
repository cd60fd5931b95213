"""The FlexRadio API's lines, statuses, slice map and discovery datagrams, sans IO."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from moas_gui.sources.flex_api import (
    OPENING,
    FlexLineError,
    FlexRadioState,
    FlexReply,
    FlexStatus,
    Handle,
    LineSplitter,
    Message,
    Slice,
    SliceMap,
    Version,
    command,
    parse_discovery,
    parse_line,
    parse_slice_map,
)
from moas_gui.testing.flex_radio import discovery_datagram


def status(text: str) -> FlexStatus:
    line = parse_line(text)
    assert isinstance(line, FlexStatus)
    return line


def test_the_greeting_and_answers_are_read() -> None:
    assert parse_line("V1.4.0.0") == Version("1.4.0.0")
    assert parse_line("H5A1B2C3D") == Handle(0x5A1B2C3D)
    assert parse_line("R12|0|") == FlexReply(12, 0, "")
    reply = parse_line("R3|50000016|Malformed command")
    assert isinstance(reply, FlexReply) and reply.code == 0x50000016 and not reply.ok
    assert parse_line("M10000001|Client connected") == Message(0x10000001, "Client connected")


def test_a_status_line_gives_its_words_and_fields() -> None:
    s = status("S5A1B2C3D|slice 0 in_use=1 RF_frequency=14.025000 mode=CW tx=1")
    assert s.handle == 0x5A1B2C3D
    assert s.words[:2] == ("slice", "0")
    assert s.fields["RF_frequency"] == "14.025000" and s.fields["tx"] == "1"


@pytest.mark.parametrize("line, reason", [
    ("", "empty"),
    ("SSH-2.0-OpenSSH_9.6", "bad_status"),
    ("HTTP/1.1 200 OK", "bad_number"),
    ("Rx|0|", "bad_reply"),
    ("S12 slice 0", "bad_status"),
    ("Szz|slice 0", "bad_number"),
    ("hello", "not_flex"),
])
def test_what_is_not_the_api_is_refused_by_name(line: str, reason: str) -> None:
    with pytest.raises(FlexLineError) as caught:
        parse_line(line)
    assert caught.value.reason == reason


def test_lines_are_split_and_an_over_long_one_is_dropped_whole() -> None:
    splitter = LineSplitter(limit=32)
    assert splitter.feed(b"V1.4.0.0\r\nH12") == (["V1.4.0.0"], 0)
    assert splitter.feed(b"34\n") == (["H1234"], 0)
    assert splitter.feed(b"S1|" + b"x" * 40) == ([], 1)
    assert splitter.feed(b"y" * 40) == ([], 0)  # the same line, counted once
    assert splitter.feed(b"zz\nR1|0|\n") == (["R1|0|"], 0)


def test_commands_are_numbered_and_the_opening_changes_nothing() -> None:
    assert command(7, "sub slice all") == b"C7|sub slice all\n"
    assert OPENING[0] == "client program moas-gui"
    for text in OPENING:
        assert not text.startswith(("slice set", "client gui", "slice create", "xmit", "tx "))


def test_slices_and_the_interlock_are_followed() -> None:
    state = FlexRadioState()
    assert state.apply(status("S1|slice 0 in_use=1 RF_frequency=14.025000 mode=CW tx=1 "
                              "active=1 rxant=ANT1 txant=ANT2 index_letter=A "
                              "client_handle=0x1234ABCD"))
    s = state.slices[0]
    assert s == Slice(0, True, 14025.0, "CW", True, True, "A", "ANT1", "ANT2", 0x1234ABCD)
    assert not state.apply(status("S1|slice 0 RF_frequency=14.025000"))  # no change
    assert state.apply(status("S1|slice 0 RF_frequency=7.012500"))
    assert state.slices[0].khz == pytest.approx(7012.5)
    assert state.transmitting is None
    assert state.apply(status("S1|interlock tx_client_handle=0x1234ABCD state=TRANSMITTING "
                              "reason= source=SW"))
    assert state.transmitting is True
    state.apply(status("S1|interlock state=UNKEY_REQUESTED"))
    assert state.transmitting is True
    state.apply(status("S1|interlock state=READY"))
    assert state.transmitting is False
    assert state.apply(status("S1|slice 0 in_use=0"))
    assert state.slices[0] == Slice(0, letter="A")
    assert state.in_use() == []


@pytest.mark.parametrize("line, reason", [
    ("S1|slice 99 in_use=1", "bad_slice"),
    ("S1|slice x in_use=1", "bad_slice"),
    ("S1|slice 0 RF_frequency=14,025", "bad_frequency"),
    ("S1|slice 0 RF_frequency=400000000", "bad_frequency"),
    ("S1|slice 0 RF_frequency=", "bad_frequency"),
    ("S1|slice 0 client_handle=0xZZ", "bad_number"),
])
def test_a_slice_status_that_makes_no_sense_is_refused(line: str, reason: str) -> None:
    state = FlexRadioState()
    with pytest.raises(FlexLineError) as caught:
        state.apply(status(line))
    assert caught.value.reason == reason


def test_other_statuses_change_nothing() -> None:
    state = FlexRadioState()
    assert not state.apply(status("S1|radio slices=4 panadapters=4 lineout_gain=60"))
    assert not state.apply(status("S1|transmit freq=14.025 rfpower=100"))
    assert state.slices == {}


def _slices(*specs: tuple[int, str, float, bool]) -> list[Slice]:
    return [Slice(i, True, khz, tx=tx, letter=letter) for i, letter, khz, tx in specs]


def test_the_default_map_follows_the_transmitting_slice() -> None:
    m = SliceMap()
    slices = _slices((0, "A", 14025.0, True), (1, "B", 21025.0, False))
    assigned = m.assign(slices)
    assert assigned[(1, 1)].letter == "A" and assigned[(1, 2)].letter == "B"
    slices = _slices((0, "A", 14025.0, False), (1, "B", 21025.0, True))
    assigned = m.assign(slices)
    assert assigned[(1, 1)].letter == "B" and assigned[(1, 2)].letter == "A"
    assert m.assign(_slices((2, "C", 7000.0, True))) == {(1, 1): _slices((2, "C", 7000.0,
                                                                          True))[0]}
    assert m.assign([]) == {}
    assert SliceMap(second=None).radios() == [(1, 1)]


def test_a_map_by_letter_keeps_each_slice_on_its_radio() -> None:
    m = SliceMap(by_letter=parse_slice_map("a=1/1, B=2/1"))
    assert m.radios() == [(1, 1), (2, 1)]
    assigned = m.assign(_slices((0, "A", 14025.0, False), (1, "B", 21025.0, True),
                                (2, "C", 7000.0, False)))
    assert {ref: s.letter for ref, s in assigned.items()} == {(1, 1): "A", (2, 1): "B"}
    assert m.text() == "A=1/1,B=2/1"


@pytest.mark.parametrize("text", ["", "A", "A=1", "AB=1/1", "A=x/1", "A=1/1,A=1/2", "A=0/1"])
def test_a_wrong_slice_map_says_what_is_wrong(text: str) -> None:
    with pytest.raises(ValueError):
        parse_slice_map(text)


RADIO = {"discovery_protocol_version": "3.0.0.2", "model": "FLEX-6600",
         "serial": "1234-5678-9012-3456", "version": "3.4.35.141", "nickname": "Shack",
         "callsign": "W1AW", "ip": "192.168.1.50", "port": "4992", "status": "Available"}


def test_a_discovery_datagram_is_read_back() -> None:
    data = discovery_datagram(RADIO)
    assert data[:1] == b"\x38" and struct.unpack(">I", data[4:8])[0] == 0x800
    assert len(data) % 4 == 0 and struct.unpack(">H", data[2:4])[0] * 4 == len(data)
    found = parse_discovery(data)
    assert (found.model, found.serial, found.nickname, found.ip, found.port) == (
        "FLEX-6600", "1234-5678-9012-3456", "Shack", "192.168.1.50", 4992)
    assert found.matches("shack") and found.matches("1234-5678-9012-3456")
    assert found.matches("192.168.1.50") and not found.matches("other")
    assert found.label() == 'FLEX-6600 "Shack" (serial 1234-5678-9012-3456, 192.168.1.50:4992)'


def test_what_is_not_a_discovery_datagram_is_refused() -> None:
    good = discovery_datagram(RADIO)
    wrong_stream = good[:4] + struct.pack(">I", 0x801) + good[8:]
    wrong_class = good[:12] + struct.pack(">I", 0x534C8002) + good[16:]
    cases = {b"hello": "bad_size", b"\x18" + good[1:]: "not_vita",
             wrong_stream: "not_discovery", wrong_class: "not_discovery",
             discovery_datagram({"model": "X"}): "no_radio",
             good[:28] + b"ip=\xff\xfe": "not_ascii", good + b"\x00" * 4096: "bad_size"}
    for data, reason in cases.items():
        with pytest.raises(FlexLineError) as caught:
            parse_discovery(data)
        assert caught.value.reason == reason, data[:40]

STATUS_WORDS = st.sampled_from(["slice", "0", "7", "15", "99", "interlock", "in_use=1",
                                "in_use=0", "tx=1", "RF_frequency=14.025", "RF_frequency=x",
                                "state=TRANSMITTING", "state=", "client_handle=0xZ",
                                "index_letter=B", "removed", "=", "rxant=ANT2"])


@settings(max_examples=300, deadline=None)
@given(st.lists(st.one_of(st.text(max_size=40), st.lists(STATUS_WORDS, max_size=8).map(
    lambda words: "S1|" + " ".join(words))), max_size=20))
def test_any_line_is_read_or_refused_by_name_and_the_state_stays_bounded(
        lines: list[str]) -> None:
    state = FlexRadioState()
    for line in lines:
        try:
            parsed = parse_line(line)
            if isinstance(parsed, FlexStatus):
                state.apply(parsed)
        except FlexLineError as exc:
            assert exc.reason
    assert len(state.slices) <= 16
    assert sum(1 for s in state.in_use() if s.khz is not None and not 0 < s.khz < 3e8) == 0


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=200))
def test_any_datagram_is_read_or_refused_by_name(data: bytes) -> None:
    try:
        parse_discovery(discovery_datagram({"ip": "10.0.0.1"})[:28] + data)
        parse_discovery(data)
    except FlexLineError as exc:
        assert exc.reason
