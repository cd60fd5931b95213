"""The YCCC MOAS II switch: its protocol (sans-IO codec), an emulator of its
firmware, and the switch link that drives one box for the server.

* :mod:`.sixbit`, :mod:`.messages`, :mod:`.commands`, :mod:`.replies`,
  :mod:`.decoder`: the codec (no ports, no clock).
* :mod:`.emulator`: the firmware as a pure model, and the pieces that run it
  in real time on a pseudo-terminal or serial port.
* :mod:`.sync`: the commands that take a box from one state to another (one planner).
* :mod:`.resync`: what a box found on (re)connection is taken to hold.
* :mod:`.plan`: which plan a session sends (:func:`.plan.choose_plan`) and the safety
  rule every plan passes (:func:`.plan.guard`).
* :mod:`.session`, :mod:`.phases`: every decision about one box, as a pure state machine.
* :mod:`.transport`, :mod:`.link`: the port seam and the link itself (the session's
  driver).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .commands import MAX_COMMAND, MAX_PAIRS, MAX_RELAYS, encode, encode_all, parse_command, split
from .decoder import SwitchDecoder
from .errors import (
    CommandRejected,
    CommandTooLong,
    EncodeError,
    Moas2Error,
    PortError,
    RelayListTooLong,
)
from .replies import encode_reply, parse_reply

if TYPE_CHECKING:
    from .link import EMULATOR_PORT, LinkStatus, LinkTiming, SwitchLink
    from .sync import CommandPlan, count_bytes, difference, initialise

_FROM_LINK = frozenset({"EMULATOR_PORT", "LinkStatus", "LinkTiming", "SwitchLink"})
"""Names of :mod:`.link`, imported when first asked for: the codec alone loads
neither asyncio nor pyserial."""

_FROM_SYNC = frozenset({"CommandPlan", "count_bytes", "difference", "initialise"})
"""Names of :mod:`.sync`, imported when first asked for too: the planner reads the
engine's switch state, so importing it loads the engine and the configuration, which
the codec and the emulator (``moas-emulator``) do without."""


def __getattr__(name: str) -> object:
    if name in _FROM_LINK:
        from . import link

        return getattr(link, name)
    if name in _FROM_SYNC:
        from . import sync

        return getattr(sync, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "EMULATOR_PORT",
    "MAX_COMMAND",
    "MAX_PAIRS",
    "MAX_RELAYS",
    "CommandPlan",
    "CommandRejected",
    "CommandTooLong",
    "EncodeError",
    "LinkStatus",
    "LinkTiming",
    "Moas2Error",
    "PortError",
    "RelayListTooLong",
    "SwitchDecoder",
    "SwitchLink",
    "count_bytes",
    "difference",
    "encode",
    "encode_all",
    "encode_reply",
    "initialise",
    "parse_command",
    "parse_reply",
    "split",
]
