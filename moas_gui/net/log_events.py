"""Forwarding the product's log to the clients that asked for it (``"log": true``).

::

    handler = ClientLogHandler(server)             # server: anything with publish_log
    logging.getLogger("moas_gui").addHandler(handler)

Errors (and critical records) become ``error`` events, warnings and info
become ``info``, anything lower ``debug``; the handler's own level decides
what is forwarded at all (the application sets it from its View menu).  A
record logged while a log event is being sent (the server cutting off a
stuck client, say) is not forwarded again, so the handler can never feed on
itself.
"""

from __future__ import annotations

import logging

from .backend import EventSink, LogLevel


def client_level(levelno: int) -> LogLevel:
    """The client protocol's level for a :mod:`logging` level number."""
    if levelno >= logging.ERROR:
        return "error"
    if levelno >= logging.INFO:
        return "info"
    return "debug"


class ClientLogHandler(logging.Handler):
    def __init__(self, sink: EventSink, level: int = logging.INFO) -> None:
        super().__init__(level)
        self.sink = sink
        self._sending = False

    def emit(self, record: logging.LogRecord) -> None:
        if self._sending or not getattr(self.sink, "log_wanted", True):
            return  # (a sink that says nobody wants the log: the record is not formatted)
        self._sending = True
        try:
            self.sink.publish_log(client_level(record.levelno), record.getMessage())
        except Exception:  # noqa: BLE001 - logging's own convention for a failing handler
            self.handleError(record)
        finally:
            self._sending = False


__all__ = ["ClientLogHandler", "client_level"]
