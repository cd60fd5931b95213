"""What clients are told of a decision leads with what decided it (issue 30 point 4)."""

from __future__ import annotations

from pathlib import Path

from moas_gui.config import load_config
from moas_gui.engine import Engine

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def engine_for(name: str) -> Engine:
    return Engine(load_config(EXAMPLES / name).config)


def test_clients_are_not_told_of_antennas_that_merely_do_not_cover_the_frequency() -> None:
    engine = engine_for("small-station.moas")
    changes = engine.set_frequency(1, 1, 7025.0)
    view = engine.radio_view(1, 1)
    assert view.why is not None
    full = view.why.to_dict()
    told = view.to_dict()["why"]
    assert any(p["reason"].startswith("does not cover") for p in full["passed_over"])
    assert not any(p["reason"].startswith("does not cover") for p in told["passed_over"])
    assert told["text"] == full["text"]
    # the Debug log still lists every antenna passed over
    assert any("does not cover 7025 kHz" in line for line in changes.details)


def test_a_conflict_passed_over_is_still_told() -> None:
    engine = engine_for("tribander-stack.moas")
    engine.set_frequency(1, 1, 14025.0)
    engine.set_frequency(1, 2, 14030.0)
    told = engine.radio_view(1, 2).to_dict()["why"]
    kept = [p["reason"] for p in told["passed_over"]]
    assert kept and all(not r.startswith("does not cover") for r in kept)


def test_an_unavailable_button_carries_the_refusal_a_press_would_get() -> None:
    engine = engine_for("big-station.moas")
    engine.set_frequency(1, 1, 14025.0)
    engine.set_frequency(2, 1, 14025.0)
    layout = engine.layout(2, 1, 4, 4)
    unavailable = [b for b in layout.buttons if b.state == "unavailable"]
    assert unavailable and all(b.reason for b in unavailable)
    assert all("reason" not in b.to_dict() for b in layout.buttons if b.state != "unavailable")
    button = next(b for b in unavailable if b.type == "Antenna")
    try:
        engine.select(2, 1, button.id)
    except Exception as refusal:  # noqa: BLE001 - the refusal's words are what is compared
        assert str(refusal) == button.reason
    else:
        raise AssertionError(f"{button.label} was pressed although shown unavailable")
