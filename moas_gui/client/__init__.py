"""A client of the moas-gui client protocol, with no Qt: the built-in client
window, ``moas-client`` and scripts use it the same way.

::

    model.py       frozen views of the snapshot, radios, antennas, rotators, layouts
    codec.py       JSON-lines framing, sans-IO (bytes in, replies and events out)
    events.py      what a connection tells its listeners
    connection.py  the asyncio connection: hello, requests by id, events, reconnect
    address.py     HOST[:PORT] as people type it
    screen.py      what a client screen may show as true: the one table of states
"""

from __future__ import annotations

from .address import DEFAULT_PORT, parse_address
from .connection import (
    Backoff,
    ClientConnection,
    ClientError,
    ConnectionLost,
    NotConnected,
    RequestTimeout,
    Selection,
    ServerError,
)
from .events import (
    ClientEvent,
    LayoutChanged,
    LinkChanged,
    LinkState,
    LogReceived,
    ProblemSeen,
    RadioChanged,
    RotatorChanged,
    StateReceived,
    SwitchChanged,
    TokenWanted,
)
from .model import (
    AntennaView,
    ButtonState,
    ButtonType,
    ButtonView,
    LayoutView,
    RadioView,
    RotatorView,
    Snapshot,
    SwitchView,
)

__all__ = [
    "DEFAULT_PORT",
    "AntennaView",
    "Backoff",
    "ButtonState",
    "ButtonType",
    "ButtonView",
    "ClientConnection",
    "ClientError",
    "ClientEvent",
    "ConnectionLost",
    "LayoutChanged",
    "LayoutView",
    "LinkChanged",
    "LinkState",
    "LogReceived",
    "NotConnected",
    "ProblemSeen",
    "RadioChanged",
    "RadioView",
    "RequestTimeout",
    "RotatorChanged",
    "RotatorView",
    "Selection",
    "ServerError",
    "Snapshot",
    "StateReceived",
    "SwitchChanged",
    "SwitchView",
    "TokenWanted",
    "parse_address",
]
