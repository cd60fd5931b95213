"""Errors a user can cause by asking the engine for something.

::

    EngineError            (code: the client protocol's error code)
    ├── BadRequest         bad_request: a malformed argument (target "up", step 0)
    ├── NotFound           not_found: no such station/radio/antenna/function/rotator
    ├── Unavailable        unavailable: exists, but cannot be used now
    └── NotRunning         not_running: the switches are stopped

Each carries one sentence that names what was wrong, for the operator.  When an
operation raises, the engine's state is exactly what it was before the call.
"""

from __future__ import annotations

from moas_gui.errors import RequestRefused


class EngineError(RequestRefused):
    """A request the engine refused; ``code`` is the client protocol's error code."""

    code = "internal"

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


class BadRequest(EngineError):
    code = "bad_request"


class NotFound(EngineError):
    code = "not_found"


class Unavailable(EngineError):
    code = "unavailable"


class NotRunning(EngineError):
    code = "not_running"


__all__ = ["BadRequest", "EngineError", "NotFound", "NotRunning", "Unavailable"]
