"""The program's one serial layer: every serial port it opens goes through here.

The switch link (:mod:`moas_gui.hw.moas2.transport`), the MOAS Rotator
program's controller ports (:mod:`moas_gui.rotator_program.serial_link`), the
emulator's end of a real serial port (:mod:`moas_gui.hw.moas2.emulator.serve`)
and a logger's OTRSP port (:mod:`moas_gui.sources.otrsp`) each hold a
:class:`SerialPort` with their own :class:`PortSettings`.  What differs between
systems is decided here, once:

* how bytes are waited for: the event loop watches the port's descriptor on
  Linux and macOS; a reader thread waits on Windows (a COM handle is no
  socket), for pyserial URLs, and for a loop that cannot watch a device
  (:func:`reads_by_thread`);
* how a pulled adapter or a closed pseudo-terminal is told from a wake-up with
  nothing to read (``poll()`` where it works on devices; macOS's refuses
  them, so there a run of empty reads decides);
* how a port is kept for one program alone (``exclusive``) and which of
  pyserial's errors (``termios.error`` too) mean "this port is gone".

Importing the package loads neither asyncio nor pyserial: :class:`PortError`
and :class:`PortSettings` are at hand for the codecs and the emulator, the port
itself (:mod:`.port`) is imported when first asked for.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .errors import PortError
from .settings import PortSettings

if TYPE_CHECKING:
    from .port import DataCallback, LostCallback, SerialPort, reads_by_thread

_FROM_PORT = frozenset({"DataCallback", "LostCallback", "SerialPort", "reads_by_thread"})


def __getattr__(name: str) -> object:
    if name in _FROM_PORT:
        from . import port

        return getattr(port, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "DataCallback",
    "LostCallback",
    "PortError",
    "PortSettings",
    "SerialPort",
    "reads_by_thread",
]
