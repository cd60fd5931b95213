"""The pure controller emulators: what they answer, how fast they turn, their quirks."""

from __future__ import annotations

import pytest

from moas_gui.hw.rotators.controllers.base import Axis
from moas_gui.hw.rotators.controllers.dcu1_emulator import DCU1Emulator
from moas_gui.hw.rotators.controllers.prosistel_emulator import ProsistelEmulator
from moas_gui.hw.rotators.controllers.rc2800_emulator import RC2800Emulator
from moas_gui.hw.rotators.controllers.rotorez_emulator import BANNER, RotorEZEmulator
from moas_gui.hw.rotators.controllers.spid_emulator import SpidEmulator
from moas_gui.hw.rotators.controllers.yaesu_emulator import YaesuEmulator

# -- movement ------------------------------------------------------------------------------


def test_axis_turns_at_its_speed_and_stops_on_target() -> None:
    axis = Axis(0.0, 0.0, 360.0, speed=6.0)
    axis.go_to(90.0, now=0.0)
    axis.advance(10.0)
    assert axis.position == pytest.approx(60.0) and axis.moving
    assert axis.arrival(10.0) == pytest.approx(15.0)
    axis.advance(20.0)
    assert axis.position == 90.0 and not axis.moving


def test_axis_never_passes_its_end_stops() -> None:
    axis = Axis(10.0, 0.0, 360.0, speed=100.0)
    axis.run(clockwise=False, now=0.0)
    axis.advance(5.0)
    assert axis.position == 0.0 and not axis.moving


# -- DCU-1 ---------------------------------------------------------------------------------


def test_dcu1_loads_without_moving_and_turns_on_am1() -> None:
    emu = DCU1Emulator(bearing=0.0, speed=10.0)
    assert emu.receive(b"AP1090;", 0.0) == b""
    assert not emu.busy
    emu.receive(b"AM1;\r\n", 1.0)
    emu.advance(4.0)
    assert emu.azimuth == pytest.approx(30.0)
    emu.advance(20.0)
    assert emu.azimuth == pytest.approx(90.0)


def test_dcu1_never_answers_anything() -> None:
    emu = DCU1Emulator()
    for data in (b"AI1;", b"AP1090;AM1;", b"?", b"AS1;", b";", b"\xff\x00"):
        assert emu.receive(data, 0.0) == b""


def test_dcu1_turns_through_north_to_avoid_the_south_stop() -> None:
    emu = DCU1Emulator(bearing=170.0, speed=10.0)
    emu.receive(b"AP1190;AM1;", 0.0)
    emu.advance(1.0)  # 10 degrees counter-clockwise, away from south
    assert emu.azimuth == pytest.approx(160.0)


def test_dcu1_stops_on_as1_and_on_a_lone_semicolon() -> None:
    for stop in (b"AS1;", b";"):
        emu = DCU1Emulator(bearing=0.0, speed=10.0)
        emu.receive(b"AP1090;AM1;", 0.0)
        emu.receive(stop, 2.0)
        emu.advance(10.0)
        assert emu.azimuth == pytest.approx(20.0)


# -- Rotor-EZ ------------------------------------------------------------------------------


def test_rotorez_answers_ai1_with_semicolon_and_three_digits() -> None:
    assert RotorEZEmulator(bearing=7.0).receive(b"AI1;", 0.0) == b";007"


def test_rotorez_green_heron_shape_puts_the_semicolon_last() -> None:
    assert RotorEZEmulator(bearing=7.0, green_heron=True).receive(b"AI1;", 0.0) == b"007;"


def test_rotorez_set_and_go_with_carriage_return() -> None:
    emu = RotorEZEmulator(bearing=0.0, speed=10.0)
    emu.receive(b"AP1045\r", 0.0)
    emu.advance(2.0)
    assert emu.azimuth == pytest.approx(20.0)


def test_rotorez_answers_a_stop_while_idle_with_its_idiom_text() -> None:
    emu = RotorEZEmulator()
    assert emu.receive(b";", 0.0) == BANNER
    assert emu.receive(b"XYZ", 0.0) == BANNER * 3


def test_rotorez_takes_option_letters_silently() -> None:
    assert RotorEZEmulator().receive(b"EeJjOoSs", 0.0) == b""


def test_rotorez_can_put_out_a_stray_byte_at_power_on() -> None:
    emu = RotorEZEmulator(bearing=90.0, stray_byte=True)
    assert emu.receive(b"AI1;", 0.0) == b"\xe0;090"
    assert emu.receive(b"AI1;", 0.1) == b";090"


# -- Yaesu ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("variant", "command", "answer"),
    [
        ("A", b"C\r", b"+0123\r\n"),
        ("A", b"C2\r", b"+0123+0000\r\n"),
        ("A", b"B\r", b"+0000\r\n"),
        ("A", b"S\r", b"\r"),
        ("A", b"M200\r", b"\r"),
        ("B", b"C\r", b"AZ=123\r\n"),
        ("B", b"C2\r", b"AZ=123  EL=000\r\n"),
        ("B", b"B\r", b"EL=000\r\n"),
        ("B", b"S\r", b""),
        ("B", b"M200\r", b""),
        ("B", b"\r", b"?>\r\n"),
        ("A", b"Q\r", b"?>\r\n"),
        ("B", b"M20\r", b"?>\r\n"),
        ("B", b"M451\r", b"?>\r\n"),
        ("B", b"c2\r\n", b"AZ=123  EL=000\r\n"),
    ],
)
def test_yaesu_answers_like_the_real_interface(variant: str, command: bytes,
                                               answer: bytes) -> None:
    assert YaesuEmulator(123.0, variant).receive(command, 0.0) == answer


def test_yaesu_w_turns_both_axes_and_x_sets_speed() -> None:
    emu = YaesuEmulator(0.0, "B", speed=10.0)
    emu.receive(b"X1\rW090 010\r", 0.0)
    emu.advance(5.0)
    assert emu.azimuth == pytest.approx(20.0)  # X1 = 40 % of top speed
    assert emu.elevation == pytest.approx(10.0)


def test_yaesu_r_and_l_run_until_stopped() -> None:
    emu = YaesuEmulator(100.0, "B", speed=10.0)
    emu.receive(b"L\r", 0.0)
    emu.receive(b"A\r", 3.0)
    emu.advance(10.0)
    assert emu.azimuth == pytest.approx(70.0)


# -- RC2800 --------------------------------------------------------------------------------


def test_rc2800_status_line_pads_the_position_to_six_characters() -> None:
    emu = RC2800Emulator(98.1, early=False)
    assert emu.receive(b"A\r", 0.0) == b"A P=  98.1 S=9 ST\n\r"


def test_rc2800px_sets_and_answers_in_one_command() -> None:
    emu = RC2800Emulator(0.0, early=False, speed=10.0)
    assert emu.receive(b"A200\r", 0.0) == b"A P=   0.0 S=9 MV\n\r"
    emu.advance(2.0)
    assert emu.azimuth == pytest.approx(20.0)


def test_rc2800pa_early_set_answers_only_the_empty_line() -> None:
    emu = RC2800Emulator(0.0, early=True, speed=10.0)
    assert emu.receive(b"A\r200\r\r", 0.0) == b"A P=   0.0 S=9 ST\n\rA P=   0.0 S=9 MV\n\r"


def test_rc2800pa_reports_by_itself_while_the_reading_changes_only() -> None:
    emu = RC2800Emulator(0.0, early=True, speed=10.0)
    emu.receive(b"A\r50\r", 0.0)
    lines = b"".join(emu.advance(t / 10) for t in range(1, 11))
    assert lines.count(b"\n\r") == 10 and lines.endswith(b"A P=  10.0 S=9 MV\n\r")
    emu.advance(10.0)  # arrives at 50
    assert emu.advance(10.5) == b""
    assert not emu.busy


def test_rc2800px_never_reports_by_itself() -> None:
    emu = RC2800Emulator(0.0, early=False, speed=10.0)
    emu.receive(b"A50\r", 0.0)
    assert all(emu.advance(t / 10) == b"" for t in range(1, 20))


def test_rc2800_answers_an_unknown_command_with_an_error_line() -> None:
    assert RC2800Emulator().receive(b"Z\r", 0.0) == b"A ERR=05\n\r"


# -- SPID ----------------------------------------------------------------------------------

STATUS = b"W" + bytes(10) + b"\x1f\x20"
STOP = b"W" + bytes(10) + b"\x0f\x20"


def test_rot1prog_answers_status_with_five_bytes() -> None:
    assert SpidEmulator(12.0).receive(STATUS, 0.0) == bytes([0x57, 3, 7, 2, 0x20])


def test_rot2prog_answers_status_with_twelve_bytes_and_its_resolution() -> None:
    emu = SpidEmulator(12.5, rot2=True, ph=2, pv=2)
    assert emu.receive(STATUS, 0.0) == bytes([0x57, 3, 7, 2, 5, 2, 3, 6, 0, 0, 2, 0x20])


def test_rot2prog_decodes_a_set_frame_with_its_own_resolution() -> None:
    emu = SpidEmulator(0.0, rot2=True, ph=2, pv=2, speed=1000.0)
    # PH/PV bytes in the frame say 1, but the unit counts 2 pulses per degree.
    assert emu.receive(b"W0967\x010874\x01\x2f\x20", 0.0) == b""
    emu.advance(100.0)
    assert emu.azimuth == pytest.approx(123.5)
    assert emu.elevation == pytest.approx(77.0)


def test_rot1prog_set_then_stop_answers_with_the_position() -> None:
    emu = SpidEmulator(0.0, speed=10.0)
    emu.receive(bytes.fromhex("57 34 38 33 30 00 00 00 00 00 00 2F 20"), 0.0)
    assert emu.receive(STOP, 2.0) == bytes([0x57, 3, 8, 0, 0x20])


def test_spid_drops_a_frame_without_its_end_byte_and_finds_the_next() -> None:
    broken = STATUS[:-1] + b"\x21"
    assert SpidEmulator(12.0).receive(broken + STATUS, 0.0) == bytes([0x57, 3, 7, 2, 0x20])


# -- Prosistel -----------------------------------------------------------------------------


def test_prosistel_answers_position_go_and_cpm_off() -> None:
    emu = ProsistelEmulator(290.0, speed=10.0)
    assert emu.receive(b"\x02A?\r", 0.0) == b"\x02A,?,290,R\r"
    assert emu.receive(b"\x02AG200\r", 0.0) == b"\x02A,G,R\r"
    assert emu.receive(b"\x02AS\r", 0.0) == b"\x02A,S,R\r"
    emu.advance(3.0)
    assert emu.azimuth == pytest.approx(260.0)


def test_prosistel_997_and_999_stop() -> None:
    for stop in (b"\x02AG997\r", b"\x02AG999\r"):
        emu = ProsistelEmulator(0.0, speed=10.0)
        emu.receive(b"\x02AG100\r", 0.0)
        emu.receive(stop, 1.0)
        emu.advance(5.0)
        assert emu.azimuth == pytest.approx(10.0)


def test_prosistel_refuses_other_units_and_bad_values() -> None:
    emu = ProsistelEmulator()
    assert emu.receive(b"\x02E?\r", 0.0) == b"\x02E,?,E,00003\r"
    assert emu.receive(b"\x02AG500\r", 0.0) == b"\x02A,G,E,00001\r"


def test_prosistel_with_cpm_reports_each_new_degree_until_told_to_stop() -> None:
    emu = ProsistelEmulator(0.0, speed=10.0, cpm=True)
    emu.receive(b"\x02AG100\r", 0.0)
    assert emu.advance(0.1) == b"\x02A,?,1,R\r"
    assert emu.advance(0.12) == b""
    emu.receive(b"\x02AS\r", 0.2)
    assert emu.advance(1.0) == b""
