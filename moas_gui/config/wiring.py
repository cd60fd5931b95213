"""Warnings about what the switches can do with the radios as wired (``--check``).

* Radio-to-radio inhibits (5.11: ``Always``, ``SameBand``, inhibit busses) are applied by
  a switch that sees both radios' ports: it reads the transmitting radio's T/R line and
  drives the other's inhibit output.  Two radios with no common switch cannot inhibit
  each other, so the entry is reported and the server does not claim the inhibit.
* A switch has one interrupt-mode delay for all its stations (switch programming manual:
  "The delay can be set from 0 to 99 ms and affects all stations"); different
  ``InterruptModeDelay`` values of interrupt-mode radios on one switch cannot all be had
  (the largest is used).
"""

from __future__ import annotations

from . import model as m
from .reading import Reading


def _switches(config: m.Config, radio: m.Radio) -> frozenset[int]:
    only = config.switches[0].id if len(config.switches) == 1 else None
    return frozenset(switch_id for sp in radio.switches
                     if (switch_id := sp.switch or only) is not None)


def check_wiring(config: m.Config, reading: Reading) -> None:
    """Add a warning to ``reading`` for every inhibit or delay the switches cannot apply."""
    radios = {r.ref: r for r in config.radios}
    for radio in config.radios:
        _named_inhibits(config, reading, radio, radios)
        _buss_inhibits(config, reading, radio)
    for switch in config.switches:
        _interrupt_delays(config, reading, switch)


def _named_inhibits(config: m.Config, reading: Reading, radio: m.Radio,
                    radios: dict[m.RadioRef, m.Radio]) -> None:
    """A radio's ``Always`` or ``SameBand`` naming a radio with no switch in common."""
    label = f"station {radio.station} radio {radio.radio}"
    mine = _switches(config, radio)
    for key, refs in (("Always", radio.always), ("SameBand", radio.same_band)):
        for ref in refs:
            other = radios.get(ref)
            if other is None or other.ref == radio.ref:
                continue
            if not mine & _switches(config, other):
                reading.warning(
                    reading.at(ref), f"{label}'s \"{key}\" names station {ref.station} "
                    f"radio {ref.radio}, but no switch has ports of both radios, so no switch "
                    "can inhibit one while the other transmits; wire them to a common switch")


def _buss_inhibits(config: m.Config, reading: Reading, radio: m.Radio) -> None:
    """A radio sharing an inhibit buss with a later radio that has no switch in common."""
    label = f"station {radio.station} radio {radio.radio}"
    mine = _switches(config, radio)
    for other in config.radios:
        if other.ref <= radio.ref:
            continue
        common = set(radio.inhibit_buss) & set(other.inhibit_buss)
        if common and not mine & _switches(config, other):
            reading.warning(
                reading.at(radio, "InhibitBuss"), f"{label} and station {other.station} "
                f"radio {other.radio} share inhibit buss {min(common)}, but no switch has "
                "ports of both radios, so neither can inhibit the other")


def _interrupt_delays(config: m.Config, reading: Reading, switch: m.Switch) -> None:
    """Interrupt-mode radios on one switch asking for different delays: each that does
    not get its own (the largest is used) is told so."""
    asking: dict[int, list[m.Radio]] = {}
    for radio in config.radios:
        if radio.interrupt and radio.interrupt_mode_delay is not None \
                and switch.id in _switches(config, radio):
            asking.setdefault(radio.interrupt_mode_delay, []).append(radio)
    if len(asking) < 2:
        return
    largest = max(max(asking), switch.interrupt_mode_delay)
    listing = ", ".join(f"station {r.station} radio {r.radio} {delay} ms"
                        for delay, rs in sorted(asking.items()) for r in rs)
    for delay, rs in sorted(asking.items()):
        if delay == largest:
            continue
        for r in rs:
            reading.warning(
                reading.at(r, "InterruptModeDelay"), f"switch {switch.id} has one "
                f"interrupt delay for all its stations ({listing}); {largest} ms is used "
                f"for station {r.station} radio {r.radio} too")


__all__ = ["check_wiring"]
