"""What the running server tells the antenna journal, and when.

The app's antenna feed (moas_gui/antenna_feed.py) calls these on the loop; each only
compares with what it last recorded and, on a change, queues one small tuple for the
journal's writer thread
(:class:`~moas_gui.antenna_log.journal.Journal`): nothing here touches the file, and
nothing is on the path from a band change to the switch (the switch hears first; this
hears what the box then reports).

* :meth:`AntennaRecorder.landed`: a switch reported the antennas it holds for a port
  (its antenna events, or its status at a survey).  Each of that port's radio's
  roles (transmit, receive, alternate; for a sub receiver on a port of its own, its
  receive antenna as its main radio's ``sub`` role) is recorded when the box holds the slot of the
  antenna the engine wants for it (what the box CONFIRMED, timed when it landed) and
  that antenna differs from the one recorded last.  Until it lands nothing is recorded
  (the relay dwell, a box that refused, a box away).
* :meth:`~AntennaRecorder.transmitting`: a radio keyed or unkeyed (the switch's T/R).
* :meth:`~AntennaRecorder.rotator`: a rotator's view; its heading is recorded when it
  has settled (not moving, online, a heading known) on a heading other than the last
  recorded one.
* :meth:`~AntennaRecorder.switches_running`: Stop Switches (every relay off: no
  antenna in force) and Start Switches.
* :meth:`~AntennaRecorder.chosen_by`: an operator's request changed a radio's
  antennas; the next change that lands for that radio within
  :data:`OPERATOR_WINDOW` seconds carries the operator's name.
* :meth:`~AntennaRecorder.contact`: a logger's contact packet.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Final

from moas_gui.antenna_log.journal import AntennaInfo, Journal
from moas_gui.antenna_log.records import ContactPacket, Role
from moas_gui.config import Config
from moas_gui.engine import NO_ANTENNA, Engine

OPERATOR_WINDOW: Final = 10.0
"""Seconds an operator's request names the antenna changes that land after it."""
_ROLES: Final[tuple[Role, Role, Role]] = ("tx", "rx", "alt")


def switch_path(switch_id: int, port: int, slot: int) -> str:
    """The relay path of an antenna as the journal writes it: the switch, the station
    port of that switch the radio is wired to, and the antenna slot the box reported."""
    return f"switch {switch_id} port {port} slot {slot}"


class AntennaRecorder:
    """The journal's view of one running configuration (one per :class:`Running`)."""

    def __init__(self, journal: Journal, config: Config, engine: Engine, *,
                 clock: Callable[[], float] = time.time) -> None:
        self.journal = journal
        self._engine = engine
        self._clock = clock
        views = engine.antenna_views()
        self._names = {a.id: a.long or a.short or f"Antenna {a.id}" for a in views}
        rotators = {r.id: r.label for r in config.rotators}
        journal.describe(
            AntennaInfo(self._names[a.id],
                        rotators.get(a.rotator) if a.rotator is not None else None,
                        float(a.offset))
            for a in views)
        self._rotators = rotators
        self._antennas: dict[tuple[int, int, Role], str] = {}
        self._keyed: dict[tuple[int, int], bool] = {}
        self._headings: dict[int, float] = {}
        self._chosen: dict[tuple[int, int], tuple[str, float]] = {}
        self._running = engine.running
        self._main_of = {(r.station, r.sub_receiver): (r.station, r.radio)
                         for r in config.radios if r.sub_receiver is not None}
        """Each sub receiver's main radio: its antenna is the main radio's ``sub`` role."""
        self._radios = frozenset((r.station, r.radio) for r in config.radios)
        """The configuration's radios (a contact of any other maps to none)."""

    def name(self, antenna: int) -> str:
        return self._names.get(antenna, f"Antenna {antenna}")

    # -- antennas ---------------------------------------------------------------------------
    def landed(self, switch_id: int, port: int, slots: tuple[int, int, int]) -> None:
        radio = self._engine.radio_on_port(switch_id, port)
        if radio is None or not self._running:
            return
        station, number = radio
        view = self._engine.radio_view(station, number)
        main = self._main_of.get(radio)
        if main is not None:  # a sub receiver on a port of its own: what it receives on
            held = NO_ANTENNA if view.rx is None else self._engine.slot_of(
                switch_id, view.rx, station, number)
            if held == slots[1]:
                name = "" if view.rx is None else self.name(view.rx)
                self._note(*main, "sub", name, switch_path(switch_id, port, slots[1]))
            return
        for role, wanted, slot in zip(_ROLES, (view.tx, view.rx, view.alt), slots, strict=True):
            if wanted is None:
                if slot != NO_ANTENNA:
                    continue  # the box still holds one: the change has not landed
                name = ""
            else:
                if self._engine.slot_of(switch_id, wanted, station, number) != slot:
                    continue  # not this switch's antenna, or not landed yet
                name = self.name(wanted)
            self._note(station, number, role, name, switch_path(switch_id, port, slot))

    def _note(self, station: int, radio: int, role: Role, name: str, path: str) -> None:
        key = (station, radio, role)
        if self._antennas.get(key) == name:
            return
        self._antennas[key] = name
        now = self._clock()
        chosen = self._chosen.get((station, radio))
        operator = chosen[0] if chosen is not None and now - chosen[1] <= OPERATOR_WINDOW else None
        self.journal.antenna(station, radio, role, name, path=path, operator=operator, at=now)

    def switches_running(self, running: bool) -> bool:
        """Stop Switches turns every relay off: each radio has no antenna in force until
        Start Switches.  Returns True when the switches have just started again (the
        caller then hands over what each box reports, :meth:`landed`)."""
        if running == self._running:
            return False
        self._running = running
        if not running:
            for station, radio, role in list(self._antennas):
                self._note(station, radio, role, "", "switches stopped")
        return running

    def chosen_by(self, operator: str, radios: set[tuple[int, int]]) -> None:
        now = self._clock()
        for radio in radios:
            self._chosen[radio] = (operator, now)

    # -- the key line, rotators, contacts ---------------------------------------------------
    def transmitting(self, station: int, radio: int, keyed: bool) -> None:
        key = (station, radio)
        if self._keyed.get(key, False) == keyed:
            return
        self._keyed[key] = keyed
        self.journal.keyed(station, radio, keyed, at=self._clock())

    def rotator(self, rotator_id: int, heading: float | None, *, moving: bool,
                online: bool) -> None:
        if heading is None or moving or not online:
            return
        if self._headings.get(rotator_id) == heading:
            return
        self._headings[rotator_id] = heading
        name = self._rotators.get(rotator_id, f"Rotator {rotator_id}")
        self.journal.heading(name, heading, at=self._clock())

    def contact(self, packet: ContactPacket, station: int | None, radio: int | None) -> None:
        """A logger's contact; a radio this configuration does not have maps to none."""
        if (station, radio) not in self._radios:
            station = radio = None
        self.journal.contact(packet, station, radio, at=self._clock())

    def stopping(self) -> None:
        """The configuration closes: transmissions still open end now (the server no
        longer hears the key line); the antennas stay in force (the relays stay)."""
        for (station, radio), keyed in list(self._keyed.items()):
            if keyed:
                self.transmitting(station, radio, False)


__all__ = ["OPERATOR_WINDOW", "AntennaRecorder", "switch_path"]
