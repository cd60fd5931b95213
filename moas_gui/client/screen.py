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

The status line follows the same table: every message it shows belongs to the
state and the radio it was shown in (:class:`StatusMessage`), and goes when the
state changes, another radio is chosen, a new configuration arrives, or the next
press or Why? replaces it.  ``docs/client.md`` ("The status line") lists each
message with what shows it and what clears it.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from .events import LinkState
from .model import ButtonState, ButtonType, ButtonView, RadioKey, Snapshot

__all__ = ["Screen", "ScreenState", "StatusMessage", "Tone", "button_answer", "screen_state"]


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


class Tone(StrEnum):
    """How a status message is drawn: a refusal or problem, or an answer to a question."""

    WARNING = "warning"
    """⚠, amber: something asked was refused, or failed."""
    INFO = "info"
    """ℹ, the window's plain text colour: why something is as it is (Why?, a press on an
    unavailable button)."""


@dataclass(frozen=True, slots=True)
class StatusMessage:
    """One message of the status line, tied to the screen state and radio it was shown in."""

    text: str
    tone: Tone
    screen: Screen
    radio: RadioKey | None = None

    @property
    def shown(self) -> str:
        """The text with its tone's mark."""
        return ("\u26a0 " if self.tone is Tone.WARNING else "\u2139 ") + self.text

    def still_true(self, screen: Screen, radio: RadioKey | None) -> bool:
        """Whether the message may stay: the same state, the same radio."""
        return screen is self.screen and radio == self.radio


def button_answer(view: ButtonView, screen: ScreenState, why: str = "") -> str:
    """What a press on a button that is not sent, or Why? on any button, answers.

    The deciding reason comes first: the screen state's refusal while nothing can be
    pressed; an unavailable button's reason (the server's words); for a selected
    antenna, ``why`` (why the radio has its antennas); otherwise what a press does.
    """
    if not screen.can_select:
        return f"{view.label}: {screen.refusal}"
    function = view.type is ButtonType.FUNCTION
    if view.state is ButtonState.UNAVAILABLE:
        reason = view.reason or "not available now (the server did not say why)"
        return f"{view.label}: {reason}"
    if view.state is ButtonState.SELECTED:
        if function:
            return f"{view.label}: on; a click turns it off"
        return f"{view.label}: in use by this radio" + (f". {why}" if why else "")
    return f"{view.label}: available; a click " + ("runs it" if function else "selects it")
