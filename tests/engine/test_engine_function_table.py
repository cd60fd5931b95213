"""The ten function kinds are one table: a check, a status, an is-on (toggles only) and a
run per kind, and every entry point of the engine goes through it."""

from __future__ import annotations

import pytest
from engine_builders import config, engine, radio, so2r

from moas_gui.config.model import FUNCTION_NAMES, Function
from moas_gui.engine.errors import Unavailable
from moas_gui.engine.function_kinds import KINDS

TOGGLES = {"Share", "Relay", "Inhibit", "Extra", "Partner", "AltActive"}


def test_one_entry_per_kind_of_the_manual() -> None:
    assert tuple(KINDS) == FUNCTION_NAMES
    for name, kind in KINDS.items():
        assert kind.name == name
        assert (kind.is_on is not None) == (name in TOGGLES), name


@pytest.mark.parametrize("name", sorted(set(FUNCTION_NAMES) - {"RXTX", "Store", "Recall"}))
def test_a_function_with_bad_parameters_is_unavailable_with_the_reason(name: str) -> None:
    e = engine(so2r(functions=[Function(id=7, name=name, short_name="F",
                                        int_params=(9, 9, 9, 9, 9))]))
    available, reason = e.function_status(1, 1, 7)
    assert not available
    assert reason.startswith("function 7 (F)"), reason
    assert not e.function_on(7)
    with pytest.raises(Unavailable, match="F is not available: function 7"):
        e.run_function(1, 1, 7)


def test_an_unknown_kind_is_unavailable() -> None:
    cfg = config([], [radio(1, 1, 1)], functions=[Function(id=1, name="Teleport")])
    e = engine(cfg)
    assert e.function_status(1, 1, 1) == (
        False, "function 1 (Teleport) has a name the server does not know: 'Teleport'")
