"""What can go wrong between this program and a MOAS II, as a small tree
under the project's :mod:`moas_gui.errors`::

    MoasError
     +-- Moas2Error
          +-- EncodeError (ValueError)      a command this program refuses to write
          |    +-- CommandTooLong           it would exceed the 40-byte limit
          |         +-- RelayListTooLong    more relays than one antenna command holds
          +-- CommandRejected (ProtocolError)  what the box answers ``?U``/``?A``/``?T``
          +-- ProbeRefused (HardwareError)     ``--probe``: a port missing, busy or held
          +-- RecordingError (ValueError)      a ``--record-serial`` file that cannot be read

A port that cannot be opened or vanished raises the serial layer's one
:class:`~moas_gui.serial.PortError` (a ``HardwareError`` and an ``OSError``),
the same class for every port of the program; it is named here too because
the switch package has always offered it.

Each error's message says what was wrong and where.
"""

from __future__ import annotations

from ...errors import HardwareError, MoasError, ProtocolError
from ...serial.errors import PortError


class Moas2Error(MoasError):
    """Anything wrong in talking to a MOAS II."""


class EncodeError(Moas2Error, ValueError):
    """A command with a value the protocol cannot carry."""


class CommandTooLong(EncodeError):
    """A command longer than the 40 bytes the driver allows itself."""


class RelayListTooLong(CommandTooLong):
    """An antenna command with more relays than fit in 40 bytes (35)."""


class CommandRejected(Moas2Error, ProtocolError):
    """A command the box would refuse; ``code`` is its ``?`` letter."""

    def __init__(self, code: str, reason: str) -> None:
        super().__init__(reason)
        self.code = code
        self.reason = reason


class ProbeRefused(Moas2Error, HardwareError):
    """``moas-server --probe``: the port cannot be opened (missing, busy, held by a
    running server); the message says which and why."""


class RecordingError(Moas2Error, ValueError):
    """A recording (``--record-serial``) that cannot be read: names the line and why."""


__all__ = [
    "CommandRejected",
    "CommandTooLong",
    "EncodeError",
    "Moas2Error",
    "PortError",
    "ProbeRefused",
    "RecordingError",
    "RelayListTooLong",
]
