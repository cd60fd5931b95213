"""moas_gui.engine: antenna selection and the rules of the MOAS II manual, with no I/O.

``Engine(config)`` takes inputs (frequencies, T/R events, button presses,
functions, directions) and returns :class:`Changes`: the radios whose view
changed, the complete wanted :class:`SwitchState` of each switch that changed,
and sentences for the operator.  See ``docs/engine.md`` for every rule.
"""

from moas_gui.config.model import RadioRef

from .changes import NO_CHANGES, Changes
from .engine import Engine
from .errors import BadRequest, EngineError, NotFound, NotRunning, Unavailable
from .switchstate import NO_ANTENNA, StationAntennas, SwitchState
from .views import AntennaView, ButtonView, LayoutView, RadioView

__all__ = [
    "NO_ANTENNA",
    "NO_CHANGES",
    "AntennaView",
    "BadRequest",
    "ButtonView",
    "Changes",
    "Engine",
    "EngineError",
    "LayoutView",
    "NotFound",
    "NotRunning",
    "RadioRef",
    "RadioView",
    "StationAntennas",
    "SwitchState",
    "Unavailable",
]
