"""The network edges of moas-gui.

The client protocol server (``docs/client-protocol.md``):

* :class:`ClientServer` -- serves the protocol on TCP (``TCPPort``, 12059);
* :class:`ClientBackend` / :class:`EventSink` -- the seam to the rest of the
  product, and :class:`RequestError` with its :class:`ErrorCode`;
* :class:`ProtocolClient` -- an asyncio client;
* :func:`is_allowed` -- who may connect (``ClientAllow``);
* :class:`ClientLogHandler` -- the log, forwarded to clients that asked.

The browser client's web server, the rotctld-compatible listener and the Antenna
Genius front live beside them in their own modules; every one of their listeners
admits through the program's one door (:mod:`moas_gui.edge.gate`).  The loggers'
listeners (N1MM Logger and the others) are frequency sources (:mod:`moas_gui.sources`).  The in-memory backend and server for tests, demos and
client authors are in :mod:`moas_gui.testing` (``fake_backend``,
``fake_server``), which nothing here imports.
"""

from .access import DEFAULT_ALLOW, allowed_networks, is_allowed, parse_allow_list
from .backend import ClientBackend, ErrorCode, EventSink, RequestError
from .client import ConnectionClosed, ProtocolClient
from .connection import ClientInfo
from .log_events import ClientLogHandler
from .server import DEFAULT_PORT, ClientServer

__all__ = [
    "DEFAULT_ALLOW",
    "DEFAULT_PORT",
    "ClientBackend",
    "ClientInfo",
    "ClientLogHandler",
    "ClientServer",
    "ConnectionClosed",
    "ErrorCode",
    "EventSink",
    "ProtocolClient",
    "RequestError",
    "allowed_networks",
    "is_allowed",
    "parse_allow_list",
]
