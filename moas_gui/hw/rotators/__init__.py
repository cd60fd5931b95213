"""Rotators for the server: the heading rules, one driver per kind of rotator
(Test, Electrical, Serial through the MOAS Rotator program, Rotator Genius,
Hamlib rotctld) and the manager that serves them to clients.

The serial controllers themselves and the MOAS Rotator program live in
``controllers/`` and ``moas_gui.rotator_program``; the stand-ins tests use for
a MOAS Rotator program and a Rotator Genius are in :mod:`moas_gui.testing`.
See ``docs/rotators.md``.

The package's names are imported from their modules when first asked for: the MOAS
Rotator program (``moas-rotator``), which needs only ``controllers/`` and the codec,
loads neither the drivers nor the configuration they read.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
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

_WHERE = {
    "RotatorError": "base", "RotatorStatus": "base", "RotatorView": "base", "Timing": "base",
    "Travel": "headings", "Turn": "headings", "angular_distance": "headings",
    "antenna_heading": "headings", "closest_direction": "headings", "normalize": "headings",
    "plan_turn": "headings", "rotator_heading_for": "headings",
    "RotatorManager": "manager",
}
"""The module of each name the package hands out."""


def __getattr__(name: str) -> object:
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from importlib import import_module

    return getattr(import_module(f"{__name__}.{where}"), name)


__all__ = [
    "RotatorError", "RotatorManager", "RotatorStatus", "RotatorView", "Timing", "Travel", "Turn",
    "angular_distance", "antenna_heading", "closest_direction", "normalize", "plan_turn",
    "rotator_heading_for",
]
