"""What runs while one configuration is open, and how each part starts and stops.

:class:`~moas_gui.app.ServerApp` decides *when* (open, restart, close) and owns
the one door into the engine; this module builds the parts it names: the
switch links, the frequency sources (N1MM Logger and the other loggers, the
rig daemons and OTRSP ports, N1MM's rotor window), the rotators and their
rotctld-compatible listeners, the client server and the browser client's web
server.  Each part that cannot
start (a port in use) is logged and left out; the others run.

What the sources told (each station's transmit and receive focus, the batch of
one loop turn) is not kept here but in the configuration's
:class:`~moas_gui.source_intake.SourceIntake`, the part that uses it.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable, Mapping, Sequence
from dataclasses import InitVar, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from moas_gui import state_store
from moas_gui.antenna_log.recorder import AntennaRecorder
from moas_gui.antenna_log.records import JournalReader
from moas_gui.config import Config
from moas_gui.config.model import Antenna, RadioRef, Rotator, RotatorControl
from moas_gui.edge.admission import DEFAULT_PER_ADDRESS
from moas_gui.engine import Engine
from moas_gui.engine.snapshot import export_selections
from moas_gui.engine.switchstate import SwitchState
from moas_gui.errors import HardwareError
from moas_gui.files import write_text_atomic
from moas_gui.hw.moas2.link import LinkOptions, LinkStatus, LinkTiming, SwitchLink
from moas_gui.hw.moas2.listener import SwitchListener
from moas_gui.hw.moas2.recording import SerialRecorder
from moas_gui.hw.moas2.transport import switch_port
from moas_gui.hw.rotators.base import (
    RotatorDriver,
    RotatorStatus,
    RotatorView,
    Timing,
    UnusableRotator,
)
from moas_gui.hw.rotators.electrical import SelectDirection
from moas_gui.hw.rotators.headings import Travel
from moas_gui.hw.rotators.manager import RotatorManager
from moas_gui.net.backend import ClientBackend
from moas_gui.net.log_events import ClientLogHandler
from moas_gui.net.secrets import SecretGuard
from moas_gui.net.server import DEFAULT_MAX_CLIENTS, ClientServer
from moas_gui.source_intake import Act, SourceIntake
from moas_gui.sources.base import SourceSink
from moas_gui.sources.server import RotatorHooks, ServerSources, SourceSettings
from moas_gui.sources.spec import SourceSpec
from moas_gui.state_store import SavedState, StateKeeper, switch_to_data

if TYPE_CHECKING:
    # loaded only when a station asks for them: the web server (aiohttp), the Antenna
    # Genius front (AGPort, --ag-port), the rotctld ports (a rotator's RotctldPort) and
    # the N1MM Logger listener (UseN1MMLogger)
    from moas_gui.net.antenna_genius.server import AgBackend, AgServer
    from moas_gui.net.rotctld_server import RotctldServer
    from moas_gui.net.web import WebServer
    from moas_gui.sources.n1mm import ContactCallback, N1MMListener

from moas_gui.net.access import allowed_networks, parse_allow_list
from moas_gui.net.identity import Identity, anonymous, as_operator
from moas_gui.operators import OperatorBook

log = logging.getLogger(__name__)

ROTCTLD_HOST = "127.0.0.1"
"""Where the rotctld-compatible listeners of rotators with a ``RotctldPort`` listen."""


@dataclass(frozen=True, slots=True)
class ServerOptions:
    """How this run differs from the configuration file (command line, tests)."""

    bind: str = "0.0.0.0"
    """Address the client server listens on."""
    tcp_port: int | None = None
    """Overrides the configuration's ``TCPPort`` (0 picks a free port)."""
    udp_port: int | None = None
    """Overrides ``UDPPort`` for N1MM Logger (0 picks a free port)."""
    udp_bind: str = "0.0.0.0"
    """Address the logger listeners (N1MM, DXLog.net, Win-Test, N1MM rotor) bind."""
    dxlog_port: int | None = None
    """Overrides ``DXLogPort``."""
    wintest_port: int | None = None
    """Overrides ``WinTestPort``."""
    n1mm_rotor_port: int | None = None
    """Overrides ``N1MMRotorPort``."""
    n1mm_rotor_headings: tuple[str, ...] | None = None
    """Overrides ``N1MMRotorHeadings`` (``host:port`` texts)."""
    sources: tuple[SourceSpec, ...] = ()
    """Rig sources (rigctld, flrig, OTRSP) run beside the configuration's (``--source``)."""
    flex: tuple[str, ...] = ()
    """FlexRadios read beside the configuration's ``FlexRadios`` (``--flex``)."""
    flex_radios: str = ""
    """``--flex-radios``: which slice of the ``--flex`` radios feeds which radio."""
    flex_discovery_port: int = 4992
    """Where FlexRadio discovery datagrams are listened for (a radio named by serial or
    nickname)."""
    web_port: int | None = None
    """Overrides ``WebPort``, the browser client's port (0 picks a free port)."""
    ag_port: int | None = None
    """Overrides ``AGPort``, the Antenna Genius API's first port (0 picks free ports)."""
    ag_radios: tuple[RadioRef, ...] | None = None
    """``--ag-radios``: the main radios served as AG ports, two per device (None: the
    first two)."""
    ag_discovery: tuple[str, int] | None = None
    """``--ag-discovery ADDR:PORT``: the AG discovery datagrams go there, not to the
    interfaces' broadcast addresses."""
    max_clients: int | None = None
    """Client connections served at once; None for the client server's default."""
    max_per_address: int | None = None
    """Connections one address may hold at once; None for the default."""
    require_token: bool = False
    """Clients from ``ClientAllow`` networks need an operator's token too (and the
    rotctld ports, which have no token, take only this computer and ``rotctld_allow``)."""
    rotctld_allow: tuple[str, ...] | None = None
    """``--rotctld-allow``: the addresses and networks the rotctld ports take besides
    this computer (None: with ``require_token`` none, without it whoever reaches them);
    given, the ports listen on ``bind`` rather than on 127.0.0.1 alone."""
    tls: bool = False
    """Serve the client port and the web page over TLS (docs/security.md)."""
    tls_cert: str | None = None
    """With ``tls_key``: the certificate to serve; None: the kept self-signed one."""
    tls_key: str | None = None
    start_rotator_program: bool | None = None
    """Overrides ``StartMOASRotator`` when not None."""
    use_rotator_program: bool = True
    """False (``--no-rotator-program``): no MOAS Rotator program at all, neither started
    nor connected to; the rotators that go through one are shown offline, saying why."""
    rotator_program_port: int = 13020
    rotator_ports: tuple[tuple[int, str], ...] = ()
    """``--rotator-port ID=DEVICE``: these rotators' controllers are on DEVICE instead of
    the file's ``CommPort`` (the file is left as it is; scripts/run-example.sh uses it
    for the emulated controllers)."""
    switch_timing: LinkTiming | None = None
    """Timing of the switch links (ping interval, timeouts); None for the real defaults."""
    rotator_timing: Timing | None = None
    """Delays and clock of the rotators (reconnects, restarts, a Test rotator's speed);
    None for the real defaults."""
    record_serial: str | None = None
    """``--record-serial FILE``: every switch session's calls and both directions' bytes
    are added to FILE (:mod:`moas_gui.hw.moas2.recording`)."""
    switch_dtr: bool | None = None
    """``--switch-dtr``: the switches' DTR line once their port is open (None: as the
    system's open leaves it, never pulsed)."""
    switch_rts: bool | None = None
    """``--switch-rts``: the switches' RTS line, as ``switch_dtr``."""
    antenna_log: bool = True
    """False (``--no-antenna-log``): no antenna journal is written (docs/antenna-log.md)."""
    antenna_log_clock: Callable[[], float] | None = None
    """The wall clock (POSIX seconds) the antenna log stamps its rows with; None for the
    system's (tests replay an hour on a clock of their own)."""
    relay_dwell: float | None = None
    """``--relay-dwell MS``, in seconds: automatic updates move a switch's relays at most
    once in this long (0: every update at once); None for the link's default (0.1 s)."""
    save_delay: float = state_store.SAVE_DELAY_S
    """How long after a state write the changes that follow wait, to be written together
    (:class:`~moas_gui.state_store.StateKeeper`); shorter only through the test hook
    ``MOAS_GUI_SAVE_DELAY``."""
    settle_garbage: bool = False
    """After each configuration opens, keep every object then alive out of later full
    collections (:func:`~moas_gui.opening.settle_garbage`, which collects first at a
    later opening): the ``moas-server`` process; not the tests, which open many
    configurations in one process."""


@dataclass
class Running:
    """The parts one configuration runs, from the moment it opens until it closes.

    :class:`~moas_gui.app.ServerApp` makes one per opened configuration and drops it
    on close (:func:`close_parts`); each part keeps its own state.  ``act`` is the app's
    one door into the engine, which the sources' intake is given.
    """

    config: Config
    engine: Engine
    act: InitVar[Act]
    intake: SourceIntake = field(init=False)
    """The sources' way into the engine, with each station's focus (source_intake.py):
    it decides through ``act`` and publishes radio entries with :meth:`publish_radio`."""
    links: dict[int, SwitchLink] = field(default_factory=dict)
    switch_status: dict[int, str] = field(default_factory=dict)
    clients: ClientServer | None = None
    web: WebServer | None = None
    n1mm: N1MMListener | None = None
    sources: ServerSources | None = None
    rotators: RotatorManager | None = None
    rotctld: list[RotctldServer] = field(default_factory=list)
    log_handler: logging.Handler | None = None
    serving: bool = False
    """Every part has started and the client and web ports listen: until then the
    title, status bar and tray do not say the configuration runs."""
    ticker: asyncio.TimerHandle | None = None
    """The status refresh's next run; :func:`close_parts` cancels it."""
    keeper: StateKeeper | None = None
    fingerprint: str = ""
    recorder: SerialRecorder | None = None
    """Where the switch sessions are recorded (``--record-serial``), or None."""
    antenna_log: AntennaRecorder | None = None
    """What feeds the antenna journal (None: no journal; docs/antenna-log.md)."""

    def __post_init__(self, act: Act) -> None:
        self.intake = SourceIntake(self.engine, act, self.publish_radio)

    @property
    def stopped(self) -> bool:
        """Stop Switches is in force: the engine's word (its wanted states are inactive
        then, and each switch session follows them), never a flag of its own here."""
        return not self.engine.running

    def publish_radio(self, station: int, radio: int) -> None:
        """A radio's entry (:meth:`SourceIntake.radio_entry`) to the clients, when any are
        connected (otherwise the entry is not even built)."""
        clients = self.clients
        if clients is not None and clients.client_count > 0:
            clients.publish_radio(self.intake.radio_entry(station, radio))

    def point_rotators(self) -> None:
        """An Electrical rotator points where its antenna in use points, however that
        antenna was chosen (a button, a band change, a turn)."""
        if self.rotators is not None:
            for rotator in self.config.rotators:
                if rotator.control is RotatorControl.ELECTRICAL:
                    heading = self.engine.electrical_heading(rotator.id)
                    if heading is not None:
                        self.rotators.note_direction(rotator.id, heading)

    def restore(self, path: Path, delay: float = state_store.SAVE_DELAY_S) -> SavedState | None:
        """Start keeping the state of this configuration (opened from ``path``, written
        at most every ``delay`` seconds); put the saved one, if usable, into its engine
        and its intake's focus."""
        self.fingerprint, saved = state_store.restore(path, self.engine)
        if self.fingerprint:
            self.keeper = StateKeeper(state_store.state_path(path), self.saved_state, delay)
        if saved is not None:
            self.intake.restore_focus(saved.focus)
        return saved

    def saved_state(self) -> SavedState:
        """What is saved: the engine's selections and each station's focus, what each box
        was last told, also while it is away (a restart during an outage must still
        check the box, not load it), and what it was last seen holding."""
        held = {i: s for i, link in self.links.items() if (s := link.holds) is not None}
        seen = {i: v for i, link in self.links.items() if (v := link.seen) is not None}
        return SavedState(self.fingerprint, export_selections(self.engine), held, seen,
                          self.intake.focus_items())


class _SwitchHeard(SwitchListener):
    """What one switch's link says, passed on to the server's callbacks with the
    switch's number; after an adoption, the engine's wanted state is what the link
    reconciles the box to."""

    def __init__(self, run: Running, switch_id: int,
                 on_status: Callable[[int, LinkStatus], None],
                 on_tr: Callable[[int, int, bool], None],
                 on_adopt: Callable[[int, Mapping[int, tuple[int, int, int]]], None],
                 on_seen: Callable[[int, int, tuple[int, int, int]], None] | None) -> None:
        self._run, self._id = run, switch_id
        self._on_status, self._on_tr, self._on_adopt, self._on_seen = (
            on_status, on_tr, on_adopt, on_seen)

    def status(self, status: LinkStatus) -> None:
        self._on_status(self._id, status)

    def transmitting(self, station: int, on: bool) -> None:
        self._on_tr(self._id, station, on)

    def adopt(self, stations: Mapping[int, tuple[int, int, int]],
              transmitting: frozenset[int]) -> SwitchState:
        # which of those stations were keyed (or may be) the server does not need here:
        # the box status the survey read gave their T/R letters to the engine first (its
        # transmitting calls come ahead of the adoption), and the link logged who was keyed
        self._on_adopt(self._id, stations)
        return self._run.engine.switch_states()[self._id]

    def seen(self, station: int, slots: tuple[int, int, int]) -> None:
        if self._on_seen is not None:
            self._on_seen(self._id, station, slots)


def start_switches(run: Running, options: ServerOptions, saved: SavedState,
                   on_status: Callable[[int, LinkStatus], None],
                   on_tr: Callable[[int, int, bool], None],
                   on_adopt: Callable[[int, Mapping[int, tuple[int, int, int]]], None],
                   on_seen: Callable[[int, int, tuple[int, int, int]], None] | None = None,
                   ) -> None:
    """A link per configured switch, told what the engine wants and connecting: each
    checks what its box holds against the saved state (``saved``) before it writes.
    ``on_seen(switch, port, slots)``: the antennas a box reports in use for a port
    changed (the antenna log records what the box confirmed, as it landed).
    ``on_adopt(switch, held)``: a survey found the box's antennas winning over the saved
    state for the ports of ``held`` (:class:`_SwitchHeard`)."""
    states = run.engine.switch_states()
    if options.record_serial is not None and run.recorder is None:
        run.recorder = open_recorder(options.record_serial)
    settings = switch_port(dtr=options.switch_dtr, rts=options.switch_rts)
    timing = options.switch_timing or LinkTiming()
    if options.relay_dwell is not None:
        timing = replace(timing, relay_dwell=options.relay_dwell)
    for switch in run.config.switches:
        run.switch_status[switch.id] = "connecting"
        link = SwitchLink(
            switch.id, switch.port, switch.echo,
            listener=_SwitchHeard(run, switch.id, on_status, on_tr, on_adopt, on_seen),
            options=LinkOptions(timing=timing, indicate_tr=switch.indicate_tr,
                                held=saved.switches.get(switch.id),
                                seen=saved.seen.get(switch.id), port_settings=settings),
            recorder=run.recorder,
        )
        run.links[switch.id] = link
        link.apply(states[switch.id])  # inactive while the engine says the switches stop
        link.connect()


async def start_sources(run: Running, options: ServerOptions, sink: SourceSink,
                        contacts: ContactCallback | None = None) -> None:
    """Every frequency source the configuration turns on, and N1MM's rotor window
    (after the rotators, whose manager it turns them with); see docs/sources.md."""
    settings = SourceSettings(
        udp_port=options.udp_port, udp_bind=options.udp_bind, dxlog_port=options.dxlog_port,
        wintest_port=options.wintest_port, n1mm_rotor_port=options.n1mm_rotor_port,
        n1mm_rotor_headings=options.n1mm_rotor_headings, sources=options.sources,
        flex=options.flex, flex_radios=options.flex_radios,
        flex_discovery_port=options.flex_discovery_port)
    hooks = None
    if run.rotators is not None:
        manager, rotators = run.rotators, run.config.rotators
        hooks = RotatorHooks(
            names=lambda: {r.id: (r.short_name, r.long_name) for r in rotators},
            turn=manager.start_rotate, stop=manager.start_stop,
            headings=lambda: [(r.id, manager.view(r.id).heading) for r in rotators])
    run.sources = ServerSources(run.config, sink, settings=settings, rotators=hooks,
                                contacts=contacts, bursts=run.intake)
    await run.sources.start()
    run.n1mm = run.sources.n1mm


class _WithoutRotatorProgram(RotatorManager):
    """Rotators with no MOAS Rotator program: those that go through one (``Serial``)
    are built offline, with the reason, so no connection is ever tried."""

    def _build(self, rotator: Rotator, travel: Travel,
               publish: Callable[[RotatorStatus], None], antennas: Sequence[Antenna],
               select: SelectDirection | None, moas_port: int | None) -> RotatorDriver:
        if rotator.control is RotatorControl.SERIAL:
            return _LeftOut(rotator, travel, publish, "it goes through the MOAS Rotator "
                            "program, which --no-rotator-program leaves out")
        return super()._build(rotator, travel, publish, antennas, select, moas_port)


class _LeftOut(UnusableRotator):
    """A rotator left out on purpose: offline, and a request says why; the one line
    :func:`start_rotators` logs for all of them is enough at start."""

    async def start(self) -> None:
        return None


async def start_rotators(run: Running, options: ServerOptions,
                         on_change: Callable[[RotatorView], None],
                         select_direction: Callable[[int, int], None]) -> None:
    """The rotators, then the rotctld-compatible listeners of those with a ``RotctldPort``."""
    if not run.config.rotators:
        return
    start = options.start_rotator_program
    manager = RotatorManager if options.use_rotator_program else _WithoutRotatorProgram
    if not options.use_rotator_program:
        start = False
        serial = [r.id for r in run.config.rotators if r.control is RotatorControl.SERIAL]
        if serial:
            log.info("No MOAS Rotator program (--no-rotator-program): rotator%s %s, which "
                     "go%s through one, stay offline", "s" if len(serial) > 1 else "",
                     ", ".join(str(i) for i in serial), "" if len(serial) > 1 else "es")
    config = run.config
    if options.rotator_ports:
        moved = dict(options.rotator_ports)
        unknown = sorted(set(moved) - {r.id for r in config.rotators})
        if unknown:
            log.warning("--rotator-port names rotator%s %s, which %s not in the file",
                        "s" if len(unknown) > 1 else "", ", ".join(map(str, unknown)),
                        "are" if len(unknown) > 1 else "is")
        config = replace(config, rotators=tuple(
            replace(r, comm_port=moved[r.id]) if r.id in moved else r
            for r in config.rotators))
    run.rotators = manager.from_config(
        config,
        on_change=on_change,
        select_direction=select_direction,
        start_moas_rotator=run.config.start_moas_rotator if start is None else start,
        moas_rotator_port=options.rotator_program_port,
        timing=options.rotator_timing,
    )
    await run.rotators.start()
    # rotators with a RotctldPort answer rotctld's protocol there (Hamlib's rotctl -m 2)
    await start_rotctld(run, run.rotators, options)


async def start_rotctld(run: Running, rotators: RotatorManager, options: ServerOptions) -> None:
    """The rotctld-compatible listeners of the rotators with a ``RotctldPort``, taking
    the peers ``--require-token`` and ``--rotctld-allow`` leave them."""
    networks = None if options.rotctld_allow is None else parse_allow_list(options.rotctld_allow)
    if all(rotator.rotctld_port is None for rotator in run.config.rotators):
        run.rotctld = []
        return
    from moas_gui.net.rotctld_server import rotctld_peers, start_rotctld_servers

    allows = rotctld_peers(options.require_token, networks)
    # this computer's programs only, unless other computers are listed: then where the
    # client port listens (--bind), taking this computer and those alone
    host = ROTCTLD_HOST if not options.rotctld_allow else options.bind
    run.rotctld = await start_rotctld_servers(rotators, run.config.rotators, host, allows)
    if run.rotctld and allows is not None:
        log.info("The rotctld ports take only this computer%s",
                 f" and {', '.join(options.rotctld_allow)} (--rotctld-allow)"
                 if options.rotctld_allow else " (--require-token: rotctld has no token)")


async def start_clients(run: Running, options: ServerOptions, backend: ClientBackend,
                        secrets: SecretGuard | None = None) -> None:
    """The client server (clients that asked for the log get it as events), then the
    browser client's web server on top of it when a web port is set."""
    port = options.tcp_port if options.tcp_port is not None else run.config.tcp_port
    most = options.max_clients
    each = options.max_per_address
    tls, seen = None, None
    if options.tls:
        from moas_gui.addresses import listen_addresses
        from moas_gui.tls import TLSError, ensure_certificate, fingerprint, server_context

        try:  # a self-signed one names the addresses listened on (made off the loop)
            certificate = await asyncio.to_thread(
                ensure_certificate, options.tls_cert, options.tls_key,
                listen_addresses(options.bind))
            tls = server_context(certificate)
            seen = fingerprint(certificate)
        except (TLSError, OSError) as exc:  # a certificate that cannot be used or made
            log.error("Clients cannot connect: TLS was asked for, but %s", exc)
            return
        log.info("TLS certificate %s, SHA-256 fingerprint %s", certificate.cert, seen)
    clients = ClientServer(backend, host=options.bind, port=port,
                           allow=run.config.client_allow,
                           max_clients=DEFAULT_MAX_CLIENTS if most is None else most,
                           per_address=DEFAULT_PER_ADDRESS if each is None else each,
                           require_token=options.require_token,
                           operators=secrets.book if secrets is not None else OperatorBook(),
                           tls=tls, secrets=secrets)
    clients.fingerprint = seen if tls is not None else None
    try:
        await clients.start()
    except HardwareError as exc:
        log.error("Clients cannot connect: %s", exc)
        return
    run.clients = clients
    # clients that said "log": true in hello get the product's log as events
    run.log_handler = ClientLogHandler(clients)
    logging.getLogger("moas_gui").addHandler(run.log_handler)
    clients.publish_state()
    web_port = options.web_port
    web_port = run.config.web_port if web_port is None else web_port
    if web_port is not None:  # the browser client: docs/web-client.md
        from moas_gui.net.web import start_web

        def journal() -> JournalReader | None:  # the page's /report reads the journal now
            return run.antenna_log.journal if run.antenna_log is not None else None

        run.web = await start_web(clients, options.bind, web_port, journal=journal)


async def close_parts(run: Running) -> None:
    """Close every listener, the rotators and the links; the relays stay as they are.
    The status refresh (``run.ticker``) is cancelled first, then the state is saved a
    last time."""
    if run.ticker is not None:
        run.ticker.cancel()
    if run.keeper is not None:
        try:
            await run.keeper.flush()
        except Exception:
            log.exception("while saving the state")
        run.keeper.close()
    if run.log_handler is not None:
        logging.getLogger("moas_gui").removeHandler(run.log_handler)
    parts: list[ServerSources | WebServer | ClientServer | RotctldServer | RotatorManager
                | None] = [run.sources, run.web, run.clients, *run.rotctld, run.rotators]
    for part in parts:
        if part is not None:
            try:
                await part.close()
            except Exception:
                log.exception("while closing %s", type(part).__name__)
    for link in run.links.values():
        try:
            await link.close()
        except Exception:
            log.exception("while closing switch link")
    if run.recorder is not None:
        run.recorder.close()


async def save_switch_data(run: Running, target: Path) -> None:
    """Every switch's status replies and tables, to ``target`` (never half a file)."""
    parts = []
    for switch_id, link in sorted(run.links.items()):
        part = target.with_name(f".{target.name}.switch{switch_id}")
        try:
            await link.save_data(part)
            parts.append(part.read_text(encoding="utf-8"))
        finally:
            part.unlink(missing_ok=True)
    write_text_atomic(target, "\n".join(parts))


class AntennaGenius:
    """The Antenna Genius front (``--ag-port`` / ``AGPort``, docs/antenna-genius.md): it
    outlives a configuration (its clients are told ``S0|antenna reload`` when the next
    one opens) and is closed with the server."""

    def __init__(self) -> None:
        self.server: AgServer | None = None

    @property
    def ports(self) -> list[int]:
        return [] if self.server is None else [d.port for d in self.server.devices]

    async def sync(self, options: ServerOptions, config: Config, backend: AgBackend,
                   name: str, allow: Callable[[], Sequence[str] | None],
                   guard: SecretGuard) -> None:
        """Serve the API for ``config`` (started, told of the new configuration, moved
        to another port, or closed when no port is set)."""
        port = options.ag_port if options.ag_port is not None else config.ag_port
        server = self.server
        if server is not None and (port is None or (port and port != server.port)):
            await self.close()
            server = None
        if port is None:
            return
        if server is not None:
            await server.reload(config)
            return
        from moas_gui.net.antenna_genius.access import SimpleAccess
        from moas_gui.net.antenna_genius.server import AgServer

        book = guard.book
        access = SimpleAccess(allow, require_token=options.require_token, guard=guard)

        def identify(host: str, address: str, named: str | None) -> Identity | None:
            # the book as last read (no file access on the loop): the check just read it
            operator = None if named is None or book is None else next(
                (op for op in book.cached() if op.name.lower() == named.lower()), None)
            if operator is not None:
                return as_operator(operator, address)
            return anonymous(host, address, allowed_networks(allow()), options.require_token)

        access.identify = identify
        server = AgServer(backend, options.bind, port, radios=options.ag_radios,
                          access=access, name=name,
                          discovery=options.ag_discovery)
        try:
            await server.start(config)
        except OSError as exc:
            log.error("Antenna Genius clients cannot connect: TCP port %d: %s (AGPort in "
                      "the configuration, or --ag-port, sets it)", port, exc.strerror or exc)
            return
        self.server = server

    def radios_changed(self, refs: set[tuple[int, int]]) -> None:
        if self.server is not None:
            self.server.radios_changed(refs)

    async def close(self) -> None:
        server, self.server = self.server, None
        if server is not None:
            await server.close()


def open_recorder(path: str) -> SerialRecorder | None:
    """The recording ``--record-serial`` asked for, or None (said once) when its file
    cannot be opened: the switches are driven all the same."""
    try:
        recorder = SerialRecorder(path, encode_state=switch_to_data)
    except OSError as exc:
        log.error("Cannot record the switch sessions to %s: %s; the switches run "
                  "unrecorded", path, exc.strerror or exc)
        return None
    log.info("Recording every switch session to %s", path)
    return recorder


__all__ = [
    "ROTCTLD_HOST",
    "AntennaGenius",
    "Running",
    "ServerOptions",
    "close_parts",
    "save_switch_data",
    "start_clients",
    "start_rotators",
    "start_sources",
    "start_switches",
]
