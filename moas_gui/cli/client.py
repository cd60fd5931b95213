"""``moas-client [HOST[:PORT]]``: the button and compass client window on its own.

``moas-client --headless --source KIND[:OPTIONS] --station N [HOST[:PORT]]``
runs without a window on an operating computer: it reads that computer's
logger or rig through :mod:`moas_gui.sources` and tells the server
(docs/client.md, "Headless: the MOAS Client's job").

Connects to a moas-gui server (default ``127.0.0.1:12059``) and keeps trying
until it answers; closing the window ends the program.  ``--quit-after``
closes it by itself after some seconds (for tests and demonstrations); the
exit status is then 0 when the server was reached at least once, 3 when not.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import sys

from moas_gui import __version__
from moas_gui.aio import CleanStop, run_until_stopped
from moas_gui.cli.options import HelpFormatter
from moas_gui.client.address import DEFAULT_HOST, DEFAULT_PORT, parse_address
from moas_gui.places import output_without_console
from moas_gui.sources.spec import SourceSpec, parse_spec

EXIT_NEVER_CONNECTED = 3


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="moas-client", formatter_class=HelpFormatter,
        description="The MOAS button and compass client: antenna buttons and rotator "
                    "control for one radio, from any computer on the station's network.")
    parser.add_argument("address", nargs="?", default=None, metavar="HOST[:PORT]",
                        help=f"the server (default {DEFAULT_HOST}:{DEFAULT_PORT}); "
                             "IPv6 as [ADDRESS]:PORT")
    parser.add_argument("--station", type=int, help="station to show first")
    parser.add_argument("--radio", type=int, help="radio to show first")
    parser.add_argument("--rows", type=int, default=4, help="button rows (default 4)")
    parser.add_argument("--columns", type=int, default=3, help="button columns (default 3)")
    parser.add_argument("--name", default=f"moas-client {__version__}",
                        help="the name the server's log shows for this client")
    parser.add_argument("--headless", action="store_true",
                        help="no window: read this computer's logger or rig (--source) and "
                             "tell the server")
    parser.add_argument("--source", action="append", default=[], metavar="KIND[:OPTIONS]",
                        help="a logger or rig to read: rigctld, flrig, otrsp, n1mm, dxlog, "
                             "wintest (see docs/sources.md); may be given more than once")
    parser.add_argument("--tls", action="store_true",
                        help="connect over TLS (a server started with moas-server --tls)")
    parser.add_argument("--pin", metavar="SHA256",
                        help="with --tls: the server certificate's fingerprint (moas-server "
                             "--fingerprint prints it); kept for next time. Without it, the "
                             "first certificate seen is trusted, shown, and kept")
    parser.add_argument("--token", metavar="TOKEN",
                        help="an operator's token (moas-server --add-operator); kept in the "
                             "system keyring for this server, so it is given once")
    parser.add_argument("--quit-after", type=float, metavar="SECONDS",
                        help="close by itself after SECONDS (for tests)")
    parser.add_argument("-v", "--verbose", action="store_true", help="log to standard error")
    parser.add_argument("--version", action="version", version=f"moas-client {__version__}")
    return parser


def main(argv: list[str] | None = None) -> int:
    output_without_console("moas-client")  # started without a console: output to a log file
    parser = _parser()
    args = parser.parse_args(argv)
    try:
        host, port = parse_address(args.address)
    except ValueError as exc:
        parser.error(str(exc))
    for name in ("rows", "columns"):
        if not 1 <= getattr(args, name) <= 50:
            parser.error(f"--{name} must be between 1 and 50, not {getattr(args, name)}")
    if args.quit_after is not None and args.quit_after <= 0:
        parser.error(f"--quit-after must be more than 0 seconds, not {args.quit_after:g}")
    specs = []
    for text in args.source:
        try:
            specs.append(parse_spec(text))
        except ValueError as exc:
            parser.error(f"--source {text}: {exc}")
    if args.headless:
        if not specs:
            parser.error("--headless needs at least one --source")
        if args.station is None:
            parser.error("--headless needs --station: the station this computer operates")
    logging.basicConfig(level=logging.INFO if args.verbose or args.headless else logging.WARNING,
                        stream=sys.stderr, format="%(asctime)s %(levelname)s %(message)s")
    try:
        security = connection_security(host, port, args)
    except ValueError as exc:
        parser.error(str(exc))
    args.security = security
    if args.headless:
        return run_headless(host, port, args, specs)
    return run(host, port, args)


def connection_security(host: str, port: int, args: argparse.Namespace) -> dict[str, object]:
    """The token, TLS and pin a connection to ``host:port`` uses: from the command line,
    else from what was kept for that server (:mod:`moas_gui.client.keys`)."""
    from moas_gui.client.keys import ClientKeys

    keys = ClientKeys()
    server = f"{host}:{port}"
    if args.token:
        where = keys.set_token(server, args.token.strip())
        print(f"moas-client: the token for {server} is kept in {where}", file=sys.stderr)
    security: dict[str, object] = {"token": keys.token(server), "tls": bool(args.tls)}
    if not args.tls:
        if args.pin:
            raise ValueError("--pin goes with --tls")
        return security
    from moas_gui.tls import TLSError, normalize_pin

    if args.pin:
        try:
            pin = normalize_pin(args.pin)
        except TLSError as exc:
            raise ValueError(str(exc)) from None
        keys.set_pin(server, pin)
        security["pin"] = pin
        return security
    kept = keys.pin(server)
    if kept is not None:
        security["pin"] = kept
        return security

    def first_use(seen: str) -> bool:
        print(f"moas-client: {server} shows the certificate fingerprint {seen}; trusted on "
              "first use and kept (compare it with moas-server --fingerprint on the server)",
              file=sys.stderr)
        keys.set_pin(server, seen)
        return True

    security["trust"] = first_use
    return security


def run_headless(host: str, port: int, args: argparse.Namespace,
                 specs: list[SourceSpec]) -> int:
    """Reads the sources and tells the server until SIGINT / SIGTERM (or ``--quit-after``)."""
    from moas_gui.sources.headless import serve

    return run_until_stopped(serve(host, port, args.station, specs, name=args.name,
                                   quit_after=args.quit_after, security=args.security))


def run(host: str, port: int, args: argparse.Namespace) -> int:
    """Shows the window on a qasync loop until it is closed (or ``--quit-after``)."""
    from moas_gui.ui.display import display_problem

    problem = display_problem()
    if problem is not None:  # Qt would abort the process: say why instead
        print(f"moas-client: {problem}; on a computer without a screen, read a logger "
              "with moas-client --headless --station N --source KIND HOST", file=sys.stderr)
        return 1
    from moas_gui.ui.qt import load_qasync

    qasync = load_qasync()

    from moas_gui.client.connection import ClientConnection
    from moas_gui.client.keys import ClientKeys
    from moas_gui.ui.client_sources import ClientSources
    from moas_gui.ui.client_window import ClientWindow
    from moas_gui.ui.main_thread_gc import MainThreadCollector
    from moas_gui.ui.qt import QApplication, QSettings

    existing = QApplication.instance()
    qt_app = existing if isinstance(existing, QApplication) else QApplication([sys.argv[0]])
    # The window's own closed signal ends the program; Qt's quit would stop the loop early.
    qt_app.setQuitOnLastWindowClosed(False)
    if existing is None:
        qt_app.setOrganizationName("moas-gui")
        qt_app.setApplicationName("moas-client")
    collector = MainThreadCollector(qt_app)  # noqa: F841 (lives as long as the application)
    loop = qasync.QEventLoop(qt_app)
    asyncio.set_event_loop(loop)

    async def show() -> int:
        done = asyncio.Event()
        connection = ClientConnection(host, port, name=args.name, station=args.station,
                                      radio=args.radio, **args.security)
        window = ClientWindow(connection, station=args.station, radio=args.radio,
                              rows=args.rows, columns=args.columns, keys=ClientKeys())
        window.closed.connect(done.set)
        sources = ClientSources(window, QSettings())
        for text in args.source:
            sources.choose(text)
        window.start()
        window.show()
        if args.quit_after is not None:
            loop.call_later(args.quit_after, done.set)
        with CleanStop(done.set):  # SIGTERM, Ctrl+C, a closed console: as closing the window
            await done.wait()
            window.close()
            await sources.aclose()
            await window.aclose()
            window.deleteLater()
        if args.quit_after is not None and connection.connects == 0:
            print(f"moas-client: could not reach the server at {connection.address}",
                  file=sys.stderr)
            return EXIT_NEVER_CONNECTED
        return 0

    try:
        with loop:
            return int(loop.run_until_complete(show()))
    finally:
        asyncio.set_event_loop(None)


if __name__ == "__main__":
    sys.exit(main())
