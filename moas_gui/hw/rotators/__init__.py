"""Rotators for the server: the heading rules, one driver per kind of rotator
(Test, Electrical, Serial through the MOAS Rotator program, Rotator Genius,
Hamlib rotctld) and the manager that serves them to clients.

The serial controllers themselves and the MOAS Rotator program live in
``controllers/`` and ``moas_gui.rotator_program``; the stand-ins tests use for
a MOAS Rotator program and a Rotator Genius are in :mod:`moas_gui.testing`.
See ``docs/rotators.md``.
"""

from .base import RotatorError, RotatorStatus, RotatorView, Timing
from .headings import (
    Travel,
    Turn,
    angular_distance,
    antenna_heading,
    closest_direction,
    normalize,
    plan_turn,
    rotator_heading_for,
)
from .manager import RotatorManager

__all__ = [
    "RotatorError", "RotatorManager", "RotatorStatus", "RotatorView", "Timing", "Travel", "Turn",
    "angular_distance", "antenna_heading", "closest_direction", "normalize", "plan_turn",
    "rotator_heading_for",
]
