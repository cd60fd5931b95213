"""Whatever bytes arrive, every source parser answers with a value or its own typed
error, and a listener with nothing but at most a count and a debug line."""

from __future__ import annotations

from hypothesis import example, given, settings
from hypothesis import strategies as st

from moas_gui.sources.base import MAX_KHZ, SourceEvent
from moas_gui.sources.n1mm import N1MMListener
from moas_gui.sources.n1mm_packet import N1MMPacketError, parse_radio_info, radio_info_packet
from moas_gui.sources.n1mm_rotor import N1MMRotorServer
from moas_gui.sources.n1mm_rotor_packet import N1MMRotorError, parse_rotor_command, turn_command
from moas_gui.sources.wintest import WinTestListener
from moas_gui.sources.wintest_frame import WinTestFrameError, parse_status, status_frame

FIELDS = ["<RadioNr>", "</RadioNr>", "<Freq>", "</Freq>", "<TXFreq>", "</TXFreq>", "1", "0",
          "-", "9" * 25, "&amp;", "&lt;", "<!DOCTYPE", "<RadioInfo>", "</RadioInfo>", "\x00",
          "\u0661", "<ActiveRadioNr>", "</ActiveRadioNr>", "True", " ", "\""]


def mutations(good: bytes) -> st.SearchStrategy[bytes]:
    """The good datagram cut, spliced or with bytes flipped: the bad input most like real."""
    return st.one_of(
        st.binary(max_size=400),
        st.integers(0, len(good)).map(lambda n: good[:n]),
        st.tuples(st.integers(0, len(good) - 1), st.binary(min_size=1, max_size=8)).map(
            lambda t: good[:t[0]] + t[1] + good[t[0] + len(t[1]):]),
        st.lists(st.sampled_from(FIELDS), max_size=30).map(lambda p: "".join(p).encode()),
    )


@settings(max_examples=300, deadline=None)
@given(mutations(radio_info_packet(2, 14025.0, 14030.0)))
@example(b"<RadioInfo><RadioNr>1</RadioNr><Freq>30000000000</Freq></RadioInfo>")
def test_n1mm_parser_gives_a_radio_or_its_error(data: bytes) -> None:
    try:
        info = parse_radio_info(data)
    except N1MMPacketError as exc:
        assert str(exc)
        return
    assert 1 <= info.radio_nr <= 99
    assert info.khz is None or 0 < info.khz < MAX_KHZ


@settings(max_examples=300, deadline=None)
@given(mutations(status_frame("STN1", 14075.1)))
def test_wintest_parser_gives_a_status_or_its_error(data: bytes) -> None:
    try:
        status = parse_status(data)
    except WinTestFrameError as exc:
        assert str(exc)
        return
    assert status.khz is None or 0 < status.khz < MAX_KHZ


@settings(max_examples=300, deadline=None)
@given(mutations(turn_command("TH6", 123.4)))
def test_rotor_parser_gives_a_command_or_its_error(data: bytes) -> None:
    try:
        command = parse_rotor_command(data)
    except N1MMRotorError as exc:
        assert str(exc)
        return
    assert command.rotor
    assert 0.0 <= getattr(command, "azimuth", 0.0) < 360.0


@settings(max_examples=200, deadline=None)
@given(st.lists(st.binary(max_size=200), max_size=20))
def test_listeners_take_any_datagrams_and_tell_only_plausible_radios(
    datagrams: list[bytes],
) -> None:
    events: list[SourceEvent] = []
    turns: list[tuple[int, float]] = []
    n1mm = N1MMListener({"127.0.0.1": 1}, on_event=events.append)
    wintest = WinTestListener({"STN1": (1, 1)}, events.append)
    rotor = N1MMRotorServer({1: ("TH6",)}, turn=lambda i, h: turns.append((i, h)),
                            stop=lambda i: None, headings=list)
    for data in datagrams:
        n1mm.handle(data, "127.0.0.1")
        wintest.handle(data, "127.0.0.1")
        rotor.handle(data, "127.0.0.1")
    for event in events:
        assert event.station == 1
        rx = getattr(event, "rx_khz", None)
        assert rx is None or 0 < rx < MAX_KHZ
    assert all(0.0 <= heading < 360.0 for _, heading in turns)
