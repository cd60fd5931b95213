"""The streaming decoder for what a MOAS II sends: every reply, event and
error of the manual, in any pieces, through garbage."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.hw.moas2.decoder import MAX_MESSAGE, SwitchDecoder
from moas_gui.hw.moas2.messages import (
    AntennaEvent,
    AntennaStatus,
    BoxMessage,
    BoxStatus,
    ErrorReply,
    ExtraRelaysEvent,
    InhibitReply,
    Malformed,
    PolarityStatus,
    Pong,
    ReceiveEvent,
    RelayStatus,
    TransmitEvent,
    TRState,
    UninhibitReply,
    UnitIdReply,
    VendorReply,
)
from moas_gui.hw.moas2.replies import encode_reply, parse_reply

R, T = TRState.RECEIVE, TRState.TRANSMIT

MANUAL_REPLIES: list[tuple[bytes, BoxMessage]] = [
    (b"!;", Pong(True)),
    (b".;", Pong(False)),
    (b"!1F1;", AntennaEvent(1, AntennaStatus.TX_FAST, 1)),
    (b"!1f1;", AntennaEvent(1, AntennaStatus.RX_FAST, 1)),
    (b"!1X;", ExtraRelaysEvent(1)),
    (b"!0X;", ExtraRelaysEvent(0)),
    (b">12;", ReceiveEvent(1, 2)),
    (b"<3p;", TransmitEvent(3, 51)),
    (b"(12;", InhibitReply(frozenset({1, 2}))),
    (b")3456;", UninhibitReply(frozenset({3, 4, 5, 6}))),
    (b'"I1;', PolarityStatus(frozenset({1}))),
    (b"|00000000007;", RelayStatus(frozenset({0, 1, 2}))),
    (b"|000000003y0;", RelayStatus(frozenset(range(8, 14)))),
    (b":1001;", UnitIdReply("100", 1)),
    (b"?A;", ErrorReply("A")),
    (b"?U;", ErrorReply("U")),
    (b"?T;", ErrorReply("T")),
    (b"?C;", ErrorReply("C")),
    (b"?F;", ErrorReply("F")),
]


@pytest.mark.parametrize(("data", "message"), MANUAL_REPLIES)
def test_manual_reply_decodes(data: bytes, message: BoxMessage) -> None:
    assert SwitchDecoder().feed(data) == [message]
    assert encode_reply(message) == data


def test_box_status_example_of_the_manual_decodes_its_first_18_antennas() -> None:
    # The manual's example carries 21 antenna characters; 18 are read.
    [status] = SwitchDecoder().feed(b'"BTRRRRR16}}}}16}}}}}}}}}}}}};')
    assert isinstance(status, BoxStatus)
    assert status.tr == (T, R, R, R, R, R)
    assert status.tx == (1, 6, 63, 63, 63, 63)
    assert status.rx == (1, 6, 63, 63, 63, 63)
    assert status.alt == (63,) * 6


def test_box_status_round_trips() -> None:
    status = BoxStatus((T, R, TRState.INHIBITED, R, R, R), (1, 2, 3, 4, 5, 6),
                       (7, 8, 9, 10, 11, 12), (63,) * 6)
    data = encode_reply(status)
    assert len(data) == 27
    assert SwitchDecoder().feed(data) == [status]


def test_every_antenna_event_status_decodes() -> None:
    for status in AntennaStatus:
        data = f"!2{status.value}z;".encode()
        assert SwitchDecoder().feed(data) == [AntennaEvent(2, status, 61)]


STREAM = b"".join(data for data, _ in MANUAL_REPLIES)
MESSAGES = [message for _, message in MANUAL_REPLIES]


def test_many_messages_in_one_chunk() -> None:
    assert SwitchDecoder().feed(STREAM) == MESSAGES


def test_one_byte_at_a_time() -> None:
    decoder = SwitchDecoder()
    out = []
    for i in range(len(STREAM)):
        out += decoder.feed(STREAM[i : i + 1])
    assert out == MESSAGES
    assert decoder.pending == b""


@given(st.lists(st.integers(0, len(STREAM)), max_size=30))
def test_any_chunking_gives_the_same_messages(cuts: list[int]) -> None:
    points = sorted({0, len(STREAM), *cuts})
    decoder = SwitchDecoder()
    out = []
    for a, b in itertools.pairwise(points):
        out += decoder.feed(STREAM[a:b])
    assert out == MESSAGES


def test_characters_at_or_below_space_are_ignored_anywhere() -> None:
    noisy = b"\r\n ! 1\tF\x001 ;\x20.\n;"
    assert SwitchDecoder().feed(noisy) == [AntennaEvent(1, AntennaStatus.TX_FAST, 1), Pong(False)]


def test_dollar_aborts_the_message_so_far() -> None:
    out = SwitchDecoder().feed(b"!1F$>12;")
    assert out[-1] == ReceiveEvent(1, 2)
    assert all(isinstance(m, Malformed) for m in out[:-1])


def test_dollar_split_across_chunks_aborts_too() -> None:
    decoder = SwitchDecoder()
    assert decoder.feed(b"<1") == []
    assert decoder.feed(b"2$") == []
    assert decoder.feed(b">12;") == [ReceiveEvent(1, 2)]


def test_garbage_before_a_message_does_not_lose_it() -> None:
    out = SwitchDecoder().feed(b"xyz=+\xff>12;")
    assert out[-1] == ReceiveEvent(1, 2)
    assert isinstance(out[0], Malformed)
    assert out[0].reason == "garbage before a message"


def test_a_message_cut_short_by_the_next_one_costs_only_itself() -> None:
    out = SwitchDecoder().feed(b"!1F<12;!;")
    assert out == [Malformed(b"!1F", "garbage before a message"), TransmitEvent(1, 2), Pong(True)]


@pytest.mark.parametrize(
    "junk",
    [b"!1Q1;", b"!12345;", b"?;", b":10;", b'"Bxx;', b"|123;", b"<1;", b"(17;", b"\xff\xfe;",
     b"%C11;"],
)
def test_malformed_messages_come_out_as_malformed_and_the_next_is_kept(junk: bytes) -> None:
    out = SwitchDecoder().feed(junk + b".;")
    assert out[-1] == Pong(False)
    assert out[:-1] and all(isinstance(m, Malformed) and m.reason for m in out[:-1])


def test_endless_garbage_without_semicolon_is_bounded_and_reported() -> None:
    decoder = SwitchDecoder()
    out = decoder.feed(b"x" * 1000)
    assert len(decoder.pending) <= MAX_MESSAGE
    assert any(isinstance(m, Malformed) for m in out)
    assert decoder.feed(b"<12;")[-1] == TransmitEvent(1, 2)


def test_reset_forgets_a_half_message() -> None:
    decoder = SwitchDecoder()
    decoder.feed(b"!1")
    decoder.reset()
    assert decoder.feed(b"F1;") == [Malformed(b"F1;", "no message starts here")]


_garbage = st.binary(max_size=12).map(lambda b: bytes(c for c in b if c not in b";$"))


@given(st.lists(st.tuples(_garbage, st.sampled_from(MANUAL_REPLIES)), max_size=15))
def test_garbage_without_start_characters_never_loses_a_good_message(
    items: list[tuple[bytes, tuple[bytes, BoxMessage]]],
) -> None:
    start = set(b"!%&(~^[]/'\\|*\"_):@#.<>?")
    data = b""
    expected = []
    for garbage, (message_bytes, message) in items:
        data += bytes(c for c in garbage if c not in start) + message_bytes
        expected.append(message)
    decoded = [m for m in SwitchDecoder().feed(data) if not isinstance(m, Malformed)]
    assert decoded == expected


@given(st.binary(max_size=300))
def test_any_bytes_never_raise(data: bytes) -> None:
    decoder = SwitchDecoder()
    decoder.feed(data)
    assert len(decoder.pending) <= MAX_MESSAGE


def test_parse_reply_says_why() -> None:
    with pytest.raises(ValueError, match="does not start a message"):
        parse_reply("x")
    assert VendorReply("abc") == parse_reply("#abc")
