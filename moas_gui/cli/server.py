"""``moas-server``: the MOAS II server.

``moas-server [FILE]`` opens the window (and FILE at once, which is what a
double-click does); ``--headless FILE`` runs the same server without a window;
``--check FILE`` explains every problem of a configuration and exits;
``--plan FILE`` prints the station plan (``--json``: as data) and exits;
``--antenna-log FILE --adif OUT`` writes the antenna journal as ADIF and exits.
"""

from __future__ import annotations

import argparse
import ipaddress
import logging
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from moas_gui import __version__
from moas_gui.cli.antenna_log import add_arguments as add_antenna_log_arguments
from moas_gui.cli.antenna_log import export_antenna_log
from moas_gui.cli.antenna_log import wants_export as wants_antenna_log_export
from moas_gui.cli.builder import add_arguments as add_builder_arguments
from moas_gui.cli.builder import builder_command, wants_builder
from moas_gui.cli.options import HelpFormatter, add_log_level, log_level_number
from moas_gui.places import output_without_console

if TYPE_CHECKING:  # loaded only by the commands that serve (--check and --plan stay quick)
    from moas_gui.app import ServerOptions
    from moas_gui.single_instance import InstanceServer
    from moas_gui.sources.spec import SourceSpec
    from moas_gui.status import ServerStatus

log = logging.getLogger("moas_gui.cli.server")
INSTANCE_NAME = "moas-server"


class RunningServer(Protocol):
    """What :func:`vet_launch` reads of the server that runs (a ``ServerApp``)."""

    @property
    def status(self) -> ServerStatus: ...

    @property
    def options(self) -> ServerOptions: ...

    @property
    def client_address(self) -> tuple[str, int] | None: ...

    def end_operator(self, name: str) -> int: ...


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="moas-server", formatter_class=HelpFormatter,
        description="The MOAS II antenna switch server. With FILE, opens that configuration.")
    parser.add_argument("file", nargs="?", help="a .moas configuration file")
    parser.add_argument("--check", action="store_true",
                        help="check FILE, print every problem (or a summary) and exit; "
                             "exit status 0 only when the file is usable")
    parser.add_argument("--plan", action="store_true",
                        help="print FILE's station plan: on every band the antennas cover "
                             "(at its CW and phone frequencies), which antennas each radio "
                             "gets and why, what each pair of radios changes, then the "
                             "findings; exit status 0 when the file is usable")
    parser.add_argument("--json", action="store_true",
                        help="with --plan or --what-if: print as JSON")
    parser.add_argument("--plan-khz", metavar="KHZ[,KHZ...]", action="append",
                        help="with --plan: plan these frequencies (kHz, comma-separated) "
                             "instead of each covered band's CW and phone frequencies")
    parser.add_argument("--headless", action="store_true",
                        help="run without a window, logging to standard error")
    add_log_level(parser, "info", "what the headless server logs")
    parser.add_argument("--bind",
                        help="address the client server listens on (default all)")
    parser.add_argument("--tcp-port", type=int, help="client port instead of the file's TCPPort")
    parser.add_argument("--udp-port", type=int, help="N1MM Logger port instead of UDPPort")
    parser.add_argument("--web-port", type=int,
                        help="serve the browser client on this port (instead of WebPort)")
    parser.add_argument("--ag-port", type=int, metavar="PORT",
                        help="serve the 4O3A Antenna Genius API on this port (instead of "
                             "AGPort; further devices on the next ports, docs/antenna-genius.md)")
    parser.add_argument("--ag-radios", type=_ag_radios, metavar="S/R,S/R",
                        help="the main radios served as Antenna Genius ports, two per device "
                             "(default the first two, as 1/1,2/1)")
    parser.add_argument("--ag-discovery", type=_ag_discovery, metavar="ADDR:PORT",
                        help="send the Antenna Genius discovery datagrams to ADDR:PORT instead "
                             "of the interfaces' broadcast addresses")
    parser.add_argument("--max-clients", type=_positive, default=None, metavar="N",
                        help="client connections served at once, browser connections "
                             "included (default 200)")
    parser.add_argument("--max-per-address", type=_positive, default=None, metavar="N",
                        help="connections one address may hold at once, client and browser "
                             "together (default 32)")
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
    parser.add_argument("--flex", action="append", metavar="ADDR[:PORT]|SERIAL|NICKNAME",
                        help="follow this FlexRadio's slices beside the file's FlexRadios "
                             "(repeat for several; docs/sources.md)")
    parser.add_argument("--flex-radios", type=_flex_radios, metavar="A=S/R,B=S/R",
                        help="which slice of the --flex radios feeds which radio (default: "
                             "the transmitting slice radio 1/1, the other slice in use 1/2)")
    parser.add_argument("--flex-list", action="store_true",
                        help="list the FlexRadios heard on the network (their discovery "
                             "broadcasts) for a few seconds, and exit")
    parser.add_argument("--flex-discovery-port", type=int, default=4992, metavar="PORT",
                        help="UDP port of the FlexRadio discovery broadcasts (default 4992)")
    parser.add_argument("--no-rotator-program", action="store_true",
                        help="no MOAS Rotator program: neither start one nor connect to "
                             "one (the rotators that go through it stay offline)")
    parser.add_argument("--rotator-program-port", type=int, default=None, metavar="PORT",
                        help="the TCP port (on 127.0.0.1) of the MOAS Rotator program to "
                             "start or connect to (default 13020, the original's)")
    parser.add_argument("--rotator-port", action="append", type=_rotator_port,
                        metavar="ID=DEVICE",
                        help="rotator ID's controller is on DEVICE, not on the file's "
                             "CommPort (the file is not changed; repeat for several)")
    parser.add_argument("--no-antenna-log", action="store_true",
                        help="write no antenna log (the journal of antenna changes, key "
                             "events, headings and the loggers' contacts; "
                             "docs/antenna-log.md)")
    parser.add_argument("--new-instance", action="store_true",
                        help="do not hand FILE to a server that is already running")
    parser.add_argument("--install-desktop", action="store_true",
                        help="register .moas files and a menu entry for this user, and exit")
    parser.add_argument("--uninstall-desktop", action="store_true",
                        help="remove what --install-desktop registered, and exit")
    parser.add_argument("--install-service", action="store_true",
                        help="Linux: write a systemd user service that runs FILE headless "
                             "(with the other options given), print how to start it, and exit")
    parser.add_argument("--probe", metavar="PORT",
                        help="ask the MOAS II on serial port PORT only questions that move no "
                             "relay (ping, unit id, firmware, status, relays), print a report "
                             "and exit (docs/switch.md: first contact with a real box)")
    parser.add_argument("--record-serial", metavar="FILE",
                        help="add every switch session's bytes, both directions, with "
                             "times, to FILE (with --probe: that exchange)")
    parser.add_argument("--switch-dtr", type=_line_level, metavar="on|off",
                        help="set the switches' DTR line to this level before their port "
                             "opens (default: as the system's open leaves it, never pulsed)")
    parser.add_argument("--switch-rts", type=_line_level, metavar="on|off",
                        help="set the switches' RTS line likewise")
    parser.add_argument("--relay-dwell", type=_milliseconds, metavar="MS",
                        help="automatic updates (loggers' frequencies) move a switch's relays "
                             "at most once in MS milliseconds; the latest lands at its end "
                             "(default 100; 0 sends every update at once); presses are never "
                             "delayed")
    parser.add_argument("--require-token", action="store_true",
                        help="clients from the allowed networks (ClientAllow) need an "
                             "operator's token too (programs on this computer never do); "
                             "the rotctld ports, which have no token, then take only this "
                             "computer and --rotctld-allow's addresses")
    parser.add_argument("--rotctld-allow", type=_networks, metavar="ADDR[,NET...]",
                        help="the rotctld ports listen where the client port does "
                             "(--bind) and take only this computer and these addresses or "
                             "networks (e.g. 192.168.1.20,10.0.0.0/24); without it they "
                             "listen on 127.0.0.1, and take only this computer with "
                             "--require-token")
    parser.add_argument("--tls", action="store_true",
                        help="serve the client port and the web page over TLS (a self-signed "
                             "certificate kept in the configuration directory, unless "
                             "--tls-cert and --tls-key give one); clients from outside the "
                             "allowed networks are then admitted with a token")
    parser.add_argument("--tls-cert", metavar="FILE", help="the TLS certificate (PEM)")
    parser.add_argument("--tls-key", metavar="FILE", help="the TLS certificate's key (PEM)")
    parser.add_argument("--fingerprint", action="store_true",
                        help="print the SHA-256 fingerprint of the TLS certificate a server "
                             "with the same --bind serves (made or renewed now if need be) "
                             "and exit")
    parser.add_argument("--add-operator", metavar="NAME",
                        help="add an operator, print its token (shown once) and exit")
    parser.add_argument("--role", choices=("view", "operate", "admin"), default=None,
                        help="with --add-operator: what it may do")
    parser.add_argument("--radios", metavar="S/R,...",
                        help="with --add-operator: the radios it may act on, e.g. 1/1,1/2 "
                             "(default: all)")
    parser.add_argument("--ag-code", metavar="N",
                        help="with --add-operator: a number of 6-9 digits the operator's "
                             "Antenna Genius clients authenticate with (auth code=N) where "
                             "--require-token asks for one")
    parser.add_argument("--remove-operator", metavar="NAME",
                        help="remove an operator and exit; a running server ends its "
                             "sessions on every front (told at once, or noticing the "
                             "file's change within a second)")
    parser.add_argument("--list-operators", action="store_true",
                        help="list the operators and exit")
    add_antenna_log_arguments(parser)
    add_builder_arguments(parser)
    parser.add_argument("--version", action="version", version=f"moas-server {__version__}")
    # no options: only the test hooks set these (main)
    parser.set_defaults(switch_timing=None, rotator_timing=None, save_delay=None)
    return parser


def _networks(text: str) -> tuple[str, ...]:
    entries = tuple(part.strip() for part in text.split(",") if part.strip())
    for entry in entries:
        try:
            ipaddress.ip_network(entry, strict=False)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{entry!r} is not an address or network such as 192.168.1.0/24") from None
    if not entries:
        raise argparse.ArgumentTypeError("no address or network given")
    return entries


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not a number of connections (1 or more)")
    return value


def _milliseconds(text: str) -> float:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number of milliseconds") \
            from None
    if not 0 <= value <= 10000:
        raise argparse.ArgumentTypeError(f"{value} ms is not 0-10000 ms")
    return value / 1000


def _ag_radios(text: str) -> tuple[object, ...]:
    from moas_gui.net.antenna_genius.mapping import parse_radios

    try:
        return parse_radios(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _flex_radios(text: str) -> str:
    from moas_gui.config.rigs import parse_slice_map

    try:
        parse_slice_map(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def flex_list(args: argparse.Namespace, seconds: float = 3.0) -> int:
    """``--flex-list``: the FlexRadios heard within a few seconds; 0 when any was heard,
    1 when the port cannot be listened on, 3 when none was heard."""
    import asyncio

    from moas_gui.sources.flex_discovery import list_radios

    port = args.flex_discovery_port
    try:
        radios = asyncio.run(list_radios(seconds, port=port))
    except OSError as exc:
        print(f"moas-server: cannot listen for FlexRadios on UDP port {port}: {exc}",
              file=sys.stderr)
        return 1
    for radio in radios:
        print(f"{radio.model or 'FlexRadio'}\tnickname {radio.nickname or '-'}\t"
              f"serial {radio.serial or '-'}\t{radio.ip}:{radio.port}")
    if not radios:
        print(f"moas-server: no FlexRadio heard on UDP port {port} in {seconds:g} s "
              "(broadcasts do not cross routers or most VPNs: name such a radio by its "
              "address, --flex ADDR)", file=sys.stderr)
        return 3
    return 0


def _ag_discovery(text: str) -> tuple[str, int]:
    from moas_gui.net.antenna_genius.discovery import parse_target

    try:
        return parse_target(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _line_level(text: str) -> bool:
    levels = {"on": True, "off": False, "1": True, "0": False}
    if text.lower() not in levels:
        raise argparse.ArgumentTypeError(f"{text!r} is not on or off")
    return levels[text.lower()]


def probe(args: argparse.Namespace) -> int:
    """``--probe PORT``: print what the box on PORT answers; 0 when it answered, 1 when
    the port cannot be opened, 3 when nothing answered."""
    import asyncio

    from moas_gui.hw.moas2.probe import ProbeRefused
    from moas_gui.hw.moas2.probe import probe as ask_box
    from moas_gui.hw.moas2.recording import SerialRecorder

    recorder = SerialRecorder(args.record_serial) if args.record_serial else None
    try:
        report = asyncio.run(ask_box(args.probe, recorder=recorder,
                                     settings=_switch_lines(args)))
    except ProbeRefused as exc:
        print(f"moas-server: {exc}", file=sys.stderr)
        return 1
    finally:
        if recorder is not None:
            recorder.close()
    sys.stdout.write(report.text())
    return 0 if report.answered else 3


def _look_around(args: argparse.Namespace) -> int | None:
    """``--probe`` or ``--flex-list``: ask the hardware, print, and the exit status;
    None when neither was asked."""
    if args.probe:
        return probe(args)
    return flex_list(args) if args.flex_list else None


def _switch_lines(args: argparse.Namespace) -> tuple[bool | None, bool | None]:
    return args.switch_dtr, args.switch_rts


def _rotator_port(text: str) -> tuple[int, str]:
    ident, sep, device = text.partition("=")
    if not sep or not ident.strip().isdigit() or not device.strip():
        raise argparse.ArgumentTypeError(
            f"{text!r} is not ID=DEVICE (a rotator's ID and its controller's port, "
            "for example 2=/dev/ttyUSB1)")
    return int(ident), device.strip()


def _source(text: str) -> SourceSpec:
    from moas_gui.sources.spec import server_spec

    try:
        return server_spec(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _source_text(specs: Sequence[SourceSpec] | None) -> str | None:
    """The --source options as one text (None without any), to compare two launches."""
    return " ".join(spec.text() for spec in specs) if specs else None


CHECK_SECONDS = 1.2
"""How long ``--check`` gives the configuration and its findings together, in this
process's processor time (the work it does, whatever else the machine is doing)."""


def check(path: str) -> int:
    """Print the problems of ``path`` (or its summary); 0 when it is usable."""
    from moas_gui.config import load_config
    from moas_gui.config.summary import summarize

    started = time.process_time()
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
    from moas_gui.plan import PlanTooLong, deadline_after, plan_of

    # --check stays quick on any file: the findings get what is left of CHECK_SECONDS
    # (the whole plan of a huge station is for --plan, which takes its time)
    left = max(0.0, CHECK_SECONDS - (time.process_time() - started))
    try:
        plan, error = plan_of(result.config, Path(path), deadline_after(left))
    except PlanTooLong:
        print()
        print(f"findings: not counted (the station is too large to plan within "
              f"{CHECK_SECONDS:g} s of processor time); the whole plan and its findings: "
              f"moas-server --plan {path}")
        return 0
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


def plan(path: str, as_json: bool, khz: list[float] | None = None) -> int:
    """Print the station plan of ``path`` (at ``khz``, when given); 0 when the file is
    usable."""
    from moas_gui.plan import plan_file

    try:
        found, error = plan_file(path, khz)
    except ValueError as exc:  # a frequency in no band
        print(f"moas-server: --plan-khz: {exc}", file=sys.stderr)
        return 2
    if found is None:
        print(error, file=sys.stderr)
        return 1
    sys.stdout.write(found.to_json() if as_json else found.to_text())
    return 0


def _plan_command(args: argparse.Namespace) -> int:
    """``--plan`` with its options (``--json``, ``--plan-khz``): 2 for options that do not go
    together, else :func:`plan`'s status."""
    if not args.plan:
        what = "--json" if args.json else "--plan-khz"
        print(f"moas-server: {what} goes with --plan", file=sys.stderr)
        return 2
    if not args.file:
        print("moas-server: --plan needs a configuration file", file=sys.stderr)
        return 2
    khz, error = _plan_khz(args.plan_khz)
    if error:
        print(f"moas-server: --plan-khz: {error}", file=sys.stderr)
        return 2
    return plan(args.file, args.json, khz)


def _plan_khz(values: list[str] | None) -> tuple[list[float] | None, str]:
    """The frequencies of ``--plan-khz`` (None: not given), or why they are not frequencies."""
    if not values:
        return None, ""
    out = []
    for word in (w.strip() for v in values for w in v.split(",")):
        try:
            khz = float(word)
        except ValueError:
            return None, f"{word!r} is not a frequency in kHz (for example 14025,14250)"
        if not khz > 0:
            return None, f"{word!r} is not a frequency in kHz above 0"
        out.append(khz)
    return out, ""


def _options(args: argparse.Namespace) -> ServerOptions:
    from moas_gui.app import SAVE_DELAY_HOOK, ServerOptions
    from moas_gui.hw.moas2.timing import ENVIRONMENT
    from moas_gui.hw.rotators.base import TIMING_HOOK

    if args.switch_timing is not None:
        log.info("Switch link clocks from %s (a test hook): %s", ENVIRONMENT, args.switch_timing)
    if args.rotator_timing is not None:
        log.info("Rotator delays from %s (a test hook): %s", TIMING_HOOK, args.rotator_timing)
    if args.save_delay is not None:
        log.info("State saves at most every %g s, from %s (a test hook)", args.save_delay,
                 SAVE_DELAY_HOOK)
    return ServerOptions(bind=args.bind or "0.0.0.0", tcp_port=args.tcp_port,
                         udp_port=args.udp_port, udp_bind=args.udp_bind or "0.0.0.0",
                         dxlog_port=args.dxlog_port, wintest_port=args.wintest_port,
                         n1mm_rotor_port=args.n1mm_rotor_port,
                         n1mm_rotor_headings=(None if args.n1mm_rotor_headings is None
                                              else tuple(args.n1mm_rotor_headings)),
                         web_port=args.web_port,
                         ag_port=args.ag_port, ag_radios=args.ag_radios,
                         ag_discovery=args.ag_discovery,
                         sources=tuple(args.source or ()),
                         flex=tuple(args.flex or ()), flex_radios=args.flex_radios or "",
                         flex_discovery_port=args.flex_discovery_port,
                         max_clients=args.max_clients,
                         max_per_address=args.max_per_address,
                         require_token=args.require_token, tls=args.tls,
                         rotctld_allow=args.rotctld_allow,
                         tls_cert=args.tls_cert, tls_key=args.tls_key,
                         start_rotator_program=False if args.no_rotator_program else None,
                         use_rotator_program=not args.no_rotator_program,
                         rotator_ports=tuple(args.rotator_port or ()),
                         **({} if args.rotator_program_port is None
                            else {"rotator_program_port": args.rotator_program_port}),
                         switch_timing=args.switch_timing,
                         **({} if args.save_delay is None else {"save_delay": args.save_delay}),
                         antenna_log=not args.no_antenna_log,
                         record_serial=args.record_serial,
                         switch_dtr=args.switch_dtr, switch_rts=args.switch_rts,
                         relay_dwell=args.relay_dwell,
                         rotator_timing=args.rotator_timing, settle_garbage=True)


def _become_instance(args: argparse.Namespace) -> tuple[InstanceServer | None, int | None]:
    """Become the one running server, or hand FILE to the one that runs.

    Returns ``(instance, None)`` to go on serving (``instance`` is None with
    ``--new-instance``), or ``(None, exit status)`` when another server took over
    or this launch cannot go on; then the reason has been told (a message window
    too for a window launch, :func:`_refuse`).
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
    if args.file:
        status = _refuse_unusable(args)
        if status is not None:
            return None, status
    target = str(Path(args.file).resolve()) if args.file else None
    answer = offer(INSTANCE_NAME, target, launch_request(args))
    if answer.taken:
        print(f"moas-server: {'handed ' + args.file + ' to' if args.file else 'showed'} "
              "the server that is already running", file=sys.stderr)
        return None, 0
    if answer.refusal is not None:
        what = f"{Path(args.file).name} was not opened" if args.file else "no window opened"
        return None, _refuse(args, f"{what}: the moas-server that is already running "
                                   f"refused: {answer.refusal}", "")
    if not answer.running:
        return None, _refuse(args, "the running moas-server ended while this one started",
                             "start it again")
    return None, _refuse(args, "another moas-server is running but does not answer",
                         "end it (or wait for it), or use --new-instance to start one anyway")


def _refuse(args: argparse.Namespace, reason: str, advice: str, *, detail: str = "",
            status: int = 1, title: str = "", window_detail: str | None = None) -> int:
    """Tells why this launch cannot go on (stderr, and a message window for a window
    launch) and returns the exit status."""
    from moas_gui.ui.launch_message import tell_launch_refused

    tell_launch_refused("moas-server", reason, advice, detail=detail,
                        window=not args.headless, title=title, window_detail=window_detail)
    return status


def launch_request(args: argparse.Namespace) -> dict[str, object]:
    """What this command line asks of a server, for the running one to vet."""
    launch: dict[str, object] = {"headless": bool(args.headless)}
    for key in ("bind", "tcp_port", "udp_port", "udp_bind", "dxlog_port", "wintest_port",
                "n1mm_rotor_port", "web_port", "ag_port"):
        value = getattr(args, key)
        if value is not None:
            launch[key] = value
    if args.source:
        launch["source"] = _source_text(args.source)
    if args.flex:
        launch["flex"] = ",".join(args.flex)
    return launch


def _refuse_unusable(args: argparse.Namespace) -> int | None:
    """None when FILE loads; else every problem is told (the running server is not
    disturbed) and the exit status returned."""
    from moas_gui.config import load_config

    path = args.file
    result = load_config(path)
    if result.config is not None:
        return None
    count = len(result.errors)
    more = f"\n... and {count - 20} more" if count > 20 else ""
    # the terminal gets each problem as FILE:LINE:COLUMN; the window names the file once
    listed = "\n".join(str(p) for p in result.errors[:20]) + more
    shown = "\n".join((f"line {p.line}, column {p.column}: " if p.line else "") + p.message
                      for p in result.errors[:20]) + more
    return _refuse(args, f"{path} has {count} error{'s' if count != 1 else ''}, so it was not "
                         "opened: it was not handed to the moas-server that is already "
                         "running, which goes on untouched with what it runs",
                   "correct the file where the lines below say, then open it again",
                   detail=listed, window_detail=shown,
                   title=f"{Path(path).name} was not opened")


def vet_launch(app: RunningServer, launch: dict[str, object], *, headless: bool) -> str | None:
    """Why the running server (``app``, headless or not) refuses a second launch, or None."""
    if launch.get("command") == "remove_operator":
        return _end_operator(app, launch.get("name"))
    if headless:
        status = app.status
        return (f"it runs {status.file or 'a configuration'} headless and takes no hand-over; "
                "stop it first (or use --new-instance with other ports)")
    if launch.get("headless"):
        return ("it runs with a window; a --headless server cannot start beside it "
                "(stop it first, or use --new-instance with other ports)")
    options = app.options
    address = app.client_address
    running = {"bind": options.bind, "udp_bind": options.udp_bind,
               "tcp_port": options.tcp_port if options.tcp_port is not None
               else (address[1] if address else None),
               "udp_port": options.udp_port, "dxlog_port": options.dxlog_port,
               "wintest_port": options.wintest_port, "n1mm_rotor_port": options.n1mm_rotor_port,
               "web_port": options.web_port, "ag_port": options.ag_port,
               "source": _source_text(options.sources), "flex": ",".join(options.flex)}
    for key, value in running.items():
        if key in launch and launch[key] != value:
            flag = "--" + key.replace("_", "-")
            shown = "the file's" if value is None else str(value)
            return (f"it runs with {flag} {shown}, this launch asked for {flag} {launch[key]}; "
                    "stop it first, or leave the option out to use the running server")
    return None


def _end_operator(app: RunningServer, name: object) -> str:
    """``--remove-operator`` told the running server: its sessions end; says how many."""
    ended = app.end_operator(str(name))
    return f"{ended} session{'s' if ended != 1 else ''} of operator {name} ended"


async def _serve_headless(args: argparse.Namespace, instance: InstanceServer | None) -> int:
    import asyncio

    from moas_gui.aio import CleanStop
    from moas_gui.app import ServerApp
    from moas_gui.cli.builder_restart import (
        RESTART_COMMAND,
        STATION_COMMAND,
        restart_request,
        station_request,
    )

    app = ServerApp(_options(args))
    result = await app.open_or_last_good(args.file)
    if result.config is None:
        return 1
    stop = asyncio.Event()
    with CleanStop(stop.set):
        if instance is not None:
            await instance.start(
                lambda path: None, lambda path, launch: vet_launch(app, launch, headless=True),
                {RESTART_COMMAND: lambda launch: restart_request(
                    app, launch, lambda _path: app.restart(), other_files=False),
                 STATION_COMMAND: lambda launch: station_request(app, launch,
                                                                 other_files=False)})
        log.info("Serving %s; stop with Ctrl+C", args.file)
        await stop.wait()
        log.info("Stopping; the relays keep their state")
        await app.close()
    return 0


def run_headless(args: argparse.Namespace) -> int:
    from moas_gui.log_repeats import LineFormatter, fold_repeats, lean_records

    lean_records()
    handler = fold_repeats(logging.StreamHandler(sys.stderr))
    handler.setFormatter(LineFormatter())
    root = logging.getLogger("moas_gui")
    root.addHandler(handler)
    root.setLevel(log_level_number(args.log_level))
    # the web server's library logs too (malformed requests: once a minute per kind,
    # see moas_gui/net/web_limits.py), in the same form and at the same level
    web_library = logging.getLogger("aiohttp")
    web_library.addHandler(handler)
    web_library.setLevel(log_level_number(args.log_level))
    web_library.propagate = False
    instance, status = _become_instance(args)
    if status is not None:
        return status
    from moas_gui.aio import run_until_stopped

    try:
        status = _about_to_serve(args)
        return status if status is not None else run_until_stopped(
            _serve_headless(args, instance))
    finally:
        if instance is not None:
            instance.close()


def _about_to_serve(args: argparse.Namespace) -> int | None:
    """What only a launch that serves needs (one that hands its file to the server
    already running needs neither, nor the switch, rotator and network packages they
    live in): the tests' shorter clocks, if set, and the open-file limit raised.  None
    to go on serving, else the exit status (the reason said)."""
    from moas_gui.app import save_delay_from_environment
    from moas_gui.hw.moas2.timing import timing_from_environment
    from moas_gui.hw.rotators.base import rotator_timing_from_environment

    try:  # tests' shorter clocks, if set
        args.switch_timing = timing_from_environment()
        args.rotator_timing = rotator_timing_from_environment()
        args.save_delay = save_delay_from_environment()
    except ValueError as exc:
        print(f"moas-server: {exc}", file=sys.stderr)
        return 2
    from moas_gui.net.fd_limit import raise_open_file_limit

    raise_open_file_limit()  # each client holds a file handle
    return None


def run_window(args: argparse.Namespace) -> int:
    from moas_gui.ui.display import NO_DISPLAY_ADVICE, display_problem

    problem = display_problem()
    if problem is not None:  # Qt would abort the process: say why instead
        print(f"moas-server: {problem}; {NO_DISPLAY_ADVICE}", file=sys.stderr)
        return 1
    instance, status = _become_instance(args)
    if status is not None:
        return status
    try:
        status = _about_to_serve(args)
        return status if status is not None else _run_window(args, instance)
    finally:
        if instance is not None:
            instance.close()


def _run_window(args: argparse.Namespace, instance: InstanceServer | None) -> int:
    import asyncio

    from moas_gui.aio import CleanStop
    from moas_gui.cli.builder_restart import (
        RESTART_COMMAND,
        STATION_COMMAND,
        restart_request,
        station_request,
    )
    from moas_gui.ui.qt import load_qasync

    qasync = load_qasync()

    from moas_gui.app import ServerApp
    from moas_gui.ui.main_thread_gc import MainThreadCollector
    from moas_gui.ui.qt import QSettings
    from moas_gui.ui.server_window import ServerWindow, application_icon, ensure_application

    qt_app = ensure_application()
    qt_app.setWindowIcon(application_icon())
    from moas_gui.ui.file_open import FileOpenEvents

    opened = FileOpenEvents(qt_app)  # macOS: a double-clicked file comes as an event
    collector = MainThreadCollector(qt_app)  # noqa: F841 (lives as long as the application)
    loop = qasync.QEventLoop(qt_app)
    asyncio.set_event_loop(loop)
    quit_event = asyncio.Event()

    async def serve() -> int:
        app = ServerApp(_options(args))
        settings = QSettings()
        window = ServerWindow(app, settings, quit_event.set)
        window.show()
        # SIGINT, SIGTERM (and Ctrl+Break, a closed console) end it as Exit does
        with CleanStop(quit_event.set):
            if instance is not None:
                await instance.start(
                    window.take_hand_over,
                    lambda path, launch: vet_launch(app, launch, headless=False),
                    {RESTART_COMMAND: lambda launch: restart_request(app, launch,
                                                                     window.restart_file),
                     STATION_COMMAND: lambda launch: station_request(app, launch)})
            from moas_gui.ui.control_hook import start_if_asked

            hook = await start_if_asked(window)
            if args.file:
                window.open_file(args.file)
            opened.attach(window.take_hand_over)
            await quit_event.wait()
            if hook is not None:
                await hook.close()
            await window.idle()
            await app.close()
            window.shutdown()
            await window.idle()  # the client windows' connections end
        return 0

    with loop:
        status: int = loop.run_until_complete(serve())  # qasync is untyped
        return status


def _install_service(args: argparse.Namespace, arguments: list[str]) -> int:
    from moas_gui import service
    from moas_gui.desktop import server_command

    if not args.file:
        print("moas-server: --install-service needs a configuration file", file=sys.stderr)
        return 2
    if check(args.file) != 0:  # every problem shown; a broken file is never installed
        return 1
    command = service.service_command(server_command(), arguments, args.file)
    try:
        done = service.install_service(command)
    except OSError as exc:
        print(f"moas-server: could not install the service: {exc}", file=sys.stderr)
        return 1
    print()
    for line in done:
        print(line)
    return 0


def _security_command(args: argparse.Namespace) -> int | None:
    """The operator commands and ``--fingerprint``: their exit status, or None when the
    command line asks for neither."""
    if args.add_operator or args.remove_operator or args.list_operators:
        from moas_gui.cli.operators import operators_command

        return operators_command(args, INSTANCE_NAME)
    if not args.fingerprint:
        return None
    from moas_gui.addresses import listen_addresses
    from moas_gui.tls import TLSError, ensure_certificate, fingerprint

    try:  # the certificate a server with the same --bind serves (renewed for it if need be)
        addresses = listen_addresses(args.bind or "0.0.0.0")
        print(fingerprint(ensure_certificate(args.tls_cert, args.tls_key, addresses)))
    except (TLSError, OSError) as exc:
        print(f"moas-server: {exc}", file=sys.stderr)
        return 1
    return 0


def _early_command(args: argparse.Namespace) -> int | None:
    """The station builder (``--edit``, ``--what-if``), the operator commands and
    ``--fingerprint``: their exit status, or None when the command line asks for none."""
    if wants_builder(args):
        return builder_command(args)
    return _security_command(args)


def main(argv: list[str] | None = None) -> int:
    output_without_console("moas-server")  # started without a console: output to a log file
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
    early = _early_command(args)
    if early is not None:
        return early
    if wants_antenna_log_export(args):
        return export_antenna_log(args)
    if args.install_service:
        return _install_service(args, sys.argv[1:] if argv is None else list(argv))
    looked = _look_around(args)
    if looked is not None:
        return looked
    if args.plan or args.json or args.plan_khz:
        return _plan_command(args)
    if args.check:
        if not args.file:
            print("moas-server: --check needs a configuration file", file=sys.stderr)
            return 2
        return check(args.file)
    if args.headless:
        if not args.file:
            print("moas-server: --headless needs a configuration file", file=sys.stderr)
            return 2
        return run_headless(args)
    return run_window(args)


if __name__ == "__main__":
    sys.exit(main())
