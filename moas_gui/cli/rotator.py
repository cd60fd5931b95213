"""``moas-rotator``: the MOAS Rotator program, or a rotator controller emulator.

    moas-rotator [--bind ADDRESS] [--port N]      serve a MOAS Server on TCP (default 127.0.0.1:13020)
                 [--allow PATTERN]... [--take-over]
    moas-rotator --emulate MODEL [--link PATH]    play a controller on a new pseudo-terminal

The first line on standard output is what another program needs: the
address listened on (``listening on 127.0.0.1:13020``), or the emulator's
pseudo-terminal path.  Logging goes to standard error.  Both run until
interrupted (Ctrl+C, SIGTERM).
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import sys
from collections.abc import Callable
from typing import Any

from moas_gui import __version__
from moas_gui.aio import CleanStop, run_until_stopped
from moas_gui.cli.options import HelpFormatter, add_log_level, log_level_number
from moas_gui.hw.rotators.controllers.base import DEFAULT_SPEED, UnknownModel
from moas_gui.hw.rotators.controllers.models import find_model, known_models
from moas_gui.hw.rotators.moas_rotator_codec import PORT
from moas_gui.rotator_program.program import RotatorProgram

log = logging.getLogger("moas_gui.cli.rotator")


def _arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog="moas-rotator", formatter_class=HelpFormatter,
        description="The MOAS Rotator program: drives rotator controllers on serial ports "
                    "for a MOAS Server connecting on TCP.",
    )
    parser.add_argument("--bind", default="127.0.0.1", metavar="ADDRESS",
                        help="address to listen on (default 127.0.0.1: only a server on this "
                             "computer can connect; give this computer's address on the "
                             "station network, or 0.0.0.0 behind the station's firewall, for "
                             "a server on another computer)")
    parser.add_argument("--allow", action="append", default=[], metavar="PATTERN",
                        help="a port CONFIGURE may open besides serial devices, e.g. "
                             "socket://10.0.0.5:4001 (shell-style * and ? allowed); repeat "
                             "for more")
    parser.add_argument("--take-over", action="store_true",
                        help="let a server connecting from another address replace the one "
                             "in control (which is told); without it, it is refused")
    parser.add_argument("--port", type=int, default=PORT,
                        help=f"TCP port (default {PORT}; the MOAS Server always uses {PORT})")
    parser.add_argument("--emulate", metavar="MODEL",
                        help=f"emulate a controller instead ({known_models()})")
    parser.add_argument("--link", metavar="PATH",
                        help="with --emulate: also make PATH a link to the pseudo-terminal")
    parser.add_argument("--speed", type=float, default=DEFAULT_SPEED, metavar="DEG/S",
                        help=f"with --emulate: turning speed (default {DEFAULT_SPEED:g})")
    parser.add_argument("--azimuth", type=float, default=0.0, metavar="DEG",
                        help="with --emulate: heading at power-on (default 0)")
    add_log_level(parser, "info", "what goes to standard error")
    parser.add_argument("--version", action="version", version=f"moas-rotator {__version__}")
    return parser.parse_args(argv)


def _emulate(args: argparse.Namespace) -> int:
    try:
        from moas_gui.hw.rotators.controllers.pty_host import EmulatorHost
    except ImportError:
        print("moas-rotator: emulators need pseudo-terminals (Linux, macOS, BSD); on Windows "
              "use a virtual COM port pair and the emulator models from Python",
              file=sys.stderr)
        return 2
    try:
        model = find_model(args.emulate)
    except UnknownModel as error:
        print(f"moas-rotator: {error}", file=sys.stderr)
        return 2
    if args.speed <= 0:
        print("moas-rotator: --speed must be more than 0", file=sys.stderr)
        return 2
    return run_until_stopped(_emulate_until_stopped(args, model, EmulatorHost))


async def _emulate_until_stopped(args: argparse.Namespace, model: Any,
                                 host_class: Callable[[], Any]) -> int:
    stop = asyncio.Event()
    with CleanStop(stop.set), host_class() as host:
        try:
            port = host.add(model.make_emulator(args.azimuth, args.speed, host.clock()),
                            link=args.link)
        except OSError as error:
            print(f"moas-rotator: cannot make the pseudo-terminal: {error}", file=sys.stderr)
            return 1
        # said only once a SIGTERM would end it cleanly (and remove the link)
        print(port.path, flush=True)
        log.info("emulating %s (%s) on %s; stop with Ctrl+C", model.name,
                 model.info.description, port.path)
        await stop.wait()
    return 0


async def _serve(args: argparse.Namespace) -> int:
    program = RotatorProgram(allow=tuple(args.allow), take_over=args.take_over)
    try:
        host, port = await program.start(args.bind, args.port)
    except OSError as error:
        print(f"moas-rotator: cannot listen on {args.bind}:{args.port}: {error.strerror or error}"
              " (is another MOAS Rotator running?)", file=sys.stderr)
        return 2
    stop = asyncio.Event()
    with CleanStop(stop.set):
        # said only once a SIGTERM would end it cleanly: whoever starts it may stop it at once
        print(f"listening on {host}:{port}", flush=True)
        try:
            await stop.wait()
        finally:
            await program.close()
    log.info("stopped")
    return 0


def main(argv: list[str] | None = None) -> int:
    args = _arguments(argv)
    logging.basicConfig(level=log_level_number(args.log_level), stream=sys.stderr,
                        format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    if args.emulate:
        return _emulate(args)
    if args.link:
        print("moas-rotator: --link is only for --emulate", file=sys.stderr)
        return 2
    return run_until_stopped(_serve(args))


if __name__ == "__main__":
    sys.exit(main())
