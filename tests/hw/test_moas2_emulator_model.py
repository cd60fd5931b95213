"""The emulated MOAS II firmware: power-on state, active/inactive, status
replies, errors, the input buffer, antennas and the conflict resolver."""

from __future__ import annotations

from moas_gui.hw.moas2.emulator.model import INPUT_BUFFER
from moas_gui.hw.moas2.emulator.station import StationPhase
from moas_gui.hw.moas2.emulator.stepped import SteppedBox


def active_box(events: str = "") -> SteppedBox:
    return SteppedBox(active=True, events=events)


# --------------------------------------------------------------------------- power-on state


def test_power_on_state_is_inactive_with_everything_at_its_defaults() -> None:
    box = SteppedBox()
    view = box.model.view()
    assert not view.active and not view.resolver_on
    assert box.send("';") == ".;"
    assert box.send("|;") == "|00000000000;"
    assert box.send('"B;') == '"BRRRRRR' + "}" * 18 + ";"
    assert box.send('"I;') == '"I;'
    assert (view.inhibit_ms, view.interrupt_ms) == (20, 0)
    assert view.events == frozenset()
    for st in view.stations:
        assert (st.tx.antenna, st.rx.antenna, st.alt.antenna) == (63, 63, 63)
        assert st.mode.name == "WAIT" and st.receive_delay_ms == 0
        assert not st.inhibited and not st.inhibit_line_low


def test_ping_answers_active_once_activated() -> None:
    box = SteppedBox()
    assert box.send("';*1;';") == ".;!;"


def test_unit_id_is_reported_set_and_survives_a_reset() -> None:
    box = SteppedBox(unit_id=4)
    assert box.send(":;") == ":1004;"
    assert box.send(":17;") == ":10017;"
    box.send("*0;")
    assert box.send(":;") == ":10017;"


def test_antennas_sent_while_inactive_are_remembered_and_selected_on_activation() -> None:
    box = SteppedBox()
    box.send("&1;!1B1123;!2TAF;")
    assert box.relays == set()
    assert box.station(1).pending == (("T", 1), ("R", 1))
    box.send("*1;")
    # Station 2 receives on its receive relays (none): 10-63 is a fast pair.
    assert box.relays == {1, 2, 3}
    assert box.station(1).tx.antenna == 1 and box.station(2).tx.antenna == 10


def test_activate_while_active_is_ignored_and_leaves_the_resolver_off() -> None:
    box = active_box()
    box.send("*r;*1;!1B1123;")
    assert box.relays == set()
    assert box.model.view().resolver_on is False


def test_reset_returns_to_the_power_on_state() -> None:
    box = active_box("ATIX")
    box.send("&1;%1;_S11;!1B1123;!0X045;[50;]9;/I1;\\1100;(2;~12;@13;^E3;")
    box.send("*0;")
    view = box.model.view()
    assert not view.active and view.relays == frozenset()
    assert view.events == frozenset() and view.inhibit_ms == 20 and view.interrupt_ms == 0
    assert box.model.conflicts.pairs() == frozenset() and box.model.fast.pairs() == frozenset()
    assert view.station0 == frozenset()
    st = view.station(1)
    assert st.tx.antenna == 63 and st.mode.name == "WAIT" and st.receive_delay_ms == 0
    assert box.send('"I;(;') == '"I;'
    assert box.send("*1;|;") == "|00000000000;"


def test_station_0_relays_are_set_at_once_in_addition_to_the_stations() -> None:
    box = active_box("X")
    box.send("&1;!1B112;")
    assert box.send("!0X0z};") == "!0X;"
    assert box.relays == {1, 2, 61, 63}
    box.send("!0X0;")
    assert box.relays == {1, 2}


def test_relay_status_reply_lists_the_closed_relays() -> None:
    box = active_box()
    box.send("&1;!1B189ABCD;")
    assert box.send("|;") == "|000000003y0;"


def test_box_status_reply_shows_tr_and_antennas() -> None:
    box = active_box()
    box.send("&1;!1B1;!2B2;!2A5;(3;")
    box.key(1, True)
    assert box.send('"B;') == '"BTRIRRR12}}}}12}}}}}5}}}};'


# --------------------------------------------------------------------------- errors and input


def test_errors_unknown_argument_and_self_reference() -> None:
    box = active_box()
    assert box.send("x;") == "?U;"
    assert box.send("!7B1;") == "?A;"
    assert box.send("~11;") == "?T;"
    assert box.send("@212;") == "?T;"
    assert box.send("';") == "!;"


def test_input_buffer_holds_128_characters_and_overflow_is_reported_once() -> None:
    box = active_box()
    assert box.send("#" + "a" * (INPUT_BUFFER - 1) + ";") == "#moas-gui-emulator;"
    assert box.send("#" + "a" * INPUT_BUFFER + ";") == "?F;"
    assert box.send("!" * 400 + ";") == "?F;"
    assert box.send("';") == "!;"


def test_dollar_aborts_and_control_characters_are_ignored() -> None:
    box = active_box()
    assert box.send("!1B1 $ ' ;") == "!;"
    assert box.send("\r\n\t'\x00;") == "!;"


def test_bytes_above_ascii_are_an_error_not_a_crash() -> None:
    box = active_box()
    assert box.send("\xff\xfe;") == "?U;"
    assert box.send("!1B\xe9;") == "?A;"


# --------------------------------------------------------------------------- receive on tx when slow


def test_station_receives_on_its_transmit_relays_when_the_pair_is_slow() -> None:
    box = active_box()
    box.send("!1T112;!1R234;")
    assert box.relays == {1, 2}
    box.send("&F12;!1R234;")
    assert box.relays == {3, 4}


# --------------------------------------------------------------------------- conflicts


def test_a_conflicting_request_is_held_and_reported_until_the_antenna_is_free() -> None:
    box = active_box("A")
    box.send("%C11;&1;")
    assert box.send("!1B112;") == "!1F1;!1f1;"
    assert box.send("!2B134;") == "!2C1;!2c1;"
    assert box.relays == {1, 2}
    assert box.station(2).tx.antenna == 63
    # Both changes happen in the same step; the older request is reported first.
    assert box.send("!1B256;") == "!2F1;!2f1;!1F2;!1f2;"
    assert box.relays == {5, 6, 3, 4}


def test_a_newer_request_replaces_a_held_one() -> None:
    box = active_box("A")
    box.send("%C11;&1;!1B112;")
    box.send("!2B134;")
    assert box.send("!2B378;") == "!2F3;!2f3;"
    box.send("!1B256;")
    assert box.station(2).tx.antenna == 3
    assert box.relays == {5, 6, 7, 8}


def test_two_stations_swap_antennas_in_one_step() -> None:
    box = active_box("A")
    box.send("%C1122;&1;!1B112;!2B234;")
    assert box.send("!1B256;") == "!1C2;!1c2;"
    assert box.relays == {1, 2, 3, 4}
    assert box.send("!2B178;") == "!1F2;!1f2;!2F1;!2f1;"
    assert box.relays == {5, 6, 7, 8}


def test_an_older_request_wins_over_a_newer_one_for_the_same_antenna() -> None:
    box = active_box("A")
    box.send("%C33;&1;*r;!1B3;!2B3;")
    assert box.send("*R;") == "!2C3;!2c3;!1F3;!1f3;"
    assert box.station(1).tx.antenna == 3 and box.station(2).tx.antenna == 63


def test_resolver_off_holds_every_change_until_it_is_on_again() -> None:
    box = active_box()
    box.send("&1;!1B112;!2B234;")
    box.send("*r;!1B356;!2B478;")
    assert box.relays == {1, 2, 3, 4}
    box.send("*R;")
    assert box.relays == {5, 6, 7, 8}


def test_changing_the_conflict_table_does_not_touch_antennas_already_set() -> None:
    box = active_box()
    box.send("&1;!1B112;!2B234;%C12;")
    assert box.relays == {1, 2, 3, 4}
    box.send("!2B234;")
    assert box.station(2).tx.antenna == 2


def test_a_station_never_conflicts_with_itself() -> None:
    box = active_box()
    box.send("%C11;&1;!1T112;!1R134;")
    assert box.station(1).rx.antenna == 1


def test_no_antenna_does_not_conflict_after_power_on() -> None:
    box = active_box()
    box.send("%C11;&1;!1B1;!2B}5;!3B}6;")
    assert box.relays == {5, 6}


# --------------------------------------------------------------------------- alternates


def test_alternate_antenna_is_used_while_a_listed_station_transmits() -> None:
    box = active_box()
    box.send("&1;!1B112;!2B234;!2A556;@12;")
    box.key(1, True)
    assert box.relays == {1, 2, 5, 6}
    assert box.station(2).on_alternate
    box.key(1, False)
    assert box.relays == {1, 2, 3, 4}


def test_alternate_in_conflict_closes_no_relays_for_that_station() -> None:
    box = active_box("A")
    box.send("&1;%C33;!1B112;!2B234;!3B356;")
    assert box.send("!2A356;") == "!2a3;"
    box.send("@12;")
    box.key(1, True)
    assert box.relays == {1, 2, 5, 6}
    assert box.station(2).closed == frozenset()


def test_alternates_do_not_conflict_with_each_other() -> None:
    box = active_box("A")
    box.send("&1;%C55;!2B234;!3B378;")
    assert box.send("!2A59;!3A5A;") == "!2A5;!3A5;"
    box.send("@123;")
    box.key(1, True)
    assert box.relays == {9, 10}


def test_a_station_cannot_move_itself_to_its_alternate() -> None:
    assert active_box().send("@11;") == "?T;"


# --------------------------------------------------------------------------- events on and off


def test_events_are_sent_only_when_enabled() -> None:
    box = active_box()
    assert box.send("&1;!1B112;!1X03;") == ""
    assert box.key(1, True) == "" and box.key(1, False) == ""
    box.send("*ATX;")
    assert box.send("!1B256;!1X04;") == "!1F2;!1f2;!1X;"
    assert box.key(1, True) == "<12;"
    assert box.key(1, False) == ">12;"
    box.send("*atx;")
    assert box.send("!1B3;") == "" and box.key(1, True) == ""


def test_receive_event_shows_the_transmit_antenna_when_receiving_on_it() -> None:
    box = active_box("T")
    box.send("!1T1;!1R2;")
    box.key(1, True)
    assert box.key(1, False) == ">11;"


def test_inhibit_replies_only_when_enabled_and_active() -> None:
    box = SteppedBox()
    assert box.send("*I;(12;") == ""
    box.send("*1;")
    assert box.send("(3;") == "(123;"
    assert box.send(")12;") == ")3;"
    box.send("*i;")
    assert box.send("(1;") == ""


def test_vendor_extension_answers_with_its_name() -> None:
    assert SteppedBox().send("#anything;") == "#moas-gui-emulator;"


def test_phase_is_receive_for_every_station_at_rest() -> None:
    box = active_box()
    assert all(st.phase is StationPhase.RECEIVE for st in box.model.view().stations)
