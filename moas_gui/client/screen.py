"""What a client screen may show as true: one table for the desktop client and the web page.

A client shows the server's state only while it has it.  Five states cover
every moment, checked in this order (the web page's ``screenState`` in
``resources/web/app.js`` is the same table; ``docs/client.md`` explains it to
people)::

    reconnecting        not connected now (also while connecting or closed):
                        everything greyed, nothing shown selected, a press
                        answers "not connected"
    no configuration    connected, but the server has no configuration open
    switches stopped    every switch stopped: no relay is on, so no antenna is
                        shown selected; antenna and function presses answer
                        "the switches are stopped"; rotators still turn
    switch unresponsive a switch does not answer: everything usable, with a
                        warning that its relays may not match
    connected           everything as the server says
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from .events import LinkState
from .model import Snapshot

__all__ = ["Screen", "ScreenState", "screen_state"]


class Screen(StrEnum):
    """The five states of a client screen (see the module notes)."""

    CONNECTED = "connected"
    RECONNECTING = "reconnecting"
    NO_CONFIGURATION = "no configuration"
    STOPPED = "switches stopped"
    UNRESPONSIVE = "switch unresponsive"


@dataclass(frozen=True, slots=True)
class ScreenState:
    """One state of the table, with what it allows."""

    screen: Screen
    unresponsive: tuple[int, ...] = ()
    """The switches that do not answer (in :attr:`Screen.UNRESPONSIVE`)."""

    @property
    def live(self) -> bool:
        """The client has the server's state now (buttons and compass drawn live)."""
        return self.screen not in (Screen.RECONNECTING, Screen.NO_CONFIGURATION)

    @property
    def shows_selection(self) -> bool:
        """Antennas may be shown selected: connected, and some relay may be on."""
        return self.screen in (Screen.CONNECTED, Screen.UNRESPONSIVE)

    @property
    def can_select(self) -> bool:
        """Antenna, function, relative and frequency presses go to the server."""
        return self.shows_selection

    @property
    def can_turn(self) -> bool:
        """The compass and Stop go to the server (rotators turn while switches are stopped)."""
        return self.live

    @property
    def refusal(self) -> str:
        """Why a press is not sent now: the answer a person sees ("" when it is sent)."""
        return {
            Screen.RECONNECTING: "not connected to the server; the window keeps trying",
            Screen.NO_CONFIGURATION: "the server has no configuration open",
            Screen.STOPPED: "the switches are stopped; start them on the server "
                            "(File > Start Switches)",
        }.get(self.screen, "")


def screen_state(link: LinkState, snapshot: Snapshot | None) -> ScreenState:
    """The state a screen with ``link`` and the last ``snapshot`` is in."""
    if link is not LinkState.CONNECTED or snapshot is None:
        return ScreenState(Screen.RECONNECTING)
    if not snapshot.config:
        return ScreenState(Screen.NO_CONFIGURATION)
    switches = snapshot.switches
    if switches and all(s.status == "stopped" for s in switches):
        return ScreenState(Screen.STOPPED)
    silent = tuple(s.id for s in switches if s.status in ("unresponsive", "connecting"))
    if silent:
        return ScreenState(Screen.UNRESPONSIVE, silent)
    return ScreenState(Screen.CONNECTED)
