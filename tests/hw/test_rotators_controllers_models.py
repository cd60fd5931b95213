"""The model registry (numbers and names) and the public names of the controllers package."""

from __future__ import annotations

import pytest

from moas_gui.hw.rotators.controllers import base, models, pty_host
from moas_gui.hw.rotators.controllers.base import UnknownModel
from moas_gui.hw.rotators.controllers.models import MODELS, find_model, is_model_name


@pytest.mark.parametrize(
    ("text", "name"),
    [
        ("1", "DCU1"),
        ("2", "RotorEZ"),
        ("4", "Yaesu"),
        ("5", "Alfaspid"),
        ("8", "RC2800P-A"),
        ("9", "RC2800P-X"),
        ("10", "Prosistel D"),
        ("04", "Yaesu"),
        ("dcu-1", "DCU1"),
        ("Rotor-EZ", "RotorEZ"),
        ("GS-232B", "Yaesu"),
        ("gs232a", "GS-232A"),
        ("prosistel d", "Prosistel D"),
        ("Prosistel", "Prosistel D"),
        ("rc2800p_a", "RC2800P-A"),
        ("Rot2Prog", "Rot2Prog"),
    ],
)
def test_models_are_found_by_moas_number_or_by_name(text: str, name: str) -> None:
    assert find_model(text).name == name


@pytest.mark.parametrize("text", ["3", "6", "7", "11", "Hygain", ""])
def test_unknown_models_are_refused_with_the_list_of_known_ones(text: str) -> None:
    with pytest.raises(UnknownModel, match="known: 1 DCU1, 2 RotorEZ, 4 Yaesu"):
        find_model(text)


def test_numbers_are_not_model_names() -> None:
    assert is_model_name("Yaesu") and not is_model_name("4") and not is_model_name("COM4")


def test_each_model_has_the_serial_speed_of_its_controller() -> None:
    speeds = {m.name: m.info.serial.baudrate for m in MODELS}
    assert speeds == {"DCU1": 4800, "RotorEZ": 4800, "Yaesu": 9600, "GS-232A": 9600,
                      "Alfaspid": 1200, "Rot1Prog": 1200, "Rot2Prog": 600,
                      "RC2800P-A": 9600, "RC2800P-X": 9600, "Prosistel D": 9600}


def test_every_model_has_an_emulator_that_starts_where_it_is_told() -> None:
    for model in MODELS:
        emulator = model.make_emulator(azimuth=100.0, speed=6.0, now=0.0)
        assert emulator.azimuth == pytest.approx(100.0), model.name


def test_public_names_do_not_drift() -> None:
    assert sorted(models.__all__) == ["MODELS", "Model", "find_model", "is_model_name",
                                      "known_models"]
    assert sorted(pty_host.__all__) == ["EmulatorHost", "IDLE_WAIT", "ServedPort", "TICK"]
    assert {"Ack", "Garbage", "Heading", "Notice", "Send", "ControllerCodec",
            "ControllerEmulator", "ModelInfo", "UnknownModel", "OutOfRange"} <= set(base.__all__)
