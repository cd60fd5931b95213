"""Global relay numbers: which switch a relay belongs to, and its number on that switch.

The configuration numbers relays across every switch: switch N owns relays
(N-1)*100 to (N-1)*100+63, and a switch itself knows only 0-63
(``docs/engine.md``).  Every conversion between the two lives here.
"""

from __future__ import annotations

SWITCH_STRIDE = 100
"""Global relay numbers between the first relays of two neighbouring switches."""

LAST_LOCAL_RELAY = 63
"""The highest relay number a switch has (its relays are 0-63)."""


def first_relay(switch_id: int) -> int:
    """The global number of relay 0 of switch ``switch_id``."""
    return (switch_id - 1) * SWITCH_STRIDE


def last_relay(switch_id: int) -> int:
    """The global number of relay 63 of switch ``switch_id``."""
    return first_relay(switch_id) + LAST_LOCAL_RELAY


def relay_span(switch_id: int) -> str:
    """``"100-163"``: the global relays of switch ``switch_id``, for messages."""
    return f"{first_relay(switch_id)}-{last_relay(switch_id)}"


def switch_of_relay(relay: int) -> int:
    """The switch that global relay ``relay`` would belong to."""
    return relay // SWITCH_STRIDE + 1


def local_relay(relay: int) -> int:
    """The number (0-99) global relay ``relay`` has on its own switch; 64-99 do not exist."""
    return relay - first_relay(switch_of_relay(relay))


def relay_exists(relay: int) -> bool:
    """Whether a switch has relay ``relay`` at all (its local number is 0-63)."""
    return 0 <= local_relay(relay) <= LAST_LOCAL_RELAY


def owns_relay(switch_id: int, relay: int) -> bool:
    """Whether global relay ``relay`` is one of switch ``switch_id``'s."""
    return first_relay(switch_id) <= relay <= last_relay(switch_id)


def local_relays(relays: frozenset[int], switch_id: int) -> frozenset[int]:
    """The relays of ``relays`` that belong to ``switch_id``, as that switch numbers them."""
    base = first_relay(switch_id)
    return frozenset(r - base for r in relays if owns_relay(switch_id, r))


RELAY_RULE = "switch N has relays (N-1)*100 to (N-1)*100+63 only"
"""The numbering rule in words, for messages."""

__all__ = [
    "LAST_LOCAL_RELAY",
    "RELAY_RULE",
    "SWITCH_STRIDE",
    "first_relay",
    "last_relay",
    "local_relay",
    "local_relays",
    "owns_relay",
    "relay_exists",
    "relay_span",
    "switch_of_relay",
]
