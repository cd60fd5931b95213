"""Forwarding log records to clients (moas_gui.net.log_events), over a real socket."""

from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Any

import pytest

from moas_gui.net.backend import LogLevel
from moas_gui.net.client import ProtocolClient
from moas_gui.net.log_events import ClientLogHandler, client_level
from moas_gui.net.server import ClientServer
from moas_gui.testing.fake_backend import FakeBackend


@pytest.mark.parametrize(
    ("levelno", "level"),
    [(logging.CRITICAL, "error"), (logging.ERROR, "error"), (logging.WARNING, "info"),
     (logging.INFO, "info"), (logging.DEBUG, "debug"), (5, "debug")],
)
def test_logging_levels_map_to_the_protocols_three(levelno: int, level: str) -> None:
    assert client_level(levelno) == level


class LoggingSink:
    """A sink that logs while it publishes, as the server does when it cuts off a client."""

    def __init__(self, logger: logging.Logger) -> None:
        self.logger = logger
        self.published: list[tuple[str, str]] = []

    def publish_log(self, level: LogLevel, message: str) -> None:
        self.published.append((level, message))
        self.logger.warning("while publishing %s", message)

    def publish_state(self) -> None: ...
    def publish_radio(self, entry: Mapping[str, Any]) -> None: ...
    def publish_rotator(self, entry: Mapping[str, Any]) -> None: ...
    def publish_switch(self, entry: Mapping[str, Any]) -> None: ...
    def layouts_may_have_changed(self) -> None: ...


def test_a_record_logged_while_publishing_is_not_forwarded_again() -> None:
    logger = logging.getLogger("moas_gui.test_log_events.loop")
    sink = LoggingSink(logger)
    handler = ClientLogHandler(sink)
    logger.addHandler(handler)
    try:
        logger.error("Switch 1 is not answering")
    finally:
        logger.removeHandler(handler)
    assert sink.published == [("error", "Switch 1 is not answering")]


def test_records_below_the_handlers_level_are_not_forwarded() -> None:
    logger = logging.getLogger("moas_gui.test_log_events.level")
    logger.setLevel(logging.DEBUG)
    sink = LoggingSink(logging.getLogger("moas_gui.test_log_events.quiet"))
    handler = ClientLogHandler(sink, level=logging.INFO)
    logger.addHandler(handler)
    try:
        logger.debug("bytes in: !1A;")
        logger.info("Station 1 radio 1: TX 20 Stack")
    finally:
        logger.removeHandler(handler)
    assert sink.published == [("info", "Station 1 radio 1: TX 20 Stack")]


@pytest.mark.asyncio
async def test_log_records_reach_clients_that_asked_for_the_log() -> None:
    backend = FakeBackend()
    server = ClientServer(backend, host="127.0.0.1", port=0)
    await server.start()
    logger = logging.getLogger("moas_gui.test_log_events.socket")
    handler = ClientLogHandler(server, level=logging.DEBUG)
    logger.addHandler(handler)
    client = await ProtocolClient.connect("127.0.0.1", server.port)
    try:
        await client.request("hello", client="log viewer", log=True)
        await client.next_event("state")
        logger.warning("Switch %d is unresponsive", 2)
        assert await client.next_event("log") == {
            "event": "log", "level": "info", "message": "Switch 2 is unresponsive"}
    finally:
        logger.removeHandler(handler)
        await client.close()
        await server.close()
