"""``--record-serial``: a switch link's sessions recorded against an emulated box on a real
pseudo-terminal, then replayed through a new session that must answer the same way;
a changed recording (the box said something else) is found at the byte that differs."""

from __future__ import annotations

import json
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until
from switch_support import Cable

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.link import LinkOptions, LinkStatus, LinkTiming, SwitchLink
from moas_gui.hw.moas2.recording import (
    RecordingError,
    SerialRecorder,
    bytes_text,
    read_recording,
    replay,
    text_bytes,
)
from moas_gui.state_store import switch_from_data, switch_to_data

pytestmark = pytest.mark.realtime

FAST = LinkTiming(ping_interval=0.05, answer_timeout=2.0, retry_first=0.05, retry_max=0.2)


def wanted(*stations: tuple[int, set[int]]) -> SwitchState:
    made = [StationAntennas(tx=slot, tx_relays=frozenset(relays), rx=slot,
                            rx_relays=frozenset(relays)) for slot, relays in stations]
    return SwitchState(stations=(*made, *(StationAntennas() for _ in range(6 - len(made)))),
                       conflicts=frozenset({(a, a) for a in range(10)}))


STATE_A = wanted((1, {1, 2}), (2, {8}))
STATE_B = wanted((3, {5}), (2, {8}))


@pytest_asyncio.fixture
async def box(tmp_path: Path) -> AsyncIterator[tuple[Cable, EmulatedBox]]:
    cable = Cable(tmp_path / "moas")
    made = cable.plug()
    yield cable, made
    cable.unplug()


async def record_a_session(cable: Cable, box: EmulatedBox, path: Path) -> None:
    """Load, change, a station keyed and released, Stop and Start, all recorded."""
    recorder = SerialRecorder(path, encode_state=switch_to_data)
    link = SwitchLink(1, str(cable.link), 0, options=LinkOptions(timing=FAST), recorder=recorder)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: box.view().relays == {1, 2, 8} and link.status is LinkStatus.OK)
        link.apply(STATE_B)
        await until(lambda: box.view().relays == {5, 8})
        box.set_tr(2, True)
        await until(lambda: link.session.keyed() == frozenset({2}))
        box.set_tr(2, False)
        await until(lambda: link.session.keyed() == frozenset())
        link.stop()
        await until(lambda: box.view().relays == frozenset())
        link.start()
        await until(lambda: box.view().relays == {5, 8})
        assert await link.ask_relays() == {5, 8}
    finally:
        await link.close()
        recorder.close()


@pytest.mark.asyncio
async def test_a_recorded_session_replays_byte_for_byte(box: tuple[Cable, EmulatedBox],
                                                        tmp_path: Path) -> None:
    path = tmp_path / "switch.jsonl"
    await record_a_session(*box, path)
    lines = read_recording(path)
    kinds = {line["kind"] for line in lines}
    assert {"recording", "session", "opened", "want", "out", "in", "tick", "stop",
            "start", "ask", "lost"} <= kinds
    result = replay(lines, 1, decode_state=switch_from_data)
    assert result.same, result.difference
    assert result.difference is None
    assert b"!1B35;" in result.recorded  # station 1 moved to slot 3 (relay 5)
    assert b"*0;" in result.recorded  # the operator's Stop
    assert result.calls > 10


@pytest.mark.asyncio
async def test_a_replay_finds_a_session_that_answers_differently(
        box: tuple[Cable, EmulatedBox], tmp_path: Path) -> None:
    path = tmp_path / "switch.jsonl"
    await record_a_session(*box, path)
    lines = read_recording(path)
    # the box of the recording said another unit id: a session must not drive it
    changed = False
    for line in lines:
        if line["kind"] == "in" and ":1000;" in line["data"]:
            line["data"] = line["data"].replace(":1000;", ":1007;")
            changed = True
            break
    assert changed
    result = replay(lines, 1, decode_state=switch_from_data)
    assert not result.same
    assert result.difference is not None and result.difference.startswith("byte ")


def test_bytes_read_as_text_both_ways() -> None:
    raw = bytes(range(256))
    assert text_bytes(bytes_text(raw)) == raw
    assert bytes_text(b"!1B35;") == "!1B35;"
    assert bytes_text(b"\\\r") == "\\x5c\\x0d"


def test_a_broken_recording_line_is_named(tmp_path: Path) -> None:
    path = tmp_path / "bad.jsonl"
    path.write_text(json.dumps({"kind": "recording"}) + "\n{not json\n")
    with pytest.raises(RecordingError, match=r"bad.jsonl:2: not a recording line"):
        read_recording(path)


def test_a_recording_goes_on_after_a_restart(tmp_path: Path) -> None:
    path = tmp_path / "r.jsonl"
    for _ in range(2):
        recorder = SerialRecorder(path)
        recorder.note(1, "out", 0.5, data=b"';")
        recorder.close()
    kinds = [line["kind"] for line in read_recording(path)]
    assert kinds == ["recording", "out", "recording", "out"]
