"""The public names of the MOAS II package, frozen: a change here is a
change for the server, the engine tests and anyone driving a switch."""

from __future__ import annotations

from moas_gui.hw import moas2
from moas_gui.hw.moas2 import emulator
from moas_gui.hw.moas2.link import SwitchLink


def test_package_names_are_frozen() -> None:
    assert sorted(moas2.__all__) == sorted([
        "EMULATOR_PORT", "MAX_COMMAND", "MAX_PAIRS", "MAX_RELAYS", "CommandRejected",
        "CommandTooLong", "EncodeError", "LinkStatus", "LinkTiming", "Moas2Error", "CommandPlan",
        "PortError", "RelayListTooLong", "SwitchDecoder", "SwitchLink", "count_bytes",
        "difference", "encode", "encode_all", "encode_reply", "initialise", "parse_command",
        "parse_reply", "split",
    ])
    for name in moas2.__all__:
        assert hasattr(moas2, name), name


def test_emulator_names_are_frozen() -> None:
    assert sorted(emulator.__all__) == sorted([
        "INPUT_BUFFER", "BoxView", "EmulatorModel", "Kind", "Phase", "Slot", "StationView",
    ])


def test_switch_link_calls_the_server_makes_are_there() -> None:
    for name in ("apply", "connect", "close", "stop", "start", "reset", "save_data",
                 "ask_relays", "status", "ready"):
        assert hasattr(SwitchLink, name), name
    link = SwitchLink(1, "emulator")
    assert link.emulator is not None
    assert link.status.value == "connecting"
