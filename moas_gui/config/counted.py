"""Problems about long lists, told once per kind with a count.

A list of a thousand wrong relays is one mistake made a thousand times: the
checks report it once, at the first culprit, with how many there are and the
first few of them.  A single culprit keeps its own plain sentence.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Sequence

from .reading import Reading
from .relays import RELAY_RULE, relay_exists, relay_span, switch_of_relay

MAX_RELAYS_PER_COMMAND = 35
"""One MOAS II antenna command of at most 40 bytes carries at most 35 relays, and a
second command for the same station replaces the first (``docs/switch.md``)."""

SHOWN = 5
"""How many culprits a counted problem names before "and N more"."""


def listed(values: Sequence[object], shown: int = SHOWN) -> str:
    """``1, 2, 3, 4, 5 and 155 more``, or ``1, 2 and 3`` for a short list."""
    words = [str(v) for v in values[:shown]]
    rest = len(values) - len(words)
    if rest:
        return f"{', '.join(words)} and {rest:,} more"
    if len(words) == 1:
        return words[0]
    return f"{', '.join(words[:-1])} and {words[-1]}"


def _configured(switches: set[int]) -> str:
    ranges = ", ".join(f"{relay_span(s)} on switch {s}" for s in sorted(switches))
    return f" (relays: {ranges})" if ranges else ""


def relay_problems(reading: Reading, switches: set[int], owner: object, key: str,
                   relays: Iterable[int], what: str) -> None:
    """Relays of ``owner``'s ``key``: at most one command's worth per switch, all existing."""
    ordered = sorted(relays)
    per_switch = Counter(switch_of_relay(relay) for relay in ordered)
    crowded = [(s, n) for s, n in sorted(per_switch.items()) if n > MAX_RELAYS_PER_COMMAND]
    if len(crowded) == 1:
        (switch_id, count), = crowded
        reading.error(reading.at(owner, key), f"{what} sets {count} relays on switch "
                      f"{switch_id} at once; a MOAS II command carries at most "
                      f"{MAX_RELAYS_PER_COMMAND}")
    elif crowded:
        reading.error(reading.at(owner, key), f"{what} sets more than "
                      f"{MAX_RELAYS_PER_COMMAND} relays at once on {len(crowded):,} switches "
                      f"({listed([f'switch {s}: {n}' for s, n in crowded])}); a MOAS II "
                      f"command carries at most {MAX_RELAYS_PER_COMMAND}")
    # a relay of a switch that is not configured is named as such first, whatever its number
    absent = [relay for relay in ordered
              if not relay_exists(relay) and switch_of_relay(relay) in switches]
    if len(absent) == 1:
        relay = absent[0]
        switch_id = switch_of_relay(relay)
        reading.error(reading.at(owner, key, relay),
                      f"{what} names relay {relay}; switch {switch_id} has relays "
                      f"{relay_span(switch_id)} only")
    elif absent:
        reading.error(reading.at(owner, key, absent[0]),
                      f"{what} names {len(absent):,} relays that no switch has "
                      f"({listed(absent)}); {RELAY_RULE}")
    foreign = [relay for relay in ordered if switch_of_relay(relay) not in switches]
    unknown = sorted({switch_of_relay(relay) for relay in foreign})
    if len(foreign) == 1:
        relay = foreign[0]
        reading.error(reading.at(owner, key, relay),
                      f"{what} names relay {relay}, which belongs to switch {switch_of_relay(relay)}, "
                      "but there is no such switch in \"Switches\"" + _configured(switches))
    elif len(unknown) == 1:
        reading.error(reading.at(owner, key, foreign[0]),
                      f"{what} names {len(foreign):,} relays ({listed(foreign)}) of switch "
                      f"{unknown[0]}, but there is no such switch in \"Switches\"")
    elif foreign:
        reading.error(reading.at(owner, key, foreign[0]),
                      f"{what} names {len(foreign):,} relays ({listed(foreign)}) of switches "
                      f"that are not in \"Switches\" ({listed(unknown)})")


def missing_problems(reading: Reading, owner: object, key: str, missing: Sequence[int],
                     what: str, plural: str, one: str) -> None:
    """``missing`` ids named by ``owner``'s ``key`` that the file does not define."""
    if len(missing) == 1:
        reading.error(reading.at(owner, key, missing[0]), one)
    elif missing:
        reading.error(reading.at(owner, key, missing[0]), f"{what} names {len(missing):,} "
                      f"{plural} ({listed(missing)})")


__all__ = ["MAX_RELAYS_PER_COMMAND", "SHOWN", "listed", "missing_problems", "relay_problems"]
