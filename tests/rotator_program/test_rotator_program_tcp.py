"""The program's TCP protocol on 127.0.0.1, with emulated controllers on pseudo-terminals,
on the bench's fake clock (tests/rotator_program/pty_bench.py): the program's polls, quiet times and
retries and the controllers' turns take no real time."""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator, Callable, Iterator
from pathlib import Path

import pytest
import pytest_asyncio
from pty_bench import PtyBench

from moas_gui.hw.rotators.controllers.models import find_model
from moas_gui.hw.rotators.controllers.pty_host import EmulatorHost, ServedPort
from moas_gui.rotator_program.program import RotatorProgram
from moas_gui.testing.faulty_controller import FaultyController

SPEED = 200.0


@pytest.fixture
def bench() -> Iterator[PtyBench]:
    with PtyBench() as running:
        yield running


@pytest.fixture
def host(bench: PtyBench) -> EmulatorHost:
    return bench.host


@pytest_asyncio.fixture
async def program(bench: PtyBench) -> AsyncIterator[tuple[RotatorProgram, int]]:
    """The program on a free port, its ports opened through the bench, on the bench's
    clock; it closes before the emulators go away."""
    running = RotatorProgram(retry=0.1, opener=bench.open, clock=bench.clock)
    _, port = await running.start("127.0.0.1", 0)
    try:
        yield running, port
    finally:
        await running.close()


class Server:
    """A MOAS Server stand-in: a TCP client that collects the program's lines (as they
    come, in a task of its own), waiting on the bench's clock."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter,
                 bench: PtyBench) -> None:
        self.reader = reader
        self.writer = writer
        self.bench = bench
        self.lines: list[str] = []
        self.closed = False
        """True once the program closed the connection."""
        self._reading = asyncio.create_task(self._read())

    @classmethod
    async def connect(cls, port: int, bench: PtyBench) -> Server:
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        return cls(reader, writer, bench)

    def send(self, *lines: str, end: str = "\r") -> None:
        self.writer.write("".join(line + end for line in lines).encode("latin-1"))

    async def _read(self) -> None:
        buffer = b""
        try:
            while data := await self.reader.read(4096):
                buffer += data
                *complete, buffer = buffer.split(b"\r")
                self.lines += [line.decode("ascii") for line in complete]
        except (ConnectionError, OSError):
            pass
        self.closed = True

    async def wait_for(self, wanted: Callable[[list[str]], bool], timeout: float = 5.0,
                       what: str = "") -> None:
        """Moves the clock on until ``wanted(lines)``, for at most ``timeout`` seconds."""
        try:
            await self.bench.until(lambda: wanted(self.lines), timeout, what)
        except AssertionError:
            raise AssertionError(f"no {what or 'such message'} in {self.lines}") from None

    async def wait_line(self, line: str, timeout: float = 5.0) -> None:
        await self.wait_for(lambda lines: line in lines, timeout, repr(line))

    async def close(self) -> None:
        self.writer.close()
        try:
            await self.writer.wait_closed()
        except (ConnectionError, OSError):
            pass
        await self._reading


def served(host: EmulatorHost, model: str, azimuth: float, link: str | None = None,
           speed: float = SPEED) -> ServedPort:
    return host.add(find_model(model).make_emulator(azimuth, speed, host.clock()), link=link)


def where(host: EmulatorHost, port: ServedPort) -> tuple[float, bool]:
    return host.call(port, lambda e, now: (e.azimuth, e.busy))


@pytest.mark.asyncio
async def test_version_is_major_dot_minor(
        bench: PtyBench, program: tuple[RotatorProgram, int]) -> None:
    server = await Server.connect(program[1], bench)
    server.send("VERSION")
    await server.wait_line("VERSION 0.1")
    await server.close()


@pytest.mark.asyncio
async def test_configure_in_both_orders_reports_the_headings(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost) -> None:
    first = served(host, "RotorEZ", 45)
    second = served(host, "Yaesu", 300)
    server = await Server.connect(program[1], bench)
    server.send(f"CONFIGURE 0 2 {first.path} 200", f"CONFIGURE 1 {second.path} 4 200")
    await server.wait_line("0 45")
    await server.wait_line("1 300")
    assert program[0].rotators[0].model.name == "RotorEZ"
    assert program[0].rotators[1].model.name == "Yaesu"
    await server.close()


@pytest.mark.asyncio
async def test_lf_and_crlf_endings_are_accepted(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost) -> None:
    port = served(host, "GS-232A", 10)
    server = await Server.connect(program[1], bench)
    server.send("VERSION", end="\n")
    server.send(f"CONFIGURE 4 {port.path} GS-232A 200", end="\r\n")
    await server.wait_line("VERSION 0.1")
    await server.wait_line("4 10")
    await server.close()


@pytest.mark.asyncio
async def test_rotate_reports_the_heading_as_it_changes_and_stop_stops(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost) -> None:
    port = served(host, "RC2800P-X", 100, speed=100.0)
    server = await Server.connect(program[1], bench)
    server.send(f"CONFIGURE 0 9 {port.path} 100")
    await server.wait_line("0 100")
    server.send("ROTATE 0 150")
    await server.wait_line("0 150")
    steps = [int(line.split()[1]) for line in server.lines if line.startswith("0 ")]
    assert len(steps) >= 3 and steps == sorted(steps)  # on the way, not just the end
    server.send("ROTATE 0 350")
    await bench.until(lambda: where(host, port)[0] > 170)
    server.send("STOP 0")
    await bench.until(lambda: not where(host, port)[1])
    stopped = where(host, port)[0]
    assert stopped < 345
    # The controller shows tenths; the report is whole degrees.
    await server.wait_for(lambda lines: abs(int(lines[-1].split()[1]) - stopped) <= 1,
                          what="the heading where it stopped")
    await server.close()


@pytest.mark.asyncio
async def test_a_heading_changed_at_the_controller_is_reported_within_a_poll(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost) -> None:
    port = served(host, "Rot2Prog", 20)
    server = await Server.connect(program[1], bench)
    server.send(f"CONFIGURE 0 Rot2Prog {port.path} 500")
    await server.wait_line("0 20")
    host.call(port, lambda e, now: e.turn_by_hand(77.0, now))
    await server.wait_line("0 77", timeout=0.5 + 0.3 + 0.5)  # poll + quiet time + answer
    await server.close()


@pytest.mark.asyncio
async def test_a_server_that_disconnects_mid_turn_leaves_the_turn_and_polling_running(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost,
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.rotator_program")
    rotators, tcp = program
    port = served(host, "Yaesu", 0, speed=100.0)
    server = await Server.connect(tcp, bench)
    server.send(f"CONFIGURE 0 4 {port.path} 100", "ROTATE 0 180")
    await bench.until(lambda: where(host, port)[1])
    await server.close()
    await bench.until(lambda: not rotators.connected)
    driver = rotators.rotators[0]
    await bench.until(lambda: driver.heading == 180, timeout=5.0)  # still polled, turn finished
    assert where(host, port)[0] == pytest.approx(180.0)
    assert any("stay configured and polled" in r.getMessage() for r in caplog.records)
    # The server comes back and configures the same: same driver, heading at once.
    again = await Server.connect(tcp, bench)
    again.send(f"CONFIGURE 0 4 {port.path} 100")
    await again.wait_line("0 180", timeout=1.0)
    assert rotators.rotators[0] is driver
    await again.close()


@pytest.mark.asyncio
async def test_a_new_server_connection_replaces_the_old_one(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost) -> None:
    port = served(host, "Prosistel D", 5)
    old = await Server.connect(program[1], bench)
    old.send(f"CONFIGURE 0 10 {port.path} 100")
    await old.wait_line("0 5")
    new = await Server.connect(program[1], bench)
    # The old connection is closed by the program.
    await bench.until(lambda: old.closed, timeout=2.0, what="the old connection closed")
    assert old.closed
    # Headings go to a connection only once it has configured the rotator.
    host.call(port, lambda e, now: e.turn_by_hand(33.0, now))
    await bench.advance(0.5)
    assert new.lines == []
    new.send(f"CONFIGURE 0 10 {port.path} 100", "VERSION")
    await new.wait_line("0 33")
    await new.wait_line("VERSION 0.1")
    await old.close()
    await new.close()


@pytest.mark.asyncio
async def test_a_vanished_port_is_logged_and_the_other_rotators_carry_on(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost,
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.rotator_program")
    link = str(tmp_path / "usb0")
    doomed = served(host, "Yaesu", 10, link=link)
    other = served(host, "GS-232A", 20)
    server = await Server.connect(program[1], bench)
    server.send(f"CONFIGURE 0 4 {link} 100", f"CONFIGURE 1 GS-232A {other.path} 100")
    await server.wait_line("0 10")
    await server.wait_line("1 20")
    host.remove(doomed)
    await bench.until(lambda: any(f"rotator 0 (Yaesu on {link}): port {link} failed"
                                  in r.getMessage() for r in caplog.records))
    server.send("ROTATE 0 50", "ROTATE 1 40")
    await server.wait_line("1 40")
    refused = [r.getMessage() for r in caplog.records if "ROTATE 50 refused" in r.getMessage()]
    assert refused == [f"rotator 0 (Yaesu on {link}): ROTATE 50 refused: port {link} is not open"]
    # It comes back: the rotator works again without a new CONFIGURE.
    served(host, "Yaesu", 99, link=link)
    await server.wait_line("0 99")
    await server.close()


@pytest.mark.asyncio
async def test_garbage_from_one_controller_is_logged_and_nothing_else_stops(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost,
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, logger="moas_gui.rotator_program")
    noisy = FaultyController(find_model("RotorEZ").make_emulator(70, SPEED))
    noisy.noise = b"\x00\xffNOISE"
    noisy_port = host.add(noisy)
    quiet = served(host, "Yaesu", 80)
    server = await Server.connect(program[1], bench)
    server.send(f"CONFIGURE 0 2 {noisy_port.path} 100", f"CONFIGURE 1 4 {quiet.path} 100")
    await server.wait_line("0 70")
    await server.wait_line("1 80")
    server.send("ROTATE 1 90")
    await server.wait_line("1 90")
    bad = [r.getMessage() for r in caplog.records if "ignored" in r.getMessage()]
    assert bad and bad[0].startswith(f"rotator 0 (RotorEZ on {noisy_port.path}): ignored")
    await server.close()


@pytest.mark.asyncio
async def test_malformed_commands_each_give_a_log_line_and_nothing_stops(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost,
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, logger="moas_gui.rotator_program")
    port = served(host, "Yaesu", 12)
    server = await Server.connect(program[1], bench)
    server.send(f"CONFIGURE 0 4 {port.path} 100")
    await server.wait_line("0 12")
    caplog.clear()
    bad = ["FLY 0", "ROTATE 0 east", "ROTATE 0 999", "ROTATE 5 10", "STOP 5", "STOP",
           "CONFIGURE 1 4 COM1", "CONFIGURE 3 7 /dev/nowhere 1000", "\x00\x01\x02"]
    server.send(*bad)
    server.send("VERSION", "ROTATE 0 33")
    await server.wait_line("VERSION 0.1")
    await server.wait_line("0 33")
    messages = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(messages) == len(bad)
    expected = [
        "bad command from the server 'FLY 0': unknown command 'FLY'",
        "rotator 0: bad command from the server 'ROTATE 0 east': heading 'east'",
        f"rotator 0 (Yaesu on {port.path}): ROTATE 999 refused: Yaesu: heading 999 is outside",
        "rotator 5: ROTATE 10 refused: this rotator is not configured",
        "rotator 5: STOP refused: this rotator is not configured",
        "bad command from the server 'STOP': STOP needs <rotator>",
        "rotator 1: bad command from the server 'CONFIGURE 1 4 COM1': CONFIGURE needs",
        "rotator 3: CONFIGURE refused: unknown rotator model '7' (known: 1 DCU1, 2 RotorEZ",
        "bad command from the server '\\x00\\x01\\x02': unknown command",
    ]
    for message, start in zip(messages, expected, strict=True):
        assert message.startswith(start), message
    await server.close()


@pytest.mark.asyncio
async def test_an_unknown_model_leaves_the_rotator_as_it_was(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost,
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, logger="moas_gui.rotator_program")
    port = served(host, "Yaesu", 40)
    server = await Server.connect(program[1], bench)
    server.send(f"CONFIGURE 2 4 {port.path} 100")
    await server.wait_line("2 40")
    driver = program[0].rotators[2]
    server.send(f"CONFIGURE 2 Hygain {port.path} 100", "ROTATE 2 60")
    await server.wait_line("2 60")
    assert program[0].rotators[2] is driver
    message = next(r.getMessage() for r in caplog.records if "refused" in r.getMessage())
    assert message.startswith("rotator 2: CONFIGURE refused: unknown rotator model 'Hygain'")
    assert message.endswith(f"; it stays rotator 2 (Yaesu on {port.path})")
    await server.close()


@pytest.mark.asyncio
async def test_a_port_given_to_another_rotator_is_taken_from_the_first(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost) -> None:
    port = served(host, "Yaesu", 40)
    server = await Server.connect(program[1], bench)
    server.send(f"CONFIGURE 0 4 {port.path} 100")
    await server.wait_line("0 40")
    server.send(f"CONFIGURE 1 4 {port.path} 100")
    await server.wait_line("1 40")
    assert sorted(program[0].rotators) == [1]
    await server.close()


@pytest.mark.asyncio
async def test_configure_with_another_port_moves_the_rotator(
        bench: PtyBench, program: tuple[RotatorProgram, int], host: EmulatorHost) -> None:
    first = served(host, "Yaesu", 40)
    second = served(host, "RC2800P-A", 41)
    server = await Server.connect(program[1], bench)
    server.send(f"CONFIGURE 0 4 {first.path} 100")
    await server.wait_line("0 40")
    server.send(f"CONFIGURE 0 8 {second.path} 100")
    await server.wait_line("0 41")
    assert program[0].rotators[0].port == second.path
    await server.close()
