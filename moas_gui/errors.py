"""The root of the project's errors.

::

    MoasError
     +-- ConfigError       (moas_gui.config)          the user's configuration file
     +-- RequestRefused                               a request that cannot be served:
     |    |                                           ``code`` (client protocol), ``message``
     |    +-- EngineError   (moas_gui.engine)         a request the rules refuse
     |    +-- RotatorError  (moas_gui.hw.rotators)    a rotate or stop that cannot be served
     |    +-- RequestError  (moas_gui.net.backend)    what the client server answers
     |    +-- Forbidden     (moas_gui.net.identity)   what the asker's role may not do
     +-- ProtocolError                                a peer sent nonsense, or a codec
     |                                                cannot write a value
     +-- HardwareError                                a port vanished or cannot be opened
     +-- Moas2Error        (moas_gui.hw.moas2)        the switch package's own errors
     +-- ClientError       (moas_gui.client)          what the client library raises
     +-- StateError        (moas_gui.state_store)     a saved state that cannot be used
     +-- SnapshotError     (moas_gui.engine.snapshot) a snapshot that does not fit the engine
     +-- OperatorError     (moas_gui.operators)       an operator that cannot be added or found
     +-- TLSError          (moas_gui.tls)         a certificate or key that cannot be used
"""

from __future__ import annotations


class MoasError(Exception):
    """Base of every error moas-gui raises on purpose."""


class RequestRefused(MoasError):
    """A request refused: ``code`` is the client protocol's error code, ``message`` the
    sentence for the operator."""

    code: str = "internal"
    message: str = ""


class ProtocolError(MoasError):
    """A switch, client, rotator or logger sent something that makes no sense."""


class HardwareError(MoasError):
    """A serial port or network peer vanished or cannot be opened."""


__all__ = ["HardwareError", "MoasError", "ProtocolError", "RequestRefused"]
