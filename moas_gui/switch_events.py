"""What the switch links say, handled in one part: :class:`SwitchEvents`.

The app holds one for its life and hands each configuration that starts to it
(:meth:`~SwitchEvents.start`); its four methods are the callbacks
:func:`~moas_gui.running.start_switches` gives every link (bound to the link's switch):

* :meth:`~SwitchEvents.status`: the link's status (connecting, ok, unresponsive...):
  kept in ``Running.switch_status``, told to the clients as a ``switch`` event, an
  alert when a switch that answered stops answering, and the saved state is due
  (what a box holds may have changed);
* :meth:`~SwitchEvents.transmitting`: the box's T/R for a port, into the engine through
  the app's one door (``SetTransmitting``), then to the antenna log;
* :meth:`~SwitchEvents.adopt`: a survey found the box holding other antennas than the
  saved state for some ports: the engine takes them all in one ``KeepSwitchAntennas``
  through the door;
* :meth:`~SwitchEvents.seen`: the antennas a box reports in use for a port changed:
  what it confirmed, to the antenna log.

When the configuration closes (:meth:`~SwitchEvents.stop`, before its links are
closed) a late event of a closing link changes nothing.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping

from moas_gui.antenna_feed import AntennaFeed
from moas_gui.engine.operations import KeepSwitchAntennas, SetTransmitting
from moas_gui.hw.moas2.link import LinkStatus
from moas_gui.running import Running
from moas_gui.source_intake import Act

log = logging.getLogger(__name__)


class SwitchEvents:
    """The switch callbacks of whichever configuration runs.

    ``act`` is the app's one door into the engine; ``feed`` the antenna log's wiring;
    ``alert(title, text)`` tells the window's alert listeners; ``status_changed`` has
    the app refresh the status it shows."""

    def __init__(self, act: Act, feed: AntennaFeed, alert: Callable[[str, str], None],
                 status_changed: Callable[[], None]) -> None:
        self._act = act
        self._feed = feed
        self._alert = alert
        self._status_changed = status_changed
        self._run: Running | None = None
        """The configuration whose links these are (None: none runs)."""

    def start(self, run: Running) -> None:
        """``run``'s links are about to start."""
        self._run = run

    def stop(self) -> None:
        """The configuration closes: its links' late events change nothing."""
        self._run = None

    def status(self, switch_id: int, status: LinkStatus) -> None:
        """Switch ``switch_id``'s link says ``status``; the saved state is due."""
        run = self._run
        if run is None:
            return
        self._note(run, switch_id, status.value)
        if run.keeper is not None:
            run.keeper.changed()

    def _note(self, run: Running, switch_id: int, status: str) -> None:
        before = run.switch_status.get(switch_id)
        if before is None or before == status:
            return
        run.switch_status[switch_id] = status
        if status == "unresponsive":
            # the link said where and why, once per outage, at Warning
            log.info("Switch %d is not responding", switch_id)
            if before == "ok":
                self._alert("MOAS switch lost", f"Switch {switch_id} stopped responding.")
        if run.clients is not None:
            run.clients.publish_switch({"id": switch_id, "status": status})
        self._status_changed()

    def transmitting(self, switch_id: int, port: int, transmitting: bool) -> None:
        """The box says the station on ``port`` transmits (or receives) now."""
        if self._run is not None:
            self._act(SetTransmitting(switch_id, port, transmitting))
            self._feed.keyed(switch_id, port)

    def adopt(self, switch_id: int, held: Mapping[int, tuple[int, int, int]]) -> None:
        """The box holds other antennas for some ports (``held``: slots by port) than the
        saved state says: the box wins, and the engine takes them all in one operation
        (the link logged which, and which of those stations were keyed then)."""
        if self._run is not None:
            self._act(KeepSwitchAntennas(switch_id, tuple(
                (port, slots[0], slots[1]) for port, slots in sorted(held.items()))))

    def seen(self, switch_id: int, port: int, slots: tuple[int, int, int]) -> None:
        """The box reports other antennas in use for ``port``: what it confirmed."""
        if self._run is not None:
            self._feed.landed(switch_id, port, slots)


__all__ = ["SwitchEvents"]
