"""The MOAS II emulator: the firmware as a pure model (:mod:`.model`), an
asyncio driver that keeps its timers (:mod:`.box`), and a pseudo-terminal or
serial port to serve it on (:mod:`.serve`)."""

from __future__ import annotations

from .model import INPUT_BUFFER, EmulatorModel
from .station import Slot, SlotRole, StationPhase
from .view import BoxView, StationView

Kind = SlotRole
"""The package's public name (frozen by tests/hw/test_moas2_api.py) for :class:`SlotRole`."""
Phase = StationPhase
"""The package's public name (frozen by tests/hw/test_moas2_api.py) for :class:`StationPhase`."""

__all__ = ["INPUT_BUFFER", "BoxView", "EmulatorModel", "Kind", "Phase", "Slot", "StationView"]
