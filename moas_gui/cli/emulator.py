"""``moas-emulator``: a MOAS II switch with no hardware.

    moas-emulator                       a window, serving a new pseudo-terminal
    moas-emulator --headless            the same without a window
    moas-emulator --link ~/moas1        also make ~/moas1 a link to the port
    moas-emulator --port COM7           serve a serial port instead (Windows)
    moas-emulator --headless --control -            key stations from standard input
    moas-emulator --headless --control ~/moas1.ctl  ... or from a local socket

With ``--log-level info`` every change of the closed relays or of a key line
is logged (``relays 1 2 3 (active, keyed 1)``, ``relays none (inactive)``),
and every reset (``reset (*0;) received while station 1 was keyed``): a
script can watch what the box did across a server's restart.

``--control`` takes commands one line at a time, so stations can be keyed
without the window: ``key N`` and ``unkey N`` (station 1-6), ``relays``,
``status`` (one JSON line), ``record [N]`` (the box's record of every relay
change, key change and reset, each with every station's key state; one JSON
line each, then ``end M``), ``watch [N]`` (the same, then every new entry as
it comes) and ``help`` (details in :mod:`moas_gui.hw.moas2.emulator.control`).
``--control -`` reads standard input and answers on standard output (after
the lines below); ``--control PATH`` listens on a Unix socket at PATH (any
number of connections; ``socat - UNIX-CONNECT:PATH`` makes a terminal of
it); ``--control PORT`` (a number; the only kind on Windows) listens on that
TCP port of 127.0.0.1, 0 for any free one.

The first line printed is the port's path (flushed at once), so a script
can read it; a configuration can name the ``--link`` path instead, which
stays the same from one run to the next.  Then ``linked at PATH`` (with
``--link``) and ``control at WHERE`` (with ``--control``, once it listens).
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import sys
from collections.abc import Sequence
from pathlib import Path

from .. import __version__
from ..aio import CleanStop, run_until_stopped
from ..hw.moas2.emulator.box import EmulatedBox, Traffic
from ..hw.moas2.emulator.control import (
    Control,
    ControlServer,
    describe_relays,
    remove_control,
    serve_control,
    serve_stdin,
)
from ..hw.moas2.emulator.model import EmulatorModel
from ..hw.moas2.emulator.record import EntryCause
from ..hw.moas2.emulator.serve import (
    Endpoint,
    PtyEndpoint,
    SerialEndpoint,
    make_link,
    remove_link,
    serve,
)
from ..hw.moas2.errors import PortError
from ..places import output_without_console
from .options import HelpFormatter, add_log_level, log_level_number

log = logging.getLogger("moas_gui.cli.emulator")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="moas-emulator", formatter_class=HelpFormatter,
        description="Emulate a YCCC MOAS II switch on a pseudo-terminal or a serial port.",
    )
    p.add_argument("--headless", action="store_true", help="no window; stop with Ctrl-C")
    p.add_argument("--link", type=Path, metavar="PATH",
                   help="make PATH a symbolic link to the port (a stable name for a configuration)")
    p.add_argument("--port", metavar="NAME",
                   help="serve this serial port (e.g. COM7) instead of a new pseudo-terminal")
    p.add_argument("--unit-id", type=int, default=0, metavar="N",
                   help="the stored unit identifier, 0-99 (what the configuration's Echo checks)")
    p.add_argument("--firmware", default="100", metavar="VER",
                   help="three-character firmware version reported by ':' (default 100)")
    p.add_argument("--control", metavar="WHERE",
                   help="take commands (key N, unkey N, relays, status, record, watch, help)"
                        " from standard input ('-'), a Unix socket at this path, or this"
                        " TCP port on 127.0.0.1 (a number; 0: any free port)")
    add_log_level(p, "warning", "what goes to standard error")
    p.add_argument("--version", action="version", version=f"moas-emulator {__version__}")
    return p


def _open_endpoint(port: str | None) -> Endpoint:
    if port:
        return SerialEndpoint(port)
    if sys.platform == "win32":
        raise PortError("Windows has no pseudo-terminals: give --port with one end of a COM pair")
    return PtyEndpoint()


async def _run(args: argparse.Namespace, windowed: bool) -> int:
    loop = asyncio.get_running_loop()
    watched = args.log_level in ("info", "debug")
    box = (_WatchedBox if watched else EmulatedBox)(
        EmulatorModel(unit_id=args.unit_id, version=args.firmware))
    try:
        endpoint = _open_endpoint(args.port)
    except PortError as exc:
        print(f"moas-emulator: {exc}", file=sys.stderr)
        return 2
    serve(box, endpoint, loop)
    if watched:
        _log_relays(box)
    try:
        if args.link:
            make_link(endpoint.path, args.link)
    except (PortError, OSError) as exc:
        print(f"moas-emulator: cannot make the link {args.link}: {exc}", file=sys.stderr)
        endpoint.close()
        return 2
    control_server: ControlServer | None = None
    control_at = ""
    if args.control and args.control != "-":
        try:
            control_server, control_at = await serve_control(Control(box), args.control)
        except OSError as exc:
            print(f"moas-emulator: cannot listen for --control at {args.control}: {exc}",
                  file=sys.stderr)
            endpoint.close()
            if args.link:
                remove_link(args.link, endpoint.path)
            return 2
    stop = asyncio.Event()
    stopping = CleanStop(stop.set).install()
    window = None
    try:
        # Only now: whoever reads these lines may stop the emulator at once.
        print(endpoint.path, flush=True)
        if args.link:
            print(f"linked at {args.link}", flush=True)
        if args.control == "-":
            print("control at -", flush=True)
            serve_stdin(Control(box), loop)
        elif control_server is not None:
            print(f"control at {control_at}", flush=True)
        if windowed:
            from ..ui.emulator_window import EmulatorWindow

            window = EmulatorWindow(box, port=endpoint.path)
            window.closed.connect(stop.set)
            window.show()
        await stop.wait()
    finally:
        if window is not None:
            window.close()
        if control_server is not None:
            await control_server.close()
            remove_control(args.control)
        box.close()
        endpoint.close()
        if args.link:
            remove_link(args.link, endpoint.path)
        stopping.remove()
    return 0


class _WatchedBox(EmulatedBox):
    """A box that takes the computer's bytes one command at a time, so that the relay log
    shows every state the relays pass through (a reset and a reload written together
    open every relay for a moment on a real box, and show here as two lines)."""

    def receive(self, data: bytes) -> None:
        start = 0
        for end, byte in enumerate(data, 1):
            if byte == 0x3B:  # ';' ends a command
                super().receive(data[start:end])
                start = end
        if start < len(data):
            super().receive(data[start:])


def _log_relays(box: EmulatedBox) -> None:
    """Log the closed relays (whether the box is active, which stations are keyed)
    whenever they change, and every reset with the stations keyed at that moment."""
    shown: list[str] = []
    read = [box.model.record.written]

    def changed(kind: Traffic, data: bytes) -> None:
        if kind is not Traffic.CHANGED:
            return
        for entry in box.model.record.after(read[0]):
            read[0] = entry.seq
            if entry.event is EntryCause.RESET:
                keyed = " ".join(str(n) for n in sorted(entry.keyed))
                log.info("reset (%s) received%s", entry.cause,
                         f" while station {keyed} was keyed" if len(entry.keyed) == 1
                         else f" while stations {keyed} were keyed" if entry.keyed else "")
        view = box.view()
        line = describe_relays(view.relays, view.active,
                               frozenset(st.number for st in view.stations if st.key))
        if shown != [line]:
            shown[:] = [line]
            log.info("%s", line)

    box.add_listener(changed)


def main(argv: Sequence[str] | None = None) -> int:
    output_without_console("moas-emulator")  # started without a console: output to a log file
    args = _parser().parse_args(argv)
    if not 0 <= args.unit_id <= 99:
        print("moas-emulator: --unit-id must be 0-99", file=sys.stderr)
        return 2
    if len(args.firmware) != 3 or not args.firmware.isalnum():
        print("moas-emulator: --firmware must be three letters or digits", file=sys.stderr)
        return 2
    logging.basicConfig(
        level=log_level_number(args.log_level), stream=sys.stderr, format="%(levelname)s %(name)s: %(message)s"
    )
    if args.headless:
        return run_until_stopped(_run(args, windowed=False))
    from moas_gui.ui.display import display_problem

    problem = display_problem()
    if problem is not None:  # Qt would abort the process: say why instead
        print(f"moas-emulator: {problem}; run it without a window with --headless",
              file=sys.stderr)
        return 1
    from moas_gui.ui.qt import load_qasync

    qasync = load_qasync()
    from PySide6.QtWidgets import QApplication

    from moas_gui.ui.main_thread_gc import MainThreadCollector

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("MOAS II emulator")
    collector = MainThreadCollector(app)  # noqa: F841 (lives as long as the application)
    try:
        return int(qasync.run(_run(args, windowed=True)))
    except KeyboardInterrupt:
        return 0


if __name__ == "__main__":
    sys.exit(main())
