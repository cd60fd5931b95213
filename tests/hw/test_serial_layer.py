"""The serial layer (moas_gui/serial) on real pseudo-terminals, read both ways: by the
event loop watching the port and by a reader thread.

The test holds the master side of each terminal (what a box's end of the cable would
be); the layer opens the slave side by its path, as it opens /dev/ttyUSB0 or COM7."""

from __future__ import annotations

import asyncio
import os
import pty
import tty
from collections.abc import Iterator
from dataclasses import dataclass, field

import pytest
from helpers import until

from moas_gui.errors import HardwareError
from moas_gui.hw.moas2.errors import PortError as SwitchPortError
from moas_gui.rotator_program.serial_link import PortError as RotatorPortError
from moas_gui.serial import PortError, PortSettings, SerialPort, reads_by_thread
from moas_gui.serial.port import HUNG_UP, POLL_SEES_HANG_UPS, hung_up

pytestmark = pytest.mark.realtime

WAYS = pytest.mark.parametrize("use_thread", [False, True], ids=["watched", "thread"])


@dataclass
class Terminal:
    """A pseudo-terminal: the test works ``master``; ``path`` is the port to open."""

    master: int
    slave: int
    path: str
    open_fds: list[int] = field(default_factory=list)

    def read_master(self) -> bytes:
        return os.read(self.master, 4096)

    def pull_out(self) -> None:
        """The other end goes away (an adapter pulled, an emulator ended)."""
        os.close(self.master)
        os.close(self.slave)
        self.open_fds.clear()


@pytest.fixture
def terminal() -> Iterator[Terminal]:
    master, slave = pty.openpty()
    tty.setraw(slave)
    made = Terminal(master, slave, os.ttyname(slave), [master, slave])
    yield made
    for fd in made.open_fds:
        try:
            os.close(fd)
        except OSError:
            pass


@dataclass
class Heard:
    """What a port's callbacks were told."""

    data: bytearray = field(default_factory=bytearray)
    lost: list[str] = field(default_factory=list)

    def on_data(self, data: bytes) -> None:
        self.data += data

    def on_lost(self, why: str) -> None:
        self.lost.append(why)


def test_there_is_one_port_error() -> None:
    assert SwitchPortError is PortError and RotatorPortError is PortError
    assert issubclass(PortError, HardwareError) and issubclass(PortError, OSError)


@pytest.mark.asyncio
@WAYS
async def test_bytes_arrive_and_leave(terminal: Terminal, use_thread: bool) -> None:
    port = SerialPort(terminal.path, use_thread=use_thread)
    heard = Heard()
    port.open(heard.on_data, heard.on_lost)
    try:
        assert port.by_thread is use_thread
        os.write(terminal.master, b"hello ")
        os.write(terminal.master, b"box;")
        await until(lambda: bytes(heard.data) == b"hello box;", what="the bytes read")
        port.write(b"!1011;")
        assert terminal.read_master() == b"!1011;"
        assert heard.lost == []
    finally:
        port.close()


@pytest.mark.asyncio
@WAYS
async def test_a_pulled_port_is_told_once_and_refuses_writes(terminal: Terminal,
                                                             use_thread: bool) -> None:
    port = SerialPort(terminal.path, use_thread=use_thread)
    heard = Heard()
    port.open(heard.on_data, heard.on_lost)
    try:
        terminal.pull_out()
        await until(lambda: heard.lost, what="the port reported lost")
        await asyncio.sleep(0.3)  # a reader that went on would report again by now
        assert len(heard.lost) == 1, heard.lost
        if POLL_SEES_HANG_UPS:  # Linux: the same words whichever way the port is read
            assert heard.lost == [HUNG_UP]
        else:  # macOS: a run of empty reads, or the read's own error
            assert heard.lost[0] == HUNG_UP or heard.lost[0].startswith("reading failed: ")
        with pytest.raises(PortError, match="is not open"):
            port.write(b"?;")
    finally:
        port.close()


@pytest.mark.asyncio
@WAYS
async def test_nothing_is_told_after_close(terminal: Terminal, use_thread: bool) -> None:
    port = SerialPort(terminal.path, use_thread=use_thread)
    heard = Heard()
    port.open(heard.on_data, heard.on_lost)
    port.close()
    os.write(terminal.master, b"late;")
    terminal.pull_out()
    await asyncio.sleep(0.3)
    assert (bytes(heard.data), heard.lost) == (b"", [])
    assert not port.is_open
    with pytest.raises(PortError, match=f"{terminal.path} is not open"):
        port.write(b"?;")


@pytest.mark.asyncio
@WAYS
async def test_a_second_opener_is_refused_while_the_first_holds_the_port(
        terminal: Terminal, use_thread: bool) -> None:
    first = SerialPort(terminal.path, use_thread=use_thread)
    first.open(Heard().on_data, Heard().on_lost)
    try:
        for _ in range(2):  # refused each time, not only the first
            second = SerialPort(terminal.path, use_thread=use_thread)
            with pytest.raises(PortError, match="exclusively lock"):
                second.open(Heard().on_data, Heard().on_lost)
            assert not second.is_open
    finally:
        first.close()
    again = SerialPort(terminal.path, use_thread=use_thread)
    again.open(Heard().on_data, Heard().on_lost)  # free once the first closed it
    again.close()


@pytest.mark.asyncio
async def test_ports_opened_without_the_lock_can_be_shared(terminal: Terminal) -> None:
    shared = PortSettings(exclusive=False)
    first, second = SerialPort(terminal.path, shared), SerialPort(terminal.path, shared)
    first.open(Heard().on_data, Heard().on_lost)
    try:
        second.open(Heard().on_data, Heard().on_lost)
        second.close()
    finally:
        first.close()


@pytest.mark.asyncio
async def test_a_missing_port_is_a_port_error_saying_so() -> None:
    port = SerialPort("/dev/no-such-serial-port")
    with pytest.raises(PortError, match="No such file or directory"):
        port.open(Heard().on_data, Heard().on_lost)
    with pytest.raises(PortError, match="No such file or directory"):
        await port.open_off_loop(Heard().on_data, Heard().on_lost)


@pytest.mark.asyncio
@WAYS
async def test_opening_off_the_loop_reads_the_same(terminal: Terminal, use_thread: bool) -> None:
    port = SerialPort(terminal.path, use_thread=use_thread)
    heard = Heard()
    await port.open_off_loop(heard.on_data, heard.on_lost)
    try:
        os.write(terminal.master, b"AZ=123\r\n")
        await until(lambda: bytes(heard.data) == b"AZ=123\r\n", what="the answer read")
    finally:
        port.close()


@pytest.mark.asyncio
async def test_the_two_steps_of_an_open_refuse_early_and_read_later(terminal: Terminal) -> None:
    """The emulator's way: the port is refused (or taken) before the loop serves it."""
    port = SerialPort(terminal.path)
    port.open_device(asyncio.get_running_loop())
    heard = Heard()
    try:
        port.start(asyncio.get_running_loop(), heard.on_data, heard.on_lost)
        os.write(terminal.master, b"x")
        await until(lambda: bytes(heard.data) == b"x", what="the byte read")
    finally:
        port.close()
    with pytest.raises(PortError, match="is not open"):
        port.start(asyncio.get_running_loop(), heard.on_data, heard.on_lost)


@pytest.mark.asyncio
@WAYS
async def test_a_write_nobody_reads_fails_after_the_write_timeout(terminal: Terminal,
                                                                  use_thread: bool) -> None:
    """A box that stops reading: the terminal's buffer fills, and a write that cannot
    finish within ``write_timeout`` is a port error saying so."""
    port = SerialPort(terminal.path, PortSettings(write_timeout=0.05), use_thread=use_thread)
    port.open(Heard().on_data, Heard().on_lost)
    try:
        with pytest.raises(PortError, match=f"writing to {terminal.path} failed: Write timeout"):
            for _ in range(1000):
                port.write(b"!" * 4096)
    finally:
        port.close()


def test_a_termios_error_while_opening_is_a_port_error(monkeypatch: pytest.MonkeyPatch,
                                                       terminal: Terminal) -> None:
    """pyserial lets termios.error through from the flush of a port that just vanished."""
    import termios

    import serial  # type: ignore[import-untyped]

    def flush_fails(self: object) -> None:
        raise termios.error(5, "Input/output error")

    monkeypatch.setattr(serial.Serial, "reset_input_buffer", flush_fails)
    with pytest.raises(PortError, match="Input/output error"):
        SerialPort(terminal.path).open_device()


@pytest.mark.asyncio
async def test_the_loop_watches_a_device_and_a_thread_waits_on_a_url() -> None:
    loop = asyncio.get_running_loop()
    assert not reads_by_thread("/dev/ttyUSB0", loop)
    assert reads_by_thread("socket://127.0.0.1:4001", loop)


def test_a_hang_up_is_seen_where_poll_tells_and_a_live_port_never_is(terminal: Terminal) -> None:
    """Where ``poll()`` refuses devices (macOS) nothing is taken for a hang-up: the run of
    empty reads decides there."""
    assert not hung_up(terminal.slave)
    os.close(terminal.master)
    terminal.open_fds.remove(terminal.master)
    assert hung_up(terminal.slave) is POLL_SEES_HANG_UPS


@pytest.mark.asyncio
@pytest.mark.parametrize(("dtr", "rts"), [(False, None), (True, False), (None, True)])
async def test_the_dtr_and_rts_levels_asked_for_are_handed_to_the_port(
        terminal: Terminal, dtr: bool | None, rts: bool | None) -> None:
    """The levels are set on pyserial's port before it opens (a pseudo-terminal has no
    such lines and ignores them: the port still carries bytes both ways)."""
    port = SerialPort(terminal.path, PortSettings(dtr=dtr, rts=rts))
    heard = Heard()
    port.open(heard.on_data, heard.on_lost)
    try:
        handle = port._serial
        assert handle.dtr is (True if dtr is None else dtr)  # pyserial's default: raised
        assert handle.rts is (True if rts is None else rts)
        os.write(terminal.master, b"!;")
        await until(lambda: bytes(heard.data) == b"!;", what="the bytes read")
        port.write(b"';")
        assert terminal.read_master() == b"';"
    finally:
        port.close()


@pytest.mark.asyncio
async def test_a_port_with_line_levels_set_is_still_opened_for_one_program(
        terminal: Terminal) -> None:
    first = SerialPort(terminal.path, PortSettings(dtr=False))
    first.open(Heard().on_data, Heard().on_lost)
    try:
        with pytest.raises(PortError, match="lock"):
            SerialPort(terminal.path, PortSettings(dtr=False)).open(Heard().on_data,
                                                                     Heard().on_lost)
    finally:
        first.close()
