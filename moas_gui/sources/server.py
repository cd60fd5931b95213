"""The sources the server runs itself, from its configuration, in one place.

:class:`ServerSources` starts every listener the configuration turns on:
N1MM Logger+ (``UseN1MMLogger``, ``UDPPort``), DXLog.net (``UseDXLog``,
``DXLogPort``; the N1MM listener serves it when both share a port), Win-Test
(``UseWinTest``, ``WinTestPort``, ``WinTest``) and N1MM's rotor window
(``UseN1MMRotor``, ``N1MMRotorPort``, ``N1MMRotorHeadings``), and the rig
sources: each ``Rigctld`` and ``Flrig`` entry's polled daemon, each ``OTRSP``
entry's serial port, and those ``moas-server --source`` adds; and each
FlexRadio of ``FlexRadios`` and ``moas-server --flex``.  Every event
goes through one :class:`~moas_gui.sources.base.SourceHub` (newest wins,
overlaps logged once) to the one sink the app gives.  A port that cannot be
opened is logged and that source left out; the others run.  A rig daemon or
OTRSP port that is not there yet is waited for quietly (docs/sources.md).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeVar

from moas_gui.config.model import Config
from moas_gui.sources.base import DEFAULT_RETRY, Bursts, SourceHub, SourceSink
from moas_gui.sources.polling import PolledRig
from moas_gui.sources.spec import SourceSpec, config_specs, make_source
from moas_gui.sources.udp import DatagramSource

if TYPE_CHECKING:
    # The listeners a configuration may leave off (N1MM Logger, DXLog.net, Win-Test,
    # N1MM's rotor window, FlexRadios, OTRSP ports) are loaded when it turns them on: a station
    # without them starts without their codecs.
    from moas_gui.sources.dxlog import DXLogListener
    from moas_gui.sources.flex import FlexSource
    from moas_gui.sources.flex_api import RadioRef, SliceMap
    from moas_gui.sources.n1mm import ContactCallback, N1MMListener
    from moas_gui.sources.n1mm_rotor import N1MMRotorServer
    from moas_gui.sources.otrsp import OtrspSource
    from moas_gui.sources.wintest import WinTestListener

log = logging.getLogger(__name__)

_D = TypeVar("_D", bound=DatagramSource)


@dataclass(frozen=True, slots=True)
class SourceSettings:
    """What the command line changes of the configuration's source keys (None: the file's)."""

    udp_port: int | None = None
    udp_bind: str = "0.0.0.0"
    dxlog_port: int | None = None
    wintest_port: int | None = None
    n1mm_rotor_port: int | None = None
    n1mm_rotor_headings: tuple[str, ...] | None = None
    sources: tuple[SourceSpec, ...] = ()
    """Rig sources run beside the configuration's (``--source``; each names its station)."""
    flex: tuple[str, ...] = ()
    """FlexRadios read beside the configuration's (``--flex``: address, serial or nickname)."""
    flex_radios: str = ""
    """``--flex-radios A=1/1,B=1/2`` for the ``--flex`` radios; empty: by transmit."""
    flex_discovery_port: int = 4992
    """Where a FlexRadio named by serial or nickname is listened for (FlexRadio's API port,
    ``flex_api.API_PORT``, written out so that a station without FlexRadios does not load
    the API)."""


@dataclass(frozen=True, slots=True)
class RotatorHooks:
    """How N1MM's rotor window reaches the server's rotator manager."""

    names: Callable[[], dict[int, tuple[str, ...]]]
    """Each rotator's id and the names N1MM may use for it."""
    turn: Callable[[int, float], object]
    stop: Callable[[int], object]
    headings: Callable[[], Iterable[tuple[int, float | None]]]


class ServerSources:
    """Every source the server runs; :meth:`start` once, :meth:`close` once."""

    def __init__(
        self,
        config: Config,
        sink: SourceSink,
        *,
        settings: SourceSettings | None = None,
        rotators: RotatorHooks | None = None,
        contacts: ContactCallback | None = None,
        bursts: Bursts | None = None,
    ) -> None:
        self._config = config
        self._settings = settings or SourceSettings()
        self.hub = SourceHub(sink)
        self._bursts = bursts
        """Told around each burst of every UDP listener (the loggers'), so the sink's owner
        decides a burst in the turn that read it (:class:`~.base.Bursts`)."""
        self._rotators = rotators
        self._contacts = contacts
        """Where the N1MM listener hands the loggers' contact packets (the antenna log)."""
        self.n1mm: N1MMListener | None = None
        self.dxlog: DXLogListener | None = None
        self.wintest: WinTestListener | None = None
        self.rotor: N1MMRotorServer | None = None
        self.polled: list[PolledRig] = []
        """The rig daemons polled (``Rigctld``, ``Flrig``, ``--source``), in order."""
        self.otrsp: list[OtrspSource] = []
        """The OTRSP ports read, in order."""
        self.flex: list[FlexSource] = []
        """The FlexRadios read (``FlexRadios``, ``--flex``), in order."""

    async def start(self) -> None:
        c, s = self._config, self._settings
        host = s.udp_bind
        n1mm_port = c.udp_port if s.udp_port is None else s.udp_port
        dxlog_port = c.dxlog_port if s.dxlog_port is None else s.dxlog_port
        if c.use_n1mm_logger:
            from moas_gui.sources.n1mm import N1MMListener

            self.n1mm = await self._bind(
                N1MMListener(c.n1mm_logger, on_event=self.hub, on_contact=self._contacts,
                             port=n1mm_port, host=host),
                "N1MM Logger packets", n1mm_port)
        if c.use_dxlog and not (self.n1mm is not None and dxlog_port == n1mm_port):
            from moas_gui.sources.dxlog import DXLogListener

            self.dxlog = await self._bind(
                DXLogListener(c.n1mm_logger, on_event=self.hub, port=dxlog_port, host=host),
                "DXLog.net packets", dxlog_port)
        if c.use_wintest:
            from moas_gui.sources.wintest import WinTestListener

            port = c.wintest_port if s.wintest_port is None else s.wintest_port
            table = {w.station_name: (w.station, w.radio) for w in c.wintest}
            self.wintest = await self._bind(
                WinTestListener(table, self.hub, port=port, host=host),
                "Win-Test broadcasts", port)
        if c.use_n1mm_rotor and self._rotators is not None:
            await self._start_rotor(host)
        await self._start_rigs()
        await self._start_flex()

    async def _start_rigs(self) -> None:
        """The configuration's rig daemons and OTRSP ports, then the command line's."""
        given = [spec for spec in self._settings.sources if self._fits(spec)]
        for spec in config_specs(self._config) + given:
            source = make_source(spec, 0, self.hub)
            await source.start()  # polls or opens in its own task: never fails here
            if isinstance(source, PolledRig):
                self.polled.append(source)
                log.info("Polling %s for station %d radio %d, %g times a second",
                         source.origin, source.station, source.radio, 1.0 / source.interval)
            elif spec.kind == "otrsp":  # make_source loaded the OTRSP source for it
                from moas_gui.sources.otrsp import OtrspSource

                assert isinstance(source, OtrspSource)
                self.otrsp.append(source)
                log.info("Reading OTRSP on %s for station %d", source.port,
                         source.mapping.station)

    async def _start_flex(self) -> None:
        """The configuration's FlexRadios, then the command line's."""
        c, s = self._config, self._settings
        wanted = [(e.address, e.station, e.slices, e.retry) for e in c.flex_radios if e.enabled]
        wanted += [(target, 1, s.flex_radios, DEFAULT_RETRY) for target in s.flex]
        if not wanted:
            return
        from moas_gui.sources.flex import FlexSource

        for address, station, slices, retry in wanted:
            mapping = self._flex_map(address, station, slices)
            if mapping is None:
                continue
            source = FlexSource(address, mapping, self.hub, retry=retry,
                                discovery_port=s.flex_discovery_port)
            await source.start()  # connects in its own task: never fails here
            self.flex.append(source)
            log.info("Following FlexRadio %s: %s", address, _map_text(mapping))

    def _flex_map(self, address: str, station: int, slices: str) -> SliceMap | None:
        """The slice map of one FlexRadio, or None (said) when it names radios the
        configuration lacks."""
        from moas_gui.sources.flex_api import SliceMap, parse_slice_map

        c = self._config
        if slices.strip():
            try:
                table = parse_slice_map(slices)
            except ValueError as exc:
                log.error("FlexRadio %s is left out: %s", address, exc)
                return None
            missing = sorted(ref for ref in set(table.values()) if c.radio(*ref) is None)
            mapping = SliceMap(by_letter=table)
        else:
            first, second = (station, 1), (station, 2)
            missing = [first] if c.radio(*first) is None else []
            mapping = SliceMap(first, second if c.radio(*second) is not None else None)
        if missing:
            log.error("FlexRadio %s is left out: %s not in the configuration", address,
                      ", ".join(f"station {s} radio {r}" for s, r in missing))
            return None
        return mapping

    def describe_flex(self) -> list[str]:
        """Each FlexRadio and the radios it feeds, in words (offline, slice, antennas)."""
        return [line for source in self.flex for line in source.describe()]

    def _fits(self, spec: SourceSpec) -> bool:
        """Whether a command-line source names radios and antennas the configuration has
        (the configuration's own entries were checked when it was read)."""
        c, o = self._config, spec.options
        station = int(o.get("station", "0"))
        names = [o.get("radio", "1")] if spec.kind != "otrsp" else \
            [o[k] for k in ("radio1", "radio2") if k in o]
        wrong = [f"station {station} radio {r}" for r in names if c.radio(station, int(r)) is None]
        if not any(r.station == station for r in c.radios):
            wrong = [f"station {station}"]
        wrong += [f"antenna {a}" for a in sorted(set(spec.antennas.values()))
                  if c.antenna(a) is None]
        if wrong:
            log.error("--source %s is left out: %s %s not in the configuration", spec.text(),
                      ", ".join(wrong), "is" if len(wrong) == 1 else "are")
        return not wrong

    async def _start_rotor(self, host: str) -> None:
        from moas_gui.sources.n1mm_rotor import N1MMRotorServer, parse_destination

        c, s, hooks = self._config, self._settings, self._rotators
        assert hooks is not None
        port = c.n1mm_rotor_port if s.n1mm_rotor_port is None else s.n1mm_rotor_port
        texts = c.n1mm_rotor_headings if s.n1mm_rotor_headings is None else s.n1mm_rotor_headings
        destinations = []
        for text in texts:
            try:
                destinations.append(parse_destination(text))
            except ValueError as exc:
                log.error("N1MM rotor window: %s; no headings go there", exc)
        self.rotor = await self._bind(
            N1MMRotorServer(hooks.names(), turn=hooks.turn, stop=hooks.stop,
                            headings=hooks.headings, destinations=destinations, port=port,
                            host=host),
            "N1MM rotor commands", port)

    async def _bind(self, source: _D, what: str, port: int) -> _D | None:
        source.bursts = self._bursts
        try:
            await source.start()
        except OSError as exc:
            log.error("%s cannot be received: UDP port %d cannot be opened (%s)", what, port,
                      exc.strerror or exc)
            return None
        return source

    def rotator_heading(self, rotator_id: int, heading: float | None) -> None:
        """A rotator's heading changed: N1MM's rotor window hears it at once."""
        if self.rotor is not None:
            self.rotor.heading_changed(rotator_id, heading)

    def forget(self) -> None:
        """Make the next report of every radio count as a change (the engine restarted)."""
        for listener in (self.n1mm, self.dxlog, self.wintest):
            if listener is not None:
                listener.forget()
        for rig in self.polled:
            rig.forget()
        for port in self.otrsp:
            port.forget()
        for radio in self.flex:
            radio.forget()

    async def close(self) -> None:
        for part in (self.n1mm, self.dxlog, self.wintest, self.rotor, *self.polled,
                     *self.otrsp, *self.flex):
            if part is not None:
                try:
                    await part.close()
                except Exception:
                    log.exception("while closing %s", part.label)


def _map_text(mapping: SliceMap) -> str:
    def name(ref: RadioRef) -> str:
        return f"station {ref[0]} radio {ref[1]}"

    if mapping.by_letter:
        return ", ".join(f"slice {k} to {name(ref)}" for k, ref in mapping.by_letter.items())
    text = f"the transmitting slice to {name(mapping.first)}" if mapping.first else ""
    if mapping.second is not None:
        text += f", the other slice in use to {name(mapping.second)}"
    return text


__all__ = ["RotatorHooks", "ServerSources", "SourceSettings"]
