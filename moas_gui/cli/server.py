"""``moas-server``: the MOAS II server.

``moas-server [FILE]`` opens the window (and FILE at once, which is what a
double-click does); ``--headless FILE`` runs the same server without a window;
``--check FILE`` explains every problem of a configuration and exits;
``--plan FILE`` prints the station plan (``--json``: as data) and exits.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import signal
import sys
from pathlib import Path

from moas_gui import __version__
from moas_gui.cli.options import add_log_level, log_level_number

log = logging.getLogger("moas_gui.server")
INSTANCE_NAME = "moas-server"


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="moas-server",
        description="The MOAS II antenna switch server. With FILE, opens that configuration.")
    parser.add_argument("file", nargs="?", help="a .moas configuration file")
    parser.add_argument("--check", action="store_true",
                        help="check FILE, print every problem (or a summary) and exit; "
                             "exit status 0 only when the file is usable")
    parser.add_argument("--plan", action="store_true",
                        help="print FILE's station plan: for every band and every pair of "
                             "radios, which antennas each radio gets and why, then the "
                             "findings; exit status 0 when the file is usable")
    parser.add_argument("--json", action="store_true",
                        help="with --plan: print the plan as JSON")
    parser.add_argument("--headless", action="store_true",
                        help="run without a window, logging to standard error")
    add_log_level(parser, "info", "what the headless server logs")
    parser.add_argument("--bind",
                        help="address the client server listens on (default all)")
    parser.add_argument("--tcp-port", type=int, help="client port instead of the file's TCPPort")
    parser.add_argument("--udp-port", type=int, help="N1MM Logger port instead of UDPPort")
    parser.add_argument("--web-port", type=int,
                        help="serve the browser client on this port (instead of WebPort)")
    parser.add_argument("--max-clients", type=_positive, default=None, metavar="N",
                        help="client connections served at once (default 200)")
    parser.add_argument("--udp-bind",
                        help="address the N1MM Logger listener binds (default all)")
    parser.add_argument("--dxlog-port", type=int, metavar="PORT",
                        help="DXLog.net port instead of DXLogPort (see docs/sources.md)")
    parser.add_argument("--wintest-port", type=int, metavar="PORT",
                        help="Win-Test broadcast port instead of WinTestPort")
    parser.add_argument("--n1mm-rotor-port", type=int, metavar="PORT",
                        help="port for N1MM's rotor commands instead of N1MMRotorPort")
    parser.add_argument("--n1mm-rotor-headings", action="append", metavar="HOST:PORT",
                        help="where N1MM's rotor window listens for headings, instead of "
                             "N1MMRotorHeadings (repeat for several)")
    parser.add_argument("--source", action="append", type=_source, metavar="KIND:OPTIONS",
                        help="also run this rig source beside the file's Rigctld, Flrig and "
                             "OTRSP entries: rigctld, flrig or otrsp naming its station, e.g. "
                             "rigctld:4532,station=1,radio=2 (repeat for several; see "
                             "docs/sources.md)")
    parser.add_argument("--no-rotator-program", action="store_true",
                        help="never start the local MOAS Rotator program")
    parser.add_argument("--new-instance", action="store_true",
                        help="do not hand FILE to a server that is already running")
    parser.add_argument("--install-desktop", action="store_true",
                        help="register .moas files and a menu entry for this user, and exit")
    parser.add_argument("--uninstall-desktop", action="store_true",
                        help="remove what --install-desktop registered, and exit")
    parser.add_argument("--version", action="version", version=f"moas-server {__version__}")
    # no options: only the test hooks set these (main)
    parser.set_defaults(switch_timing=None, rotator_timing=None)
    return parser


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not a number of clients (1 or more)")
    return value


def _source(text: str) -> object:
    from moas_gui.sources.spec import server_spec

    try:
        return server_spec(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _source_text(specs: list[object] | tuple[object, ...] | None) -> str | None:
    """The --source options as one text (None without any), to compare two launches."""
    return " ".join(spec.text() for spec in specs) if specs else None  # type: ignore[attr-defined]


def check(path: str) -> int:
    """Print the problems of ``path`` (or its summary); 0 when it is usable."""
    from moas_gui.config import load_config
    from moas_gui.config.summary import summarize

    result = load_config(path)
    for problem in result.problems:
        print(problem)
    if result.config is None:
        count = len(result.errors)
        print(f"{path}: {count} error{'s' if count != 1 else ''}; the configuration cannot be used.")
        return 1
    if result.warnings:
        print()
    print(summarize(result.config))
    from moas_gui.plan import plan_file

    plan, error = plan_file(path)
    if plan is None:
        print(error)
        return 1
    count = len(plan.findings)
    print()
    for finding in plan.findings:
        where = f"{path}:{finding.line}" if finding.line else path
        print(f"{where}: {finding.text}")
    print(f"{count} finding{'s' if count != 1 else ''}; the whole plan: "
          f"moas-server --plan {path}")
    return 0


def plan(path: str, as_json: bool) -> int:
    """Print the station plan of ``path``; 0 when the file is usable."""
    from moas_gui.plan import plan_file

    found, error = plan_file(path)
    if found is None:
        print(error, file=sys.stderr)
        return 1
    sys.stdout.write(found.to_json() if as_json else found.to_text())
    return 0


def _options(args: argparse.Namespace) -> object:
    from moas_gui.app import ServerOptions
    from moas_gui.hw.moas2.timing import ENVIRONMENT
    from moas_gui.hw.rotators.base import TIMING_HOOK

    if args.switch_timing is not None:
        log.info("Switch link clocks from %s (a test hook): %s", ENVIRONMENT, args.switch_timing)
    if args.rotator_timing is not None:
        log.info("Rotator delays from %s (a test hook): %s", TIMING_HOOK, args.rotator_timing)
    return ServerOptions(bind=args.bind or "0.0.0.0", tcp_port=args.tcp_port,
                         udp_port=args.udp_port, udp_bind=args.udp_bind or "0.0.0.0",
                         dxlog_port=args.dxlog_port, wintest_port=args.wintest_port,
                         n1mm_rotor_port=args.n1mm_rotor_port,
                         n1mm_rotor_headings=(None if args.n1mm_rotor_headings is None
                                              else tuple(args.n1mm_rotor_headings)),
                         web_port=args.web_port,
                         sources=tuple(args.source or ()),
                         max_clients=args.max_clients,
                         start_rotator_program=False if args.no_rotator_program else None,
                         switch_timing=args.switch_timing,
                         rotator_timing=args.rotator_timing)


def _become_instance(args: argparse.Namespace) -> tuple[object | None, int | None]:
    """Become the one running server, or hand FILE to the one that runs.

    Returns ``(instance, None)`` to go on serving (``instance`` is None with
    ``--new-instance``), or ``(None, exit status)`` when another server took over.
    """
    if args.new_instance:
        return None, None
    from moas_gui.single_instance import InstanceError, claim, offer

    try:
        instance = claim(INSTANCE_NAME)
    except InstanceError as exc:
        log.warning("Cannot check for another running moas-server: %s", exc)
        return None, None
    if instance is not None:
        return instance, None
    if args.file and not _usable(args.file):
        return None, 1
    target = str(Path(args.file).resolve()) if args.file else None
    answer = offer(INSTANCE_NAME, target, launch_request(args))
    if answer.taken:
        print(f"moas-server: {'handed ' + args.file + ' to' if args.file else 'showed'} "
              "the server that is already running", file=sys.stderr)
        return None, 0
    if answer.refusal is not None:
        print(f"moas-server: the moas-server that is already running refused: {answer.refusal}",
              file=sys.stderr)
        return None, 1
    if not answer.running:
        print("moas-server: the running moas-server ended while this one started; "
              "start it again", file=sys.stderr)
        return None, 1
    print("moas-server: another moas-server is running but does not answer; "
          "use --new-instance to start one anyway", file=sys.stderr)
    return None, 1


def launch_request(args: argparse.Namespace) -> dict[str, object]:
    """What this command line asks of a server, for the running one to vet."""
    launch: dict[str, object] = {"headless": bool(args.headless)}
    for key in ("bind", "tcp_port", "udp_port", "udp_bind", "dxlog_port", "wintest_port",
                "n1mm_rotor_port", "web_port"):
        value = getattr(args, key)
        if value is not None:
            launch[key] = value
    if args.source:
        launch["source"] = _source_text(args.source)
    return launch


def _usable(path: str) -> bool:
    """Whether ``path`` loads; when not, every problem goes to stderr (the running
    server is not disturbed)."""
    from moas_gui.config import load_config

    result = load_config(path)
    if result.config is not None:
        return True
    for problem in result.errors:
        print(problem, file=sys.stderr)
    count = len(result.errors)
    print(f"moas-server: {path} has {count} error{'s' if count != 1 else ''}; not handed to "
          "the server that is already running, which carries on untouched", file=sys.stderr)
    return False


def vet_launch(app: object, launch: dict[str, object], *, headless: bool) -> str | None:
    """Why the running server (``app``, headless or not) refuses a second launch, or None."""
    if headless:
        status = app.status  # type: ignore[attr-defined]
        return (f"it runs {status.file or 'a configuration'} headless and takes no hand-over; "
                "stop it first (or use --new-instance with other ports)")
    if launch.get("headless"):
        return ("it runs with a window; a --headless server cannot start beside it "
                "(stop it first, or use --new-instance with other ports)")
    options = app.options  # type: ignore[attr-defined]
    address = app.client_address  # type: ignore[attr-defined]
    running = {"bind": options.bind, "udp_bind": options.udp_bind,
               "tcp_port": options.tcp_port if options.tcp_port is not None
               else (address[1] if address else None),
               "udp_port": options.udp_port, "dxlog_port": options.dxlog_port,
               "wintest_port": options.wintest_port, "n1mm_rotor_port": options.n1mm_rotor_port,
               "web_port": options.web_port, "source": _source_text(options.sources)}
    for key, value in running.items():
        if key in launch and launch[key] != value:
            flag = "--" + key.replace("_", "-")
            shown = "the file's" if value is None else str(value)
            return (f"it runs with {flag} {shown}, this launch asked for {flag} {launch[key]}; "
                    "stop it first, or leave the option out to use the running server")
    return None


async def _serve_headless(args: argparse.Namespace, instance: object | None) -> int:
    from moas_gui.app import ServerApp

    app = ServerApp(_options(args))  # type: ignore[arg-type]
    result = await app.open(args.file)
    if result.config is None:
        return 1
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for number in (signal.SIGINT, signal.SIGTERM):
        try:
            loop.add_signal_handler(number, stop.set)
        except (NotImplementedError, RuntimeError):  # Windows
            signal.signal(number, lambda *_: loop.call_soon_threadsafe(stop.set))
    if instance is not None:
        await instance.start(  # type: ignore[attr-defined]
            lambda path: None, lambda path, launch: vet_launch(app, launch, headless=True))
    log.info("Serving %s; stop with Ctrl+C", args.file)
    await stop.wait()
    log.info("Stopping; the relays keep their state")
    await app.close()
    return 0


def run_headless(args: argparse.Namespace) -> int:
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)-7s %(message)s", "%H:%M:%S"))
    root = logging.getLogger("moas_gui")
    root.addHandler(handler)
    root.setLevel(log_level_number(args.log_level))
    instance, status = _become_instance(args)
    if status is not None:
        return status
    try:
        return asyncio.run(_serve_headless(args, instance))
    finally:
        if instance is not None:
            instance.close()  # type: ignore[attr-defined]


def run_window(args: argparse.Namespace) -> int:
    instance, status = _become_instance(args)
    if status is not None:
        return status
    try:
        return _run_window(args, instance)
    finally:
        if instance is not None:
            instance.close()  # type: ignore[attr-defined]


def _run_window(args: argparse.Namespace, instance: object | None) -> int:
    import qasync

    from moas_gui.app import ServerApp
    from moas_gui.ui.main_thread_gc import MainThreadCollector
    from moas_gui.ui.qt import QSettings
    from moas_gui.ui.server_window import ServerWindow, application_icon, ensure_application

    qt_app = ensure_application()
    qt_app.setWindowIcon(application_icon())
    collector = MainThreadCollector(qt_app)  # noqa: F841 (lives as long as the application)
    loop = qasync.QEventLoop(qt_app)
    asyncio.set_event_loop(loop)
    quit_event = asyncio.Event()

    async def serve() -> int:
        app = ServerApp(_options(args))  # type: ignore[arg-type]
        settings = QSettings()
        window = ServerWindow(app, settings, quit_event.set)
        window.show()
        _stop_on_signals(quit_event)
        if instance is not None:
            await instance.start(  # type: ignore[attr-defined]
                window.take_hand_over, lambda path, launch: vet_launch(app, launch, headless=False))
        from moas_gui.ui.control_hook import start_if_asked

        hook = await start_if_asked(window)
        if args.file:
            window.open_file(args.file)
        await quit_event.wait()
        if hook is not None:
            await hook.close()
        await window.idle()
        await app.close()
        window.shutdown()
        return 0

    with loop:
        return loop.run_until_complete(serve())


def _stop_on_signals(quit_event: asyncio.Event) -> None:
    """SIGINT and SIGTERM end the window server as Exit does (the relays stay as they are)."""
    loop = asyncio.get_running_loop()
    for number in (signal.SIGINT, signal.SIGTERM):
        try:
            loop.add_signal_handler(number, quit_event.set)
        except (NotImplementedError, RuntimeError):
            signal.signal(number, lambda *_: loop.call_soon_threadsafe(quit_event.set))


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    if args.install_desktop or args.uninstall_desktop:
        from moas_gui import desktop

        try:
            done = (desktop.install_desktop() if args.install_desktop
                    else desktop.uninstall_desktop())
        except OSError as exc:  # a full disk, a read-only home: every file is old or new
            what = "install" if args.install_desktop else "uninstall"
            print(f"moas-server: could not {what} the desktop integration: {exc}",
                  file=sys.stderr)
            return 1
        for line in done:
            print(line)
        return 0
    if args.json and not args.plan:
        print("moas-server: --json goes with --plan", file=sys.stderr)
        return 2
    if args.plan:
        if not args.file:
            print("moas-server: --plan needs a configuration file", file=sys.stderr)
            return 2
        return plan(args.file, args.json)
    if args.check:
        if not args.file:
            print("moas-server: --check needs a configuration file", file=sys.stderr)
            return 2
        return check(args.file)
    from moas_gui.hw.moas2.timing import timing_from_environment
    from moas_gui.hw.rotators.base import rotator_timing_from_environment

    try:  # tests' shorter clocks, if set
        args.switch_timing = timing_from_environment()
        args.rotator_timing = rotator_timing_from_environment()
    except ValueError as exc:
        print(f"moas-server: {exc}", file=sys.stderr)
        return 2
    from moas_gui.net.fd_limit import raise_open_file_limit

    raise_open_file_limit()  # each client holds a file handle
    if args.headless:
        if not args.file:
            print("moas-server: --headless needs a configuration file", file=sys.stderr)
            return 2
        return run_headless(args)
    return run_window(args)


if __name__ == "__main__":
    sys.exit(main())
