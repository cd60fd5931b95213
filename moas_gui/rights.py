"""What a change touches, for the role check (:func:`moas_gui.net.identity.check`).

The engine's operations name the radio they act for; a function may touch other
radios too (an antenna swap, a transfer), named in its parameters; a rotator
belongs to the radios whose antennas it turns.  These functions turn each into an
:class:`~moas_gui.net.identity.Action` -- pure reading of the configuration and the
engine's views, no decision of their own.
"""

from __future__ import annotations

from moas_gui.config.model import Config
from moas_gui.engine import Engine
from moas_gui.engine.operations import (
    Hold,
    Operation,
    Relative,
    RunFunction,
    Select,
    SetFrequency,
    StartSwitches,
    StopSwitches,
)
from moas_gui.net.identity import Action, RadioRef

FUNCTION_RADIOS: dict[str, tuple[int, ...]] = {
    "AntennaSwap": (0, 2),
    "Relay": (1,),
    "Inhibit": (0,),
    "Extra": (0, 2),
    "Partner": (0, 2),
    "AltActive": (0, 2),
}
"""Where each function kind names radios in its numbers (``Station, Radio`` pairs)."""


def function_radios(config: Config, station: int, radio: int, function: int
                    ) -> frozenset[RadioRef]:
    """The radio asking, and every existing radio the function names."""
    radios: set[RadioRef] = {(station, radio)}
    found = next((f for f in config.functions if f.id == function), None)
    if found is None:
        return frozenset(radios)
    known = {(r.station, r.radio) for r in config.radios}
    params = found.int_params
    for at in FUNCTION_RADIOS.get(found.name, ()):
        if len(params) >= at + 2 and (params[at], params[at + 1]) in known:
            radios.add((params[at], params[at + 1]))
    return frozenset(radios)


def action_for(op: Operation, config: Config) -> Action | None:
    """The :class:`Action` an operation asked by a client is; None for what only the
    server itself does (a station's T/R, a rotator's heading, the box's own antennas),
    which no client can ask for and no role check concerns."""
    match op:
        case SetFrequency(station=s, radio=r):
            return Action(f"tuning radio {s}/{r}", frozenset({(s, r)}))
        case Select(station=s, radio=r) | Relative(station=s, radio=r):
            return Action(f"selecting antennas of radio {s}/{r}", frozenset({(s, r)}))
        case Hold(station=s, radio=r, by=None):
            return Action(f"releasing the hold of radio {s}/{r}", frozenset({(s, r)}))
        case Hold(station=s, radio=r):
            return Action(f"holding radio {s}/{r}", frozenset({(s, r)}))
        case RunFunction(station=s, radio=r, function=f):
            return Action(f"function {f} for radio {s}/{r}", function_radios(config, s, r, f))
        case StopSwitches() | StartSwitches():
            return Action("stopping or starting the switches", admin=True)
    return None


def rotator_radios(engine: Engine, rotator: int) -> frozenset[RadioRef]:
    """The radios whose transmit or receive antenna the rotator turns."""
    config = engine.config
    turned = {a.id for a in config.antennas if a.rotator == rotator}
    return frozenset((v.station, v.radio) for v in engine.radios()
                     if v.tx in turned or v.rx in turned)


__all__ = ["FUNCTION_RADIOS", "action_for", "function_radios", "rotator_radios"]
