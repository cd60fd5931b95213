"""Single instance: real processes and real sockets hand files over; crashes leave nothing stuck."""

from __future__ import annotations

import asyncio
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from moas_gui import single_instance
from moas_gui.single_instance import InstanceError, claim, hand_over, instance_dir

NAME = "test-server"

# A moas-server in miniature: claim, or hand over the file named on the command line.
INSTANCE = r"""
import asyncio, sys
from pathlib import Path
from moas_gui.single_instance import claim, hand_over

directory, transport = Path(sys.argv[1]), sys.argv[2]
path = sys.argv[3] if len(sys.argv) > 3 else None

async def serve(server):
    done = asyncio.Event()
    def on_open(opened):
        print("OPEN", opened, flush=True)
        if opened is not None and opened.name == "quit.moas":
            done.set()
    await server.start(on_open)
    print("READY", flush=True)
    await done.wait()
    server.close()

server = claim("test-server", directory=directory, transport=transport)
if server is None:
    handed = hand_over("test-server", path, directory=directory, transport=transport)
    print("HANDED" if handed else "FAILED", flush=True)
    sys.exit(0 if handed else 1)
asyncio.run(serve(server))
"""


def launch(directory: Path, transport: str, path: str | None = None,
           cwd: Path | None = None) -> subprocess.Popen[str]:
    args = [sys.executable, "-c", INSTANCE, str(directory), transport]
    if path is not None:
        args.append(path)
    return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=cwd)


def wait_ready(process: subprocess.Popen[str]) -> None:
    assert process.stdout is not None
    line = process.stdout.readline()
    assert line == "READY\n", line + (process.stderr.read() if process.stderr else "")


@pytest.fixture
def directory(tmp_path: Path) -> Path:
    return tmp_path / "run"


@pytest.mark.realtime
@pytest.mark.parametrize("transport", ["unix", "tcp"])
def test_a_second_launch_hands_its_file_to_the_running_one_and_exits(
    directory: Path, tmp_path: Path, transport: str,
) -> None:
    first = launch(directory, transport)
    try:
        wait_ready(first)
        second = subprocess.run(
            [sys.executable, "-c", INSTANCE, str(directory), transport, "contest.moas"],
            capture_output=True, text=True, cwd=tmp_path, timeout=30, check=False)
        assert (second.returncode, second.stdout) == (0, "HANDED\n"), second.stderr
        assert hand_over(NAME, tmp_path / "quit.moas", directory=directory, transport=transport)
        out, err = first.communicate(timeout=10)
    finally:
        first.kill()
        first.communicate()
    assert out.splitlines() == [f"OPEN {tmp_path / 'contest.moas'}", f"OPEN {tmp_path / 'quit.moas'}"]
    assert first.returncode == 0, err
    assert not (directory / f"{NAME}.sock").exists() and not (directory / f"{NAME}.port").exists()


@pytest.mark.realtime
def test_simultaneous_launches_end_with_one_instance_holding_every_file(
    directory: Path, tmp_path: Path,
) -> None:
    names = ["a.moas", "b.moas", "c.moas", "d.moas"]
    processes = [launch(directory, "unix", name, cwd=tmp_path) for name in names]
    try:
        deadline = time.monotonic() + 30
        while sum(p.poll() is not None for p in processes) < 3 and time.monotonic() < deadline:
            time.sleep(0.05)
        running = [p for p in processes if p.poll() is None]
        assert len(running) == 1, "exactly one instance keeps running"
        assert hand_over(NAME, tmp_path / "quit.moas", directory=directory)
        outputs = {name: p.communicate(timeout=10)[0] for name, p in zip(names, processes)}
    finally:
        for process in processes:
            process.kill()
            process.communicate()
    winner = running[0]
    winner_name = names[processes.index(winner)]
    assert all(outputs[name] == "HANDED\n" for name in names if name != winner_name)
    opened = sorted(line for line in outputs[winner_name].splitlines() if line.startswith("OPEN"))
    expected = sorted(f"OPEN {tmp_path / n}" for n in [*names, "quit.moas"] if n != winner_name)
    assert opened == expected


@pytest.mark.realtime
def test_a_crashed_instance_leaves_a_socket_that_the_next_one_takes_over(
    directory: Path, tmp_path: Path,
) -> None:
    crashed = launch(directory, "unix")
    wait_ready(crashed)
    os.kill(crashed.pid, signal.SIGKILL)
    crashed.communicate(timeout=10)
    assert (directory / f"{NAME}.sock").exists(), "the crash left its socket file behind"
    assert not hand_over(NAME, "x.moas", directory=directory, timeout=2)

    heir = launch(directory, "unix")
    try:
        wait_ready(heir)
        assert hand_over(NAME, tmp_path / "after-crash.moas", directory=directory)
        assert hand_over(NAME, tmp_path / "quit.moas", directory=directory)
        out, _ = heir.communicate(timeout=10)
    finally:
        heir.kill()
        heir.communicate()
    assert f"OPEN {tmp_path / 'after-crash.moas'}" in out.splitlines()


def test_with_no_instance_running_hand_over_says_no_at_once(directory: Path) -> None:
    directory.mkdir(mode=0o700)
    leftover = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    leftover.bind(str(directory / f"{NAME}.sock"))
    leftover.close()
    # an hour's patience: were it waiting for an answer, the test's own timeout would end it
    assert hand_over(NAME, "a.moas", directory=directory, timeout=3600) is False
    assert hand_over(NAME, "a.moas", directory=directory, transport="tcp",
                     timeout=3600) is False


def test_only_one_claim_succeeds_and_close_frees_the_name(directory: Path) -> None:
    first = claim(NAME, directory=directory)
    assert first is not None
    try:
        assert claim(NAME, directory=directory) is None
        other = claim("another-name", directory=directory)
        assert other is not None
        other.close()
    finally:
        first.close()
        first.close()
    again = claim(NAME, directory=directory)
    assert again is not None
    again.close()


@pytest.mark.asyncio
async def test_the_tcp_way_refuses_a_request_without_the_users_token(directory: Path) -> None:
    server = claim(NAME, directory=directory, transport="tcp")
    assert server is not None
    opened: list[Path | None] = []
    await server.start(opened.append)
    try:
        port = json.loads((directory / f"{NAME}.port").read_text())["port"]
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        writer.write(b'{"open": "/etc/evil.moas", "token": "guess"}\n')
        reply = json.loads(await reader.readline())
        writer.close()
        assert reply["ok"] is False and "token" in reply["error"]
        assert await asyncio.to_thread(hand_over, NAME, None, directory=directory,
                                       transport="tcp")
    finally:
        server.close()
    assert opened == [None]
    assert oct((directory / f"{NAME}.lock").stat().st_mode & 0o777) == "0o600"


@pytest.mark.asyncio
async def test_garbage_and_huge_requests_are_refused_and_the_server_carries_on(
    directory: Path, caplog: pytest.LogCaptureFixture,
) -> None:
    server = claim(NAME, directory=directory)
    assert server is not None
    opened: list[Path | None] = []
    await server.start(opened.append)
    path = str(directory / f"{NAME}.sock")
    try:
        for junk in (b"\xff\xfe not json\n", b"[1, 2]\n", b'{"open": 42}\n', b'{"file": "x"}\n'):
            reader, writer = await asyncio.open_unix_connection(path)
            writer.write(junk)
            reply = json.loads(await reader.readline())
            writer.close()
            assert reply["ok"] is False and reply["error"]
        reader, writer = await asyncio.open_unix_connection(path)
        writer.write(b'{"open": "' + b"x" * 100_000 + b'"}\n')
        assert await reader.read() == b""
        writer.close()
        assert await asyncio.to_thread(hand_over, NAME, "/srv/station.moas", directory=directory)
    finally:
        server.close()
    assert opened == [Path("/srv/station.moas")]
    assert sum("Refused a hand-over" in r.getMessage() for r in caplog.records) == 4


@pytest.mark.asyncio
async def test_a_crowd_of_silent_connections_is_bounded_and_a_hand_over_follows(
    directory: Path, caplog: pytest.LogCaptureFixture,
) -> None:
    """The hand-over socket admits through the program's one door: at most HAND_OVERS
    connections at once; the next is told why and closed; once the crowd has gone a
    second launch is served."""
    server = claim(NAME, directory=directory)
    assert server is not None
    opened: list[Path | None] = []
    await server.start(opened.append)
    path = str(directory / f"{NAME}.sock")
    crowd: list[asyncio.StreamWriter] = []
    try:
        for _ in range(single_instance.HAND_OVERS):
            _reader, writer = await asyncio.open_unix_connection(path)
            crowd.append(writer)
        reader, writer = await asyncio.open_unix_connection(path)
        reply = json.loads(await asyncio.wait_for(reader.readline(), 10))
        writer.close()
        assert reply["ok"] is False and "the most" in reply["error"], reply
        for each in crowd:
            each.close()
        deadline = time.monotonic() + 30
        while server.admission.count and time.monotonic() < deadline:
            await asyncio.sleep(0.01)
        assert server.admission.count == 0
        assert await asyncio.to_thread(hand_over, NAME, "/srv/station.moas", directory=directory)
    finally:
        server.close()
    assert opened == [Path("/srv/station.moas")]
    refused = [r.getMessage() for r in caplog.records if "Refused a hand-over connection" in r.getMessage()]
    assert len(refused) == 1, refused


@pytest.mark.asyncio
async def test_when_the_running_instance_cannot_open_the_file_the_caller_hears_no(
    directory: Path,
) -> None:
    server = claim(NAME, directory=directory)
    assert server is not None

    def refuse(path: Path | None) -> None:
        raise RuntimeError("a dialog is already open")

    await server.start(refuse)
    try:
        assert await asyncio.to_thread(hand_over, NAME, "/x.moas", directory=directory) is False
    finally:
        server.close()


def test_a_directory_other_users_can_write_is_refused(tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    with pytest.raises(InstanceError, match="other users"):
        claim(NAME, directory=shared)
    assert not (shared / f"{NAME}.lock").exists()


def test_the_directory_is_private_and_under_the_runtime_dir(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path))
    assert instance_dir() == tmp_path / "moas-gui"
    server = claim(NAME)
    assert server is not None
    server.close()
    assert (tmp_path / "moas-gui").stat().st_mode & 0o777 == 0o700
    monkeypatch.delenv("XDG_RUNTIME_DIR")
    assert instance_dir().name == f"moas-gui-{os.getuid()}"


def test_names_that_could_escape_the_directory_are_refused(directory: Path) -> None:
    for bad in ("../moas", "a/b", "", ".hidden"):
        with pytest.raises(ValueError, match="instance name"):
            claim(bad, directory=directory)


def test_the_public_names_do_not_drift() -> None:
    assert sorted(single_instance.__all__) == sorted([
        "Command", "DEFAULT_NAME", "HandOver", "InstanceError", "InstanceServer",
        "OpenCallback", "Vetting", "claim", "command", "default_transport", "hand_over",
        "instance_dir", "offer"])


def test_a_refusal_reaches_the_second_launch_with_its_reason(directory: Path, tmp_path: Path) -> None:
    seen: list[tuple[object, dict[str, object]]] = []

    def vet(path: Path | None, launch: dict[str, object]) -> str | None:
        seen.append((path, launch))
        return "it runs headless" if launch.get("headless") else None

    async def scenario() -> tuple[single_instance.HandOver, single_instance.HandOver]:
        server = claim(NAME, directory=directory)
        assert server is not None
        opened: list[Path | None] = []
        await server.start(opened.append, vet)
        refused = await asyncio.to_thread(
            single_instance.offer, NAME, tmp_path / "a.moas", {"headless": True},
            directory=directory)
        taken = await asyncio.to_thread(
            single_instance.offer, NAME, tmp_path / "b.moas", {"headless": False},
            directory=directory)
        server.close()
        assert opened == [tmp_path / "b.moas"]
        return refused, taken

    refused, taken = asyncio.run(scenario())
    assert refused == single_instance.HandOver(taken=False, refusal="it runs headless")
    assert taken.taken
    assert seen == [(tmp_path / "a.moas", {"headless": True}), (tmp_path / "b.moas", {"headless": False})]


@pytest.mark.skipif(not hasattr(socket, "SO_PEERCRED"), reason="needs SO_PEERCRED (Linux)")
def test_the_hand_over_socket_refuses_another_user(
        directory: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    async def scenario() -> single_instance.HandOver:
        server = claim(NAME, directory=directory)
        assert server is not None
        opened: list[Path | None] = []
        await server.start(opened.append)
        real = os.getuid()
        # the server now believes it belongs to another user: our uid is a stranger's
        monkeypatch.setattr(single_instance.os, "getuid", lambda: real + 4242)
        answer = await asyncio.to_thread(hand_over_offer, directory, tmp_path / "x.moas")
        server.close()
        assert opened == []
        return answer

    answer = asyncio.run(scenario())
    assert not answer.taken and answer.refusal is not None
    assert "only the same user" in answer.refusal


def hand_over_offer(directory: Path, path: Path) -> single_instance.HandOver:
    return single_instance.offer(NAME, path, directory=directory)


@pytest.mark.asyncio
@pytest.mark.parametrize("transport", ["unix", "tcp"])
async def test_a_registered_command_is_awaited_sent_once_and_its_whole_answer_comes_back(
    directory: Path, transport: single_instance.Transport,
) -> None:
    server = claim(NAME, directory=directory, transport=transport)
    assert server is not None
    done: list[dict[str, object]] = []
    opened: list[Path | None] = []

    async def restart(launch: dict[str, object]) -> dict[str, object]:
        done.append(launch)
        await asyncio.sleep(0.05)  # the handler is awaited: the answer follows its work
        if launch.get("file") == "/broken.moas":
            return {"ok": False, "error": "it has errors", "keyed": ["station 1"]}
        if launch.get("file") == "/fails.moas":
            raise RuntimeError("the port vanished")
        return {"ok": True, "done": "restarted", "running": launch.get("file")}

    await server.start(opened.append, lambda _path, _launch: "refused by vet",
                       {"restart": restart})
    try:
        def ask(path: str) -> single_instance.HandOver:
            return single_instance.command(NAME, {"command": "restart", "file": path},
                                           directory=directory, transport=transport)
        good = await asyncio.to_thread(ask, "/good.moas")
        assert good.taken and good.done == "restarted" and good.answer["running"] == "/good.moas"
        bad = await asyncio.to_thread(ask, "/broken.moas")
        assert not bad.taken and bad.refusal == "it has errors"
        assert bad.answer["keyed"] == ["station 1"]
        failed = await asyncio.to_thread(ask, "/fails.moas")
        assert not failed.taken and failed.refusal is not None
        assert "the port vanished" in failed.refusal  # told, and the server carries on
        assert [launch["file"] for launch in done] == ["/good.moas", "/broken.moas",
                                                       "/fails.moas"]  # each sent once
        # an unregistered command still goes to the vetting callback
        other = await asyncio.to_thread(single_instance.command, NAME, {"command": "other"},
                                        directory=directory, transport=transport)
        assert other.taken and other.done == "refused by vet"
    finally:
        server.close()
    assert opened == []
    gone = single_instance.command(NAME, {"command": "restart"}, directory=directory,
                                   transport=transport)
    assert gone.running is False and not gone.taken  # nobody runs: said at once
    never = single_instance.command(NAME, {"command": "restart"},
                                    directory=directory.parent / "never-made")
    assert never.running is False and not (directory.parent / "never-made").exists()
