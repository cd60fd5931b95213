"""The client protocol server over real sockets on 127.0.0.1, against the fake backend."""

from __future__ import annotations

import asyncio
import json
import logging
import socket
from collections.abc import AsyncIterator
from dataclasses import dataclass, field
from typing import Any

import pytest
import pytest_asyncio
from helpers import until

from moas_gui import __version__
from moas_gui.errors import HardwareError
from moas_gui.net.backend import RequestError
from moas_gui.net.client import ProtocolClient
from moas_gui.net.server import ClientServer
from moas_gui.testing.fake_backend import FakeBackend

HOST = "127.0.0.1"


@dataclass
class Rig:
    backend: FakeBackend
    server: ClientServer
    clients: list[ProtocolClient] = field(default_factory=list)

    async def connect(self, name: str | None = "test client", **hello: Any) -> ProtocolClient:
        client = await ProtocolClient.connect(HOST, self.server.port)
        self.clients.append(client)
        if name is not None:
            await client.request("hello", client=name, **hello)
            await client.next_event("state")
        return client


async def make_rig(backend: FakeBackend | None = None, **options: Any) -> Rig:
    backend = backend or FakeBackend()
    server = ClientServer(backend, host=HOST, port=0, **options)
    backend.attach(server)
    await server.start()
    return Rig(backend, server)


async def dispose(rig: Rig) -> None:
    for client in rig.clients:
        await client.close()
    await rig.server.close()


@pytest_asyncio.fixture
async def rig() -> AsyncIterator[Rig]:
    made = await make_rig()
    yield made
    await dispose(made)


# ---- hello and state ---------------------------------------------------------------------


@pytest.mark.asyncio
async def test_hello_names_the_server_and_a_state_event_follows(rig: Rig) -> None:
    client = await rig.connect(None)
    reply = await client.call("hello", client="Button client", station=1, radio=1)
    assert reply == {"id": 1, "ok": True,
                     "result": {"server": "moas-gui", "version": __version__, "protocol": 1}}
    state = await client.next_event()
    assert state["event"] == "state"
    assert {k: v for k, v in state.items() if k != "event"} == rig.backend.snapshot()


@pytest.mark.asyncio
async def test_state_works_without_hello(rig: Rig) -> None:
    client = await rig.connect(None)
    assert await client.request("state") == rig.backend.snapshot()


@pytest.mark.asyncio
async def test_a_request_without_id_gets_a_reply_with_null_id(rig: Rig) -> None:
    client = await rig.connect(None)
    client.send_raw(b'{"cmd": "stop", "rotator": 1}\n')
    assert await asyncio.wait_for(client.stray.get(), 5) == {"id": None, "ok": True, "result": {}}


@pytest.mark.asyncio
@pytest.mark.parametrize("request_id", ["a-7", [1, 2], {"n": {"m": None}}, 3.25, False])
async def test_the_id_is_echoed_unchanged(rig: Rig, request_id: Any) -> None:
    client = await rig.connect(None)
    client.send({"id": request_id, "cmd": "stop", "rotator": 1})
    reply = await asyncio.wait_for(client.stray.get(), 5)
    assert reply["id"] == request_id and reply["ok"] is True


@pytest.mark.asyncio
async def test_crlf_and_blank_lines_are_accepted(rig: Rig) -> None:
    client = await rig.connect(None)
    client.send_raw(b'\r\n\n   \n{"id": "a", "cmd": "stop", "rotator": 1}\r\n'
                    b'{"id": "b", "cmd": "stop", "rotator": 2}\r\n')
    first = await asyncio.wait_for(client.stray.get(), 5)
    second = await asyncio.wait_for(client.stray.get(), 5)
    assert (first["id"], second["id"]) == ("a", "b")
    assert client.stray.empty()


@pytest.mark.asyncio
async def test_replies_come_in_the_order_of_the_requests(rig: Rig) -> None:
    client = await rig.connect(None)
    lines = b"".join(
        json.dumps({"id": i, "cmd": "rotate", "rotator": 9 if i % 3 else 1, "heading": i}).encode()
        + b"\n" for i in range(200)
    )
    client.send_raw(lines)
    ids = [(await asyncio.wait_for(client.stray.get(), 5))["id"] for _ in range(200)]
    assert ids == list(range(200))


# ---- commands ------------------------------------------------------------------------------


@pytest.mark.asyncio
async def test_frequency_runs_selection_and_every_greeted_client_hears_of_it(rig: Rig) -> None:
    a, b = await rig.connect("a"), await rig.connect("b")
    assert await a.request("frequency", station=1, radio=1, khz=7100) == {}
    for client in (a, b):
        event = await client.next_event("radio")
        assert (event["station"], event["khz"], event["tx"], event["rx"]) == (1, 7100.0, 4, 4)


@pytest.mark.asyncio
async def test_split_frequency_is_passed_on(rig: Rig) -> None:
    client = await rig.connect("a")
    await client.request("frequency", station=1, radio=1, khz=14005, tx_khz=14025.5)
    assert rig.backend.calls[-1] == ("frequency", (1, 1, 14005.0, 14025.5))


@pytest.mark.asyncio
async def test_select_returns_the_antennas_and_the_others_get_a_radio_event(rig: Rig) -> None:
    a, b = await rig.connect("a"), await rig.connect("b")
    assert await a.request("select", station=1, radio=1, antenna=1) == {"tx": 1, "rx": 1}
    event = await b.next_event("radio")
    assert (event["station"], event["radio"], event["tx"], event["rx"]) == (1, 1, 1, 1)


@pytest.mark.asyncio
async def test_select_passes_target_and_exclusive(rig: Rig) -> None:
    client = await rig.connect("a")
    await client.request("frequency", station=1, radio=1, khz=7100)
    result = await client.request("select", station=1, radio=1, antenna=6, target="rx",
                                  exclusive=True)
    assert result == {"tx": 4, "rx": 6}
    assert rig.backend.calls[-1] == ("select", (1, 1, 6, "rx", True))


@pytest.mark.asyncio
async def test_function_runs_and_both_radios_are_reported(rig: Rig) -> None:
    client = await rig.connect("a")
    await client.request("frequency", station=1, radio=1, khz=7100)
    await client.next_event("radio")
    assert await client.request("function", station=1, radio=1, function=0) == {}
    first, second = await client.next_event("radio"), await client.next_event("radio")
    assert {(e["station"], e["tx"]) for e in (first, second)} == {(1, 3), (2, 4)}


@pytest.mark.asyncio
async def test_relative_by_step_and_by_index(rig: Rig) -> None:
    client = await rig.connect("a")
    assert await client.request("relative", station=1, radio=1, step=1) == {"tx": 1, "rx": 1}
    assert await client.request("relative", station=1, radio=1, index=0) == {"tx": 2, "rx": 2}


@pytest.mark.asyncio
async def test_rotate_and_stop_are_reported_as_rotator_events(rig: Rig) -> None:
    client = await rig.connect("a")
    assert await client.request("rotate", rotator=2, heading=135.5) == {}
    event = await client.next_event("rotator")
    assert (event["id"], event["target"], event["moving"]) == (2, 135.5, True)
    assert await client.request("stop", rotator=2) == {}
    event = await client.next_event("rotator")
    assert (event["id"], event["target"], event["moving"]) == (2, None, False)


@pytest.mark.asyncio
async def test_a_switch_status_change_is_a_switch_event(rig: Rig) -> None:
    client = await rig.connect("a")
    rig.backend.set_switch_status(1, "unresponsive")
    assert await client.next_event() == {"event": "switch", "id": 1, "status": "unresponsive"}


@pytest.mark.asyncio
async def test_a_reloaded_configuration_sends_a_fresh_state_to_everyone(rig: Rig) -> None:
    a, b = await rig.connect("a"), await rig.connect("b")
    rig.backend.load()
    for client in (a, b):
        assert (await client.next_event())["event"] == "state"


@pytest.mark.asyncio
async def test_events_start_only_after_hello(rig: Rig) -> None:
    silent = await rig.connect(None)
    rig.backend.set_switch_status(1, "connecting")
    await silent.request("state")
    assert silent.events.empty()


@pytest.mark.asyncio
async def test_log_events_go_only_to_clients_that_asked(rig: Rig) -> None:
    listener, other = await rig.connect("listener", log=True), await rig.connect("other")
    rig.server.publish_log("info", "Station 1 radio 1: TX 20 Stack")
    rig.backend.set_switch_status(1, "ok")
    assert await listener.next_event() == {"event": "log", "level": "info",
                                           "message": "Station 1 radio 1: TX 20 Stack"}
    assert (await listener.next_event())["event"] == "switch"
    assert (await other.next_event())["event"] == "switch"


@pytest.mark.asyncio
async def test_an_unknown_log_level_is_a_programming_error(rig: Rig) -> None:
    with pytest.raises(ValueError, match="'warning' is not one of error, info, debug"):
        rig.server.publish_log("warning", "x")  # type: ignore[arg-type]


# ---- layouts -------------------------------------------------------------------------------


@pytest.mark.asyncio
async def test_layout_replies_and_then_follows_changes(rig: Rig) -> None:
    client = await rig.connect("buttons", station=1, radio=1)
    layout = await client.request("layout", station=1, radio=1, rows=4, columns=3)
    assert (layout["station"], layout["radio"], layout["rows"], layout["columns"]) == (1, 1, 4, 3)
    assert {b["id"]: b["state"] for b in layout["buttons"] if b["type"] == "Antenna"} == {
        2: "selected", 1: "available"}
    other = await rig.connect("logger")
    await other.request("frequency", station=2, radio=1, khz=14100)
    event = await client.next_event("layout")
    assert {b["id"]: b["state"] for b in event["buttons"] if b["type"] == "Antenna"} == {
        2: "selected", 1: "unavailable"}
    assert {k: v for k, v in event.items() if k != "event"} == rig.backend.layout(1, 1, 4, 3)


@pytest.mark.asyncio
async def test_an_unchanged_layout_is_not_sent_again(rig: Rig) -> None:
    client = await rig.connect("buttons")
    await client.request("layout", station=1, radio=1, rows=4, columns=3)
    rig.server.layouts_may_have_changed()
    await asyncio.sleep(0)
    await asyncio.sleep(0)
    rig.backend.set_switch_status(1, "ok")
    assert (await client.next_event())["event"] == "switch"


@pytest.mark.asyncio
async def test_layout_events_go_only_to_connections_that_follow_that_layout(rig: Rig) -> None:
    follower, bystander = await rig.connect("follower"), await rig.connect("bystander")
    await follower.request("layout", station=1, radio=1, rows=4, columns=3)
    await bystander.request("select", station=1, radio=1, antenna=1)
    assert (await follower.next_event("layout"))["station"] == 1
    rig.backend.set_switch_status(1, "ok")
    assert [(await bystander.next_event())["event"] for _ in range(2)] == ["radio", "switch"]


@pytest.mark.asyncio
async def test_many_followers_of_one_layout_cost_one_backend_call(rig: Rig) -> None:
    clients = [await rig.connect(f"c{i}") for i in range(5)]
    for client in clients:
        await client.request("layout", station=1, radio=1, rows=4, columns=3)
    before = sum(1 for name, _ in rig.backend.calls if name == "layout")
    await clients[0].request("select", station=1, radio=1, antenna=1)
    for client in clients:
        await client.next_event("layout")
    assert sum(1 for name, _ in rig.backend.calls if name == "layout") == before + 1


@pytest.mark.asyncio
async def test_a_connection_follows_a_bounded_number_of_layouts(rig: Rig) -> None:
    client = await rig.connect("greedy")
    for columns in range(1, 31):
        await client.request("layout", station=1, radio=1, rows=1, columns=columns)
    assert [info.layouts for info in rig.server.clients()] == [rig.server.max_layouts]


# ---- errors --------------------------------------------------------------------------------

ERRORS = [
    ({"cmd": "select", "station": 1, "radio": 1}, "bad_request", '"antenna" is missing'),
    ({"cmd": "select", "station": "1", "radio": 1, "antenna": 1}, "bad_request",
     '"station" must be a whole number'),
    ({"cmd": "frequency", "station": 1, "radio": 1, "khz": "fast"}, "bad_request",
     '"khz" must be a frequency in kHz'),
    ({"cmd": "layout", "station": 1, "radio": 1, "rows": 0, "columns": 3}, "bad_request",
     '"rows" must be'),
    ({"cmd": "relative", "station": 1, "radio": 1}, "bad_request", "exactly one of"),
    ({"cmd": "hello"}, "bad_request", '"client" is missing'),
    ({"cmd": "explode"}, "unknown_cmd", 'there is no command "explode"'),
    ({"station": 1}, "bad_request", '"cmd" is missing'),
    ({"cmd": "select", "station": 5, "radio": 1, "antenna": 1}, "not_found",
     "there is no station 5 radio 1"),
    ({"cmd": "select", "station": 1, "radio": 1, "antenna": 77}, "not_found",
     "there is no antenna 77"),
    ({"cmd": "function", "station": 1, "radio": 1, "function": 9}, "not_found",
     "there is no function 9"),
    ({"cmd": "rotate", "rotator": 12, "heading": 10}, "not_found", "there is no rotator 12"),
    ({"cmd": "select", "station": 1, "radio": 1, "antenna": 3}, "unavailable",
     "Antenna 3 (40 Beam) does not cover 14025 kHz"),
    ({"cmd": "select", "station": 1, "radio": 1, "antenna": 6, "target": "tx"}, "unavailable",
     "receive-only"),
    ({"cmd": "function", "station": 1, "radio": 1, "function": 0}, "unavailable", "Swap is not"),
    ({"cmd": "rotate", "rotator": 3, "heading": 10}, "unavailable", "is offline"),
]


@pytest.mark.asyncio
@pytest.mark.parametrize(("message", "code", "words"), ERRORS)
async def test_each_bad_request_gets_its_error_and_the_connection_stays_open(
    rig: Rig, message: dict[str, Any], code: str, words: str
) -> None:
    client = await rig.connect("a")
    client.send({"id": "q", **message})
    reply = await asyncio.wait_for(client.stray.get(), 5)
    assert reply["id"] == "q" and reply["ok"] is False
    assert reply["error"]["code"] == code
    assert words in reply["error"]["message"]
    assert await client.request("stop", rotator=1) == {}


@pytest.mark.asyncio
async def test_an_antenna_in_use_elsewhere_is_unavailable_with_who_uses_it(rig: Rig) -> None:
    client = await rig.connect("a")
    await client.request("frequency", station=1, radio=1, khz=7100)
    with pytest.raises(RequestError) as caught:
        await client.request("select", station=1, radio=1, antenna=3)
    assert caught.value.code == "unavailable"
    assert caught.value.message == "Antenna 3 (40 Beam) is in use by station 2 radio 1"


@pytest.mark.asyncio
async def test_stopped_switches_answer_not_running(rig: Rig) -> None:
    client = await rig.connect("a")
    rig.backend.stop_switches()
    with pytest.raises(RequestError) as caught:
        await client.request("select", station=1, radio=1, antenna=1)
    assert (caught.value.code, caught.value.message) == ("not_running", "the switches are stopped")


@pytest.mark.asyncio
async def test_hello_without_a_configuration_answers_and_sends_no_state(rig: Rig) -> None:
    rig.backend.unload()
    client = await rig.connect(None)
    await client.request("hello", client="early")
    with pytest.raises(RequestError) as caught:
        await client.request("state")
    assert caught.value.code == "not_running"
    assert client.events.empty()
    rig.backend.load()
    assert (await client.next_event())["event"] == "state"


async def bad_line_replies(client: ProtocolClient, count: int) -> list[dict[str, Any]]:
    return [await asyncio.wait_for(client.stray.get(), 5) for _ in range(count)]


@pytest.mark.asyncio
async def test_three_bad_lines_in_a_row_close_the_connection(
    rig: Rig, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.net")
    client = await rig.connect("clumsy")
    client.send_raw(b"hello?\n[1]\n\xff\n")
    replies = await bad_line_replies(client, 3)
    assert all(r["id"] is None and r["error"]["code"] == "bad_request" for r in replies)
    assert "not JSON" in replies[0]["error"]["message"]
    assert "not an object" in replies[1]["error"]["message"]
    assert "not UTF-8" in replies[2]["error"]["message"]
    await asyncio.wait_for(client.closed.wait(), 5)
    await until(lambda: rig.server.client_count == 0)
    assert any("disconnected by the server: 3 bad lines in a row" in r.getMessage()
               for r in caplog.records)


@pytest.mark.asyncio
async def test_a_good_line_between_bad_ones_resets_the_count(rig: Rig) -> None:
    client = await rig.connect("clumsy")
    client.send_raw(b'x\ny\n{"id": 1, "cmd": "nope"}\nx\ny\n')
    replies = await bad_line_replies(client, 5)
    assert replies[2]["error"]["code"] == "unknown_cmd"
    assert await client.request("stop", rotator=1) == {}
    assert not client.closed.is_set()


@pytest.mark.asyncio
async def test_a_line_over_65536_bytes_gets_an_error_and_the_next_line_is_served(
    rig: Rig,
) -> None:
    client = await rig.connect("big")
    client.send_raw(b'{"id": 1, "cmd": "state", "pad": "' + b"x" * 70_000 + b'"}\n')
    reply = (await bad_line_replies(client, 1))[0]
    assert reply["id"] is None and "longer than 65,536 bytes" in reply["error"]["message"]
    assert await client.request("stop", rotator=1) == {}


@pytest.mark.asyncio
async def test_a_line_of_exactly_65536_bytes_is_served(rig: Rig) -> None:
    client = await rig.connect("big")
    head = b'{"id": "full", "cmd": "stop", "rotator": 1'
    line = head + b" " * (65_536 - len(head) - 1) + b"}"
    assert len(line) == 65_536
    client.send_raw(line + b"\r\n")
    assert (await bad_line_replies(client, 1))[0] == {"id": "full", "ok": True, "result": {}}


@pytest.mark.asyncio
async def test_megabytes_without_a_newline_are_refused_without_being_kept(rig: Rig) -> None:
    client = await rig.connect("flood")
    for _ in range(40):
        client.send_raw(b"[" * 100_000)
    await client.writer.drain()
    reply = (await bad_line_replies(client, 1))[0]
    assert "longer than" in reply["error"]["message"]
    client.send_raw(b"]\n")
    assert await client.request("stop", rotator=1) == {}


@pytest.mark.asyncio
@pytest.mark.parametrize(
    "line",
    [b'{"id": 1e999, "cmd": "state"}',
     b'{"id": ' + b"[" * 980 + b"]" * 980 + b', "cmd": "state"}'],
    ids=["huge number", "deep id"],
)
async def test_an_id_that_cannot_be_written_back_is_a_bad_request_not_a_failure(
    rig: Rig, caplog: pytest.LogCaptureFixture, line: bytes
) -> None:
    client = await rig.connect("odd ids")
    client.send_raw(line + b"\n")
    reply = (await bad_line_replies(client, 1))[0]
    assert reply["id"] is None and reply["error"]["code"] == "bad_request"
    assert await client.request("stop", rotator=1) == {}
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR]


# ---- the backend failing -------------------------------------------------------------------


class BrokenBackend(FakeBackend):
    def select(self, *args: Any) -> dict[str, Any]:
        raise ZeroDivisionError("division by zero")

    def relative(self, *args: Any) -> dict[str, Any]:
        return {"tx": {1, 2}}  # not JSON


@pytest.mark.asyncio
async def test_a_backend_failure_is_an_internal_error_and_everything_carries_on(
    caplog: pytest.LogCaptureFixture,
) -> None:
    rig = await make_rig(BrokenBackend())
    try:
        client = await rig.connect("a")
        with pytest.raises(RequestError) as caught:
            await client.request("select", station=1, radio=1, antenna=1)
        assert caught.value.code == "internal"
        assert "ZeroDivisionError: division by zero" in caught.value.message
        with pytest.raises(RequestError) as caught:
            await client.request("relative", station=1, radio=1, step=1)
        assert caught.value.code == "internal" and "could not be written" in caught.value.message
        assert await client.request("stop", rotator=1) == {}
        errors = [r for r in caplog.records if r.levelno >= logging.ERROR]
        assert "The server failed on select from client" in errors[0].getMessage()
        assert errors[0].exc_info is not None
        assert "The reply to relative" in errors[1].getMessage()
    finally:
        await dispose(rig)


@pytest.mark.asyncio
async def test_an_event_that_is_not_json_is_logged_and_not_sent(
    rig: Rig, caplog: pytest.LogCaptureFixture
) -> None:
    client = await rig.connect("a")
    rig.server.publish_radio({"station": 1, "khz": float("nan")})
    rig.backend.set_switch_status(1, "ok")
    assert (await client.next_event())["event"] == "switch"
    assert any("Could not write a radio event" in r.getMessage() for r in caplog.records)


# ---- connections ---------------------------------------------------------------------------


@pytest.mark.asyncio
async def test_connects_hellos_and_disconnects_are_logged_at_info_with_the_name(
    rig: Rig, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.net")
    client = await rig.connect("Logger PC", station=2, radio=1)
    await client.close()
    await until(lambda: rig.server.client_count == 0)
    lines = [r.getMessage() for r in caplog.records
             if r.name.startswith("moas_gui.net") and r.levelno == logging.INFO]
    # the connection's opening is at Debug: only a client that said hello is news
    assert not any(line.startswith("Client connected from") for line in lines)
    assert any(line.startswith("Client at 127.0.0.1:") and line.endswith(
        'is "Logger PC" for station 2 radio 1') for line in lines)
    assert any(line.startswith('Client "Logger PC" at 127.0.0.1:') and
               line.endswith("disconnected") for line in lines)


@pytest.mark.asyncio
async def test_a_clients_name_is_cleaned_for_the_log(rig: Rig) -> None:
    await rig.connect("evil\nname\x1b[31m" + "x" * 100)
    (info,) = rig.server.clients()
    assert info.name is not None and "\n" not in info.name and "\x1b" not in info.name
    assert len(info.name) == 64


@pytest.mark.asyncio
async def test_the_server_counts_and_describes_its_clients(rig: Rig) -> None:
    await rig.connect("one", station=1, radio=1, log=True)
    await rig.connect(None)
    await until(lambda: rig.server.client_count == 2)
    infos = sorted(rig.server.clients(), key=lambda i: i.name or "")
    assert [(i.name, i.station, i.radio, i.log) for i in infos] == [
        (None, None, None, False), ("one", 1, 1, True)]
    assert all(i.address.startswith("127.0.0.1:") for i in infos)


@pytest.mark.asyncio
async def test_many_clients_all_get_each_event() -> None:
    rig = await make_rig(per_address=100)  # sixty from one address, on purpose
    try:
        clients = [await rig.connect(f"client {i}") for i in range(60)]
        await clients[7].request("select", station=1, radio=1, antenna=1)
        events = await asyncio.gather(*(c.next_event("radio") for c in clients))
        assert all(e["tx"] == 1 for e in events)
        assert rig.server.client_count == 60
    finally:
        await dispose(rig)


@pytest.mark.asyncio
async def test_closing_the_server_disconnects_every_client(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.net")
    rig = await make_rig()
    clients = [await rig.connect(f"c{i}") for i in range(3)]
    await rig.server.close()
    for client in clients:
        await asyncio.wait_for(client.closed.wait(), 5)
        await client.close()
    assert rig.server.client_count == 0
    assert sum("the server is closing" in r.getMessage() for r in caplog.records) == 3


# ---- access --------------------------------------------------------------------------------


async def refused_at_once(port: int) -> bool:
    """Whether the server closes a new connection without a word, even after a request.
    From 127.0.0.2, another host as far as the server can tell: ``127.0.0.1`` (this
    computer's programs) is never refused by address."""
    reader, writer = await asyncio.open_connection(HOST, port, local_addr=("127.0.0.2", 0))
    writer.write(b'{"id": 1, "cmd": "state"}\n')
    try:
        data = await asyncio.wait_for(reader.read(), 5)
    except ConnectionResetError:
        data = b""
    writer.close()
    await asyncio.gather(writer.wait_closed(), return_exceptions=True)
    return data == b""


@pytest.mark.asyncio
async def test_a_client_outside_the_allow_list_is_refused_at_once(
    caplog: pytest.LogCaptureFixture,
) -> None:
    rig = await make_rig(allow=["10.0.0.0/8", "192.168.1.7"])
    try:
        assert await refused_at_once(rig.server.port)
        assert rig.server.client_count == 0
        assert rig.backend.calls == []
        refused = [r for r in caplog.records if r.levelno == logging.WARNING]
        assert refused and refused[0].getMessage().startswith("Refused a client from 127.0.0.2:")
    finally:
        await dispose(rig)


@pytest.mark.asyncio
async def test_a_client_in_the_allow_list_is_served() -> None:
    rig = await make_rig(allow=["127.0.0.1"])
    try:
        client = await rig.connect("allowed")
        assert await client.request("stop", rotator=1) == {}
    finally:
        await dispose(rig)


@pytest.mark.asyncio
async def test_a_new_allow_list_applies_to_new_connections(rig: Rig) -> None:
    kept = await rig.connect("kept")
    rig.server.set_allow(["10.0.0.0/8"])
    assert await refused_at_once(rig.server.port)
    assert await kept.request("stop", rotator=1) == {}


# ---- a client that stops reading ----------------------------------------------------------


@pytest.mark.asyncio
async def test_a_client_that_stops_reading_is_cut_off_and_the_others_get_every_event(
    caplog: pytest.LogCaptureFixture,
) -> None:
    rig = await make_rig(max_pending=64 * 1024)
    stuck = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        stuck.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        stuck.setblocking(False)
        await asyncio.get_running_loop().sock_connect(stuck, (HOST, rig.server.port))
        stuck.send(b'{"id": 1, "cmd": "hello", "client": "stuck", "log": true}\n')
        await until(lambda: any(i.name == "stuck" for i in rig.server.clients()))
        healthy = await rig.connect("healthy", log=True)
        published = 0
        while rig.server.client_count == 2 and published < 5000:
            rig.server.publish_log("info", f"{published} " + "x" * 4000)
            published += 1
            if published % 8 == 0:
                await asyncio.sleep(0)
        assert rig.server.client_count == 1, "the stuck client was never cut off"
        print(f"stuck client cut off after {published} events of 4 kB")
        assert [i.name for i in rig.server.clients()] == ["healthy"]
        for number in range(published):
            event = await healthy.next_event("log")
            assert event["message"].startswith(f"{number} ")
        assert await healthy.request("stop", rotator=1) == {}
        cut = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
        assert cut and cut[0].startswith('Disconnecting client "stuck" at 127.0.0.1:')
        assert "it stopped reading" in cut[0]
    finally:
        stuck.close()
        await dispose(rig)


@pytest.mark.asyncio
async def test_a_port_in_use_is_reported_with_its_number(rig: Rig) -> None:
    second = ClientServer(FakeBackend(), host=HOST, port=rig.server.port)
    with pytest.raises(HardwareError, match=f"cannot accept clients on TCP port {rig.server.port}"):
        await second.start()
    await second.close()
    client = await rig.connect("still served")
    assert await client.request("stop", rotator=1) == {}


@pytest.mark.asyncio
async def test_closing_does_not_wait_for_a_client_that_never_reads(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.net")
    rig = await make_rig(max_pending=64 * 1024 * 1024)
    rig.server.close_grace = 0.2
    stuck = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        stuck.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        stuck.setblocking(False)
        await asyncio.get_running_loop().sock_connect(stuck, (HOST, rig.server.port))
        stuck.send(b'{"id": 1, "cmd": "hello", "client": "stuck", "log": true}\n')
        await until(lambda: any(i.name == "stuck" for i in rig.server.clients()))
        for number in range(2000):  # 8 MB: more than the kernel's buffers hold
            rig.server.publish_log("info", f"{number} " + "x" * 4000)
        await asyncio.wait_for(rig.server.close(), 10)
        assert rig.server.client_count == 0
        assert any('"stuck"' in r.getMessage() and "the server is closing" in r.getMessage()
                   for r in caplog.records)
    finally:
        stuck.close()
        await dispose(rig)
