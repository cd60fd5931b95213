"""The network edges of moas-gui.

The client protocol server (``docs/client-protocol.md``):

* :class:`ClientServer` -- serves the protocol on TCP (``TCPPort``, 12059);
* :class:`ClientBackend` / :class:`EventSink` -- the seam to the rest of the
  product, and :class:`RequestError` with its :class:`ErrorCode`;
* :class:`ProtocolClient` -- an asyncio client;
* :func:`is_allowed` -- who may connect (``ClientAllow``);
* :class:`ClientLogHandler` -- the log, forwarded to clients that asked.

The N1MM Logger listener and the rotctld-compatible listener live beside them
in their own modules.  The in-memory backend and server for tests, demos and
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
