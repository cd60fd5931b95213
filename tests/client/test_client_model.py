"""Typed views of the server's JSON: what is read, and what is refused with which words."""

from __future__ import annotations

import pytest

from moas_gui.client.model import (
    ButtonState,
    ButtonType,
    RadioView,
    RotatorView,
    SwitchView,
    parse_layout,
    parse_radio,
    parse_rotator,
    parse_snapshot,
)
from moas_gui.errors import ProtocolError

STATE = {
    "event": "state", "config": "big-station.moas",
    "radios": [{"station": 1, "radio": 1, "khz": 14025.0, "tx_khz": 14025.0, "tx": 6, "rx": 6,
                "alt": None, "transmitting": False, "inhibited": False, "note": ""}],
    "antennas": [{"id": 6, "short": "All", "long": "20m stack all", "rotator": 1}],
    "rotators": [{"id": 1, "short": "20 Top", "heading": 45, "target": None, "moving": False,
                  "online": True}],
    "switches": [{"id": 1, "status": "ok"}],
}


def test_the_contract_example_snapshot_is_read_whole() -> None:
    snapshot = parse_snapshot(STATE)
    assert snapshot.config == "big-station.moas"
    assert snapshot.radio(1, 1) == RadioView(1, 1, 14025.0, 14025.0, 6, 6)
    assert snapshot.antenna(6).name == "20m stack all"  # type: ignore[union-attr]
    assert snapshot.antenna(6).offset == 0.0  # type: ignore[union-attr]
    assert snapshot.rotator(1) == RotatorView(1, "20 Top", heading=45.0)
    assert snapshot.rotator(1).travel_known is False  # type: ignore[union-attr]
    assert snapshot.switches == (SwitchView(1, "ok"),)
    assert snapshot.stations == (1,) and snapshot.radios_of(1) == (1,)


def test_fields_the_protocol_may_grow_are_read_when_present() -> None:
    rotator = parse_rotator({"id": 3, "heading": 10, "ccw_limit": 180, "rotation": 450,
                             "has_stop": True, "electrical": False, "long": "Tower beam",
                             "something_new": [1, 2]})
    assert (rotator.ccw_limit, rotator.rotation, rotator.has_stop) == (180.0, 450.0, True)
    assert rotator.travel_known
    radio = parse_radio({"station": 2, "radio": 1, "relative": [3, 4]})
    assert radio.relative == (3, 4)
    assert radio.radio_rx_antenna is False
    assert parse_radio({"station": 2, "radio": 1, "radio_rx_antenna": True}).radio_rx_antenna


@pytest.mark.parametrize(("entry", "words"), [
    ({"radio": 1}, "radio event has no 'station' field"),
    ({"station": "1", "radio": 1}, "'station' is the string '1', not a whole number"),
    ({"station": 1, "radio": 1, "khz": "fast"}, "'khz' is the string 'fast', not a number"),
    ({"station": 1, "radio": 1, "transmitting": 1}, "'transmitting' is the number 1, not true"),
    ({"station": True, "radio": 1}, "'station' is true, not a whole number"),
    ({"station": 1, "radio": 1, "relative": [1, "x"]}, "relative[1] is the string 'x'"),
    ({"station": 1, "radio": 1, "radio_rx_antenna": 1}, "'radio_rx_antenna' is the number 1"),
    ([1, 2], "radio event is a list, not a JSON object"),
])
def test_a_wrong_field_is_refused_naming_the_field(entry: object, words: str) -> None:
    with pytest.raises(ProtocolError, match=words.replace("[", r"\[").replace("]", r"\]")):
        parse_radio(entry, "radio event")


def test_a_bad_entry_in_a_list_is_named_by_its_position() -> None:
    broken = dict(STATE, antennas=[{"id": 6}, {"id": "seven"}])
    with pytest.raises(ProtocolError, match=r"state antennas\[1\]: 'id' is the string 'seven'"):
        parse_snapshot(broken)


def test_layout_buttons_are_typed_and_unknown_states_refused() -> None:
    layout = parse_layout({"station": 1, "radio": 1, "rows": 4, "columns": 3, "buttons": [
        {"row": 3, "column": 2, "type": "Function", "id": 0, "label": "Swap",
         "state": "available"}]})
    button = layout.button_at(3, 2)
    assert button is not None and button.type is ButtonType.FUNCTION
    assert button.state is ButtonState.AVAILABLE and layout.button_at(0, 0) is None
    with pytest.raises(ProtocolError, match=r"buttons\[0\]: 'state' is 'pressed', not selected"):
        parse_layout({"station": 1, "radio": 1, "rows": 1, "columns": 1, "buttons": [
            {"row": 0, "column": 0, "type": "Antenna", "id": 1, "label": "x",
             "state": "pressed"}]})


def test_change_events_replace_one_entry_and_keep_the_rest() -> None:
    snapshot = parse_snapshot(STATE)
    moved = snapshot.with_rotator(RotatorView(1, "20 Top", heading=90.0))
    assert moved.rotator(1).heading == 90.0  # type: ignore[union-attr]
    assert snapshot.rotator(1).heading == 45.0  # type: ignore[union-attr]
    added = moved.with_radio(RadioView(2, 1, 7000.0))
    assert added.stations == (1, 2) and added.antenna(6) is not None
    assert added.with_switch(SwitchView(1, "stopped")).switches[0].status == "stopped"


def test_the_client_packages_public_names_are_frozen() -> None:
    from moas_gui import client

    assert sorted(client.__all__) == sorted([
        "DEFAULT_PORT", "AntennaView", "Backoff", "ButtonState", "ButtonType", "ButtonView",
        "ClientConnection", "ClientError", "ClientEvent", "ConnectionLost", "LayoutChanged",
        "LayoutView", "LinkChanged", "LinkState", "LogReceived", "NotConnected", "ProblemSeen",
        "RadioChanged", "RadioView", "RequestTimeout", "RotatorChanged", "RotatorView",
        "Selection", "ServerError", "Snapshot", "StateReceived", "SwitchChanged", "SwitchView",
        "TokenWanted", "parse_address",
    ])
    assert all(hasattr(client, name) for name in client.__all__)
