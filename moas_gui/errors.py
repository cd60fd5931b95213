"""The root of the project's errors.

::

    MoasError
     +-- ConfigError     (moas_gui.config)   the user's configuration file
     +-- EngineError     (moas_gui.engine)          a request the rules refuse
     +-- ProtocolError                              a peer sent nonsense
     +-- HardwareError                              a port vanished or cannot be opened
"""

from __future__ import annotations


class MoasError(Exception):
    """Base of every error moas-gui raises on purpose."""


class ProtocolError(MoasError):
    """A switch, client, rotator or logger sent something that makes no sense."""


class HardwareError(MoasError):
    """A serial port or network peer vanished or cannot be opened."""


__all__ = ["HardwareError", "MoasError", "ProtocolError"]
