"""moas-rotator hardened: it binds loopback unless told otherwise, a second controlling
server from another address is refused (or takes over when allowed, the first told),
and CONFIGURE opens serial devices and what the user allowed, nothing else."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import sys
from collections.abc import AsyncIterator, Callable
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until

from moas_gui.cli.rotator import _arguments
from moas_gui.hw.rotators.controllers.base import SerialSettings
from moas_gui.hw.rotators.moas_rotator_process import default_command
from moas_gui.rotator_program.ports import port_refusal
from moas_gui.rotator_program.program import RotatorProgram
from moas_gui.rotator_program.serial_link import ControllerPort

POSIX = pytest.mark.skipif(sys.platform == "win32", reason="device paths are POSIX")


class Opened:
    """An opener that records what the program opened, and opens nothing real."""

    def __init__(self) -> None:
        self.ports: list[str] = []

    async def __call__(
        self,
        port: str,
        settings: SerialSettings,
        on_data: Callable[[bytes], None],
        on_lost: Callable[[Exception], None],
    ) -> ControllerPort:
        self.ports.append(port)
        return _Silent(port)


class _Silent:
    def __init__(self, name: str) -> None:
        self.name = name

    def write(self, data: bytes) -> None:
        pass

    def close(self) -> None:
        pass


@pytest_asyncio.fixture
async def program_of() -> AsyncIterator[
    Callable[..., asyncio.Future[tuple[RotatorProgram, Opened, int]]]
]:
    made: list[RotatorProgram] = []

    async def make(**options: object) -> tuple[RotatorProgram, Opened, int]:
        opened = Opened()
        program = RotatorProgram(opener=opened, retry=0.1, **options)  # type: ignore[arg-type]
        made.append(program)
        _, port = await program.start("127.0.0.1", 0)
        return program, opened, port

    yield make  # type: ignore[misc]
    for program in made:
        await program.close()


async def connect(
    port: int, source: str = "127.0.0.1"
) -> tuple[asyncio.StreamReader, asyncio.StreamWriter]:
    return await asyncio.open_connection("127.0.0.1", port, local_addr=(source, 0))


async def all_said(reader: asyncio.StreamReader) -> bytes:
    async with asyncio.timeout(10):
        return await reader.read()


async def shut(writer: asyncio.StreamWriter) -> None:
    writer.close()
    with contextlib.suppress(OSError):
        await writer.wait_closed()


def test_it_binds_loopback_unless_told_otherwise() -> None:
    assert _arguments([]).bind == "127.0.0.1"
    assert _arguments(["--bind", "0.0.0.0"]).bind == "0.0.0.0"
    assert _arguments(["--allow", "socket://a:1", "--allow", "COM9"]).allow == [
        "socket://a:1",
        "COM9",
    ]


@POSIX
def test_configure_refuses_urls_files_and_devices_that_are_not_serial(tmp_path: Path) -> None:
    (tmp_path / "plain").write_text("x")
    os.symlink("/dev/null", tmp_path / "null")
    for port, words in (
        ("socket://192.0.2.1:4001", "is a URL"),
        ("loop://", "is a URL"),
        ("rfc2217://192.0.2.1:1", "is a URL"),
        ("/etc/passwd", "/etc/passwd is not a serial device"),
        ("/dev/zero", "not a serial device"),
        ("/dev/tty", "not a serial device"),
        ("/dev/tty1", "not a serial device"),
        (str(tmp_path / "plain"), "not a serial device"),
        (str(tmp_path / "null"), "which leads to /dev/null"),
        ("ttyUSB0", "not a serial port name"),
    ):
        refusal = port_refusal(port)
        assert refusal is not None and words in refusal, (port, refusal)
        assert "moas-rotator --allow" in refusal


@POSIX
def test_configure_accepts_serial_devices_and_what_the_user_allowed() -> None:
    for port in (
        "COM3",
        "com14@4800",
        "/dev/ttyUSB7",
        "/dev/ttyACM0@9600",
        "/dev/ttyS0",
        "/dev/serial/by-id/usb-FTDI_FT232R-if00-port0",
        "/dev/cu.usbserial-A1",
        "/dev/rfcomm0",
    ):
        assert port_refusal(port) is None, port
    master, slave = os.openpty()
    try:
        assert port_refusal(os.ttyname(slave)) is None  # a pseudo-terminal
    finally:
        os.close(master)
        os.close(slave)
    assert port_refusal("socket://10.0.0.5:4001", ["socket://10.0.0.5:4001"]) is None
    assert port_refusal("socket://10.0.0.5:4002", ["socket://10.0.0.5:*"]) is None
    assert port_refusal("socket://10.0.0.6:4001", ["socket://10.0.0.5:*"]) is not None


def test_the_server_starts_it_allowing_its_configurations_ports() -> None:
    command = default_command(13020, ["socket://10.0.0.5:4001", "COM3", "COM3"])
    assert command[command.index("--bind") + 1] == "127.0.0.1"
    allowed = [command[i + 1] for i, word in enumerate(command) if word == "--allow"]
    assert allowed == ["socket://10.0.0.5:4001", "COM3"]
    arguments = _arguments(command[3:])
    assert port_refusal("socket://10.0.0.5:4001", arguments.allow) is None


@pytest.mark.asyncio
async def test_a_configure_naming_a_url_or_a_file_opens_nothing(
    program_of: Callable[..., asyncio.Future[tuple[RotatorProgram, Opened, int]]],
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.WARNING, logger="moas_gui.rotator_program")
    program, opened, port = await program_of()
    reader, writer = await connect(port)
    try:
        writer.write(
            b"CONFIGURE 1 4 /etc/passwd 100\rCONFIGURE 2 4 socket://192.0.2.1:22 100\r"
            b"CONFIGURE 3 4 COM3 100\rVERSION\r"
        )
        async with asyncio.timeout(5):
            assert (await reader.readuntil(b"\r")).startswith(b"VERSION")
        assert opened.ports == ["COM3"] and set(program.rotators) == {3}
        refused = [r.getMessage() for r in caplog.records if "CONFIGURE refused" in r.getMessage()]
        assert len(refused) == 2 and "rotator 1" in refused[0] and "rotator 2" in refused[1]
    finally:
        await shut(writer)


@pytest.mark.asyncio
async def test_a_second_server_from_another_address_is_refused(
    program_of: Callable[..., asyncio.Future[tuple[RotatorProgram, Opened, int]]],
) -> None:
    program, _, port = await program_of()
    reader, writer = await connect(port, "127.0.0.1")
    try:
        await until(lambda: program.connected)
        other_reader, other_writer = await connect(port, "127.0.0.2")
        said = await all_said(other_reader)
        assert said.startswith(b"BUSY: the MOAS Server at 127.0.0.1:")
        await shut(other_writer)
        writer.write(b"VERSION\r")  # the first is still in control
        async with asyncio.timeout(5):
            assert (await reader.readuntil(b"\r")).startswith(b"VERSION")
    finally:
        await shut(writer)


@pytest.mark.asyncio
async def test_a_second_server_takes_over_only_when_allowed_and_the_first_is_told(
    program_of: Callable[..., asyncio.Future[tuple[RotatorProgram, Opened, int]]],
) -> None:
    program, _, port = await program_of(take_over=True)
    reader, writer = await connect(port, "127.0.0.1")
    try:
        await until(lambda: program.connected)
        new_reader, new_writer = await connect(port, "127.0.0.2")
        said = await all_said(reader)
        assert said.startswith(b"TAKEN OVER by the MOAS Server at 127.0.0.2:")
        new_writer.write(b"VERSION\r")
        async with asyncio.timeout(5):
            assert (await new_reader.readuntil(b"\r")).startswith(b"VERSION")
        await shut(new_writer)
    finally:
        await shut(writer)
