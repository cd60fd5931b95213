"""What a :class:`~moas_gui.client.connection.ClientConnection` tells its listeners.

Each value is frozen; a listener receives them one at a time, in the order the
server sent them, on the event loop's thread::

    LinkChanged      connecting / connected / reconnecting / closed, and why
    StateReceived    a whole new snapshot (after hello, after a configuration load)
    RadioChanged     one radio's entry changed
    RotatorChanged   one rotator's entry changed
    SwitchChanged    one switch's status changed
    LayoutChanged    a followed layout changed
    LogReceived      a log line (only when the connection asked for the log)
    ProblemSeen      the server sent something this client could not use
    TokenWanted      the server refused hello: it wants an operator's token (or another)
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from .model import LayoutView, RadioView, RotatorView, Snapshot, SwitchView

__all__ = [
    "ClientEvent",
    "LayoutChanged",
    "LinkChanged",
    "LinkState",
    "LogReceived",
    "ProblemSeen",
    "RadioChanged",
    "RotatorChanged",
    "StateReceived",
    "SwitchChanged",
    "TokenWanted",
]

TOKEN_ASKED = ("This station asks for an operator's token: ask its admin, or scan its "
               "pairing code")
"""What a client says when a station wants a token it was not given (an operator's
words, not the protocol's)."""
TOKEN_REFUSED = ("This station did not take that token (it may have been removed): ask its "
                 "admin for a new one, or scan its pairing code")
"""What a client says when a station refused the token it was given."""


class LinkState(StrEnum):
    """Where the connection to the server stands."""

    CONNECTING = "connecting"
    """The first attempt is under way."""
    CONNECTED = "connected"
    """The server answered ``hello``."""
    RECONNECTING = "reconnecting"
    """The connection failed or was lost; the next attempt waits its back-off."""
    CLOSED = "closed"
    """The client was closed on purpose; it will not try again."""


@dataclass(frozen=True, slots=True)
class LinkChanged:
    state: LinkState
    detail: str = ""
    """In words: the server's name and version, or what went wrong and when the next try is."""


@dataclass(frozen=True, slots=True)
class StateReceived:
    snapshot: Snapshot


@dataclass(frozen=True, slots=True)
class RadioChanged:
    radio: RadioView


@dataclass(frozen=True, slots=True)
class RotatorChanged:
    rotator: RotatorView


@dataclass(frozen=True, slots=True)
class SwitchChanged:
    switch: SwitchView


@dataclass(frozen=True, slots=True)
class LayoutChanged:
    layout: LayoutView


@dataclass(frozen=True, slots=True)
class LogReceived:
    level: str
    message: str


@dataclass(frozen=True, slots=True)
class ProblemSeen:
    message: str


@dataclass(frozen=True, slots=True)
class TokenWanted:
    """The server refused ``hello`` (``forbidden``): this address needs an operator's
    token and none was given (``refused`` False), or the one given was not taken."""

    refused: bool
    message: str
    """The server's own sentence (for the log; an operator reads :data:`TOKEN_ASKED` or
    :data:`TOKEN_REFUSED`)."""


ClientEvent = (
    LinkChanged | StateReceived | RadioChanged | RotatorChanged | SwitchChanged
    | LayoutChanged | LogReceived | ProblemSeen | TokenWanted
)
