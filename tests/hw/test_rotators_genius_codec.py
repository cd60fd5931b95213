"""Rotator Genius rev. 4: the codec (both ends) and the emulator's pure model."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.hw.rotators.genius_codec import (
    STATUS_LENGTH,
    GeniusCommand,
    GeniusCommandDecoder,
    GeniusGarbage,
    GeniusReply,
    GeniusStatus,
    ReplyDecoder,
    RotorBlock,
    decode_status,
    encode_move,
    encode_read,
    encode_status,
    encode_stop,
    encode_turn,
)
from moas_gui.testing.genius_server import GeniusModel

# A real unit's |h reply (rotator-protocols.md 8): rotor 1 without sensor, rotor 2 at 43.
CAPTURED = (
    b"|h2\x00"
    b"999359  0A0   0999999\x00Tower       "
    b" 43359  0A0   0999999\x00Rotator 2   "
)


def test_the_captured_reply_of_a_real_unit_decodes() -> None:
    assert len(CAPTURED) == STATUS_LENGTH == 72
    status = decode_status(CAPTURED)
    first, second = status.rotors
    assert first.azimuth is None and first.name == "Tower"
    assert second == RotorBlock(azimuth=43, limit_cw=359, limit_ccw=0, configuration="A",
                                moving=0, offset=0, target=None, start=None,
                                out_of_limits=False, name="Rotator 2")
    assert status.active == "2"


def test_status_round_trips_through_the_encoder() -> None:
    status = GeniusStatus((
        RotorBlock(azimuth=100, limit_cw=5, limit_ccw=350, moving=1, target=200, start=90,
                   name="TOW1"),
        RotorBlock(azimuth=None, limit_cw=10, limit_ccw=60, configuration="E", offset=-12,
                   out_of_limits=True),
    ))
    assert decode_status(encode_status(status)) == status


def test_commands_have_no_terminator_and_three_digit_azimuths() -> None:
    assert encode_read() == b"|h"
    assert encode_move(2, 45) == b"|A2045"
    assert encode_stop() == b"|S"
    assert encode_turn(1, clockwise=True) == b"|P1"
    assert encode_turn(2, clockwise=False) == b"|M2"
    with pytest.raises(ValueError, match="rotators 1 and 2"):
        encode_move(3, 10)
    with pytest.raises(ValueError, match="0-360"):
        encode_move(1, 361)


def test_replies_split_by_header_and_length_even_in_pieces() -> None:
    decoder = ReplyDecoder()
    stream = b"|AK" + CAPTURED + b"|A158F|SK"
    events = []
    for i in range(0, len(stream), 5):
        events += decoder.feed(stream[i:i + 5])
    assert events[0] == GeniusReply("A", True)
    assert isinstance(events[1], GeniusStatus)
    assert events[2:] == [GeniusReply("A", False, 158), GeniusReply("S", True)]


def test_garbage_is_reported_and_the_decoder_resynchronises_on_the_next_header() -> None:
    decoder = ReplyDecoder()
    broken = bytearray(CAPTURED)
    broken[4 + 9] = ord("X")  # configuration byte of rotor 1
    events = decoder.feed(b"\xff\x00junk" + bytes(broken) + CAPTURED + b"|Zq|SK")
    kinds = [type(e).__name__ for e in events]
    assert kinds == ["GeniusGarbage", "GeniusGarbage", "GeniusStatus", "GeniusGarbage", "GeniusReply"]
    assert isinstance(events[1], GeniusGarbage) and "configuration byte is 'X'" in events[1].reason
    assert isinstance(events[3], GeniusGarbage) and "unknown reply header |Z" in events[3].reason


@given(st.binary(max_size=200))
def test_the_decoder_survives_any_bytes(data: bytes) -> None:
    decoder = ReplyDecoder()
    decoder.feed(data)
    events = decoder.feed(b"|" * 0 + CAPTURED + CAPTURED)
    assert any(isinstance(e, GeniusStatus) for e in events)


def test_the_controller_side_reads_commands_by_length() -> None:
    decoder = GeniusCommandDecoder()
    out = decoder.feed(b"|h|A1") + decoder.feed(b"270|S|P2|x")
    assert out[:4] == [GeniusCommand("h", raw=b"|h"), GeniusCommand("A", 1, 270, b"|A1270"),
                       GeniusCommand("S", raw=b"|S"), GeniusCommand("P", 2, raw=b"|P2")]
    assert isinstance(out[4], GeniusGarbage)


@given(st.binary(max_size=200))
def test_the_controller_side_survives_any_bytes(data: bytes) -> None:
    decoder = GeniusCommandDecoder()
    decoder.feed(data)
    out = decoder.feed(b"h" * 22 + b"|h")  # 22 bytes complete any command left pending
    assert out[-1] == GeniusCommand("h", raw=b"|h")


# ---- the emulator's model ------------------------------------------------------------------

def test_model_turns_at_its_speed_and_reports_target_and_direction() -> None:
    model = GeniusModel(speed=10.0)
    assert model.handle(GeniusCommand("A", 1, 30), now=0.0) == b"|AK"
    first = model.status(now=1.0).rotors[0]
    assert (first.azimuth, first.moving, first.target, first.start) == (10, 1, 30, 0)
    done = model.status(now=5.0).rotors[0]
    assert (done.azimuth, done.moving, done.target) == (30, 0, None)


def test_model_never_turns_through_its_stop() -> None:
    model = GeniusModel(speed=100.0)
    model.rotors[0].limit_ccw, model.rotors[0].limit_cw = 180, 180  # stop at south
    model.set_azimuth(1, 170, now=0.0)
    model.handle(GeniusCommand("A", 1, 190), now=0.0)
    assert model.status(now=0.1).rotors[0].moving == 2  # counterclockwise, the long way


def test_model_refuses_targets_outside_its_limits_and_moves_without_sensor() -> None:
    model = GeniusModel()
    model.rotors[1].limit_ccw, model.rotors[1].limit_cw = 0, 300
    assert model.handle(GeniusCommand("A", 2, 330), now=0.0) == b"|AF"
    model.rotors[0].sensor = False
    assert model.handle(GeniusCommand("A", 1, 10), now=0.0) == b"|AF"
    assert model.status(now=0.0).rotors[0].azimuth is None


def test_stop_stops_both_rotors() -> None:
    model = GeniusModel(speed=1.0)
    model.handle(GeniusCommand("A", 1, 90), now=0.0)
    model.handle(GeniusCommand("P", 2), now=0.0)
    assert model.handle(GeniusCommand("S"), now=1.0) == b"|SK"
    rotors = model.status(now=5.0).rotors
    assert [r.moving for r in rotors] == [0, 0]
    assert [r.azimuth for r in rotors] == [1, 1]
