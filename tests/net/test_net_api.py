"""The public names of moas_gui.net's client protocol parts are frozen here, so
the API cannot drift silently."""

from __future__ import annotations

import importlib

import pytest

import moas_gui.net
from moas_gui.testing.fake_backend import FakeBackend

PUBLIC = {
    "moas_gui.net": [
        "DEFAULT_ALLOW", "DEFAULT_PORT", "ClientBackend", "ClientInfo", "ClientLogHandler",
        "ClientServer", "ConnectionClosed", "ErrorCode", "EventSink",
        "ProtocolClient", "RequestError", "allowed_networks", "is_allowed", "parse_allow_list",
    ],
    "moas_gui.net.backend": [
        "ClientBackend", "ErrorCode", "EventSink", "JSONObject", "LogLevel", "RequestError",
        "SwitchAction", "Target",
    ],
    "moas_gui.net.identity": [
        "LOCAL_ADDRESSES", "Action", "Forbidden", "Identity", "RadioRef", "Party", "anonymous", "as_operator",
        "check", "current", "enforce", "is_local", "serving", "token_needed",
    ],
    "moas_gui.tls": [
        "CERT_NAME", "KEY_NAME", "Certificate", "TLSError", "carried_names",
        "certificate_names", "check_pin", "client_context",
        "default_paths", "ensure_certificate", "fingerprint", "format_fingerprint",
        "make_self_signed", "normalize_pin", "peer_fingerprint", "server_context",
    ],
    "moas_gui.net.server": [
        "DEFAULT_MAX_CLIENTS", "DEFAULT_MAX_PENDING_TOTAL", "DEFAULT_PORT", "LOG_LEVELS",
        "MAX_BAD_LINES", "ClientServer",
    ],
    "moas_gui.net.access": [
        "DEFAULT_ALLOW", "DEFAULT_ALLOW_TEXT", "IPAddress", "IPNetwork", "allowed_networks",
        "is_allowed", "parse_allow_list", "peer_address",
    ],
    "moas_gui.net.framing": ["MAX_LINE", "Line", "LineFramer", "LongLine", "request_framer"],
    "moas_gui.net.requests": [
        "COMMANDS", "MAX_DEPTH", "Arg", "BadLine", "Command", "InvalidRequest", "Kind", "Request",
        "check_request", "describe", "parse_line", "too_deep",
    ],
    "moas_gui.net.messages": [
        "EVENTS", "PROTOCOL_VERSION", "SERVER_NAME", "MessageEncodeError", "encode", "event",
        "hello_result", "reply_error", "reply_ok",
    ],
    "moas_gui.net.connection": [
        "ClientInfo", "Connection", "LayoutKey", "LineTransport", "LineWriter", "clean_name",
        "cut_slowest",
    ],
    "moas_gui.net.client": ["ConnectionClosed", "ProtocolClient"],
    "moas_gui.net.web": ["StaticFile", "WebServer", "page_files", "start_web"],
    "moas_gui.net.web_socket": ["MAX_MESSAGE", "WebSocketOutlet", "converse"],
    "moas_gui.net.web_guard": ["host_allowed", "local_names", "origin_complaint", "split_host"],
    "moas_gui.net.dispatch": ["HANDLERS", "MAX_BAD_LINES", "answer"],
    "moas_gui.testing.fake_backend": ["FakeBackend"],
    "moas_gui.net.log_events": ["ClientLogHandler", "client_level"],
}


@pytest.mark.parametrize("module", sorted(PUBLIC))
def test_public_names_are_exactly_these(module: str) -> None:
    imported = importlib.import_module(module)
    assert sorted(imported.__all__) == sorted(PUBLIC[module])
    for name in imported.__all__:
        assert hasattr(imported, name), f"{module} lists {name} but has no such name"


def test_every_command_has_a_handler() -> None:
    from moas_gui.net.dispatch import HANDLERS
    from moas_gui.net.requests import COMMANDS

    assert set(HANDLERS) == set(COMMANDS)


def test_the_server_is_an_event_sink_and_the_fake_a_backend() -> None:
    from moas_gui.net.backend import ClientBackend, EventSink

    for name in ("snapshot", "frequency", "select", "function", "relative", "layout",
                 "rotate", "stop"):
        assert name in ClientBackend.__dict__ and callable(getattr(FakeBackend, name))
    for name in ("publish_state", "publish_radio", "publish_rotator", "publish_switch",
                 "layouts_may_have_changed", "publish_log"):
        assert name in EventSink.__dict__ and callable(getattr(moas_gui.net.ClientServer, name))


def test_the_fake_and_the_server_satisfy_the_protocols_for_the_type_checker() -> None:
    from moas_gui.net.backend import ClientBackend, EventSink

    backend: ClientBackend = FakeBackend()
    sink: EventSink = moas_gui.net.ClientServer(backend, host="127.0.0.1", port=0)
    assert sink.client_count == 0  # type: ignore[attr-defined]
