"""``KIND[:OPTIONS]``: a source named on ``moas-client``'s command line (or in its menu).

``OPTIONS`` is a comma-separated list of ``name=value``; one item without a
``=`` is the source's address.  The station is ``station=N``, or else the
client's ``--station``; the rest, per kind (docs/sources.md and docs/client.md):

=========  ====================================  =====================================
kind       address (item without ``=``)          names
=========  ====================================  =====================================
rigctld    ``[HOST:]PORT`` (127.0.0.1:4532)      ``station``, ``radio`` (1),
                                                 ``rate`` (polls/s, 10), ``retry`` (s, 0.5)
flrig      ``[HOST:]PORT`` (127.0.0.1:12345)     ``station``, ``radio`` (1), ``rate`` (10),
                                                 ``retry``
otrsp      the serial port (required)            ``station``, ``radio1``, ``radio2`` (1, 2),
                                                 ``retry``;
                                                 ``ant<R>.<N>=ID``: AUX<R> value N is antenna ID
n1mm       UDP port (12060)                      ``bind`` (0.0.0.0)
dxlog      UDP port (12060)                      ``bind``
wintest    UDP port (9871)                       ``name`` (the Win-Test station name,
                                                 required), ``radio`` (1), ``bind``
flex       the FlexRadio's ``ADDR[:PORT]``,      ``station``, ``radio1``, ``radio2`` (1, 2:
           serial number or nickname (required)  the transmitting slice and the other;
                                                 ``radio2=0``: the other slice unused),
                                                 or ``a``...``h`` (slice letter to radio,
                                                 ``a=1,b=2``), ``retry``
=========  ====================================  =====================================

Examples: ``rigctld``, ``rigctld:4534,radio=2``, ``flrig:shack-pc:12345``,
``otrsp:/dev/ttyUSB1,ant1.3=5,ant2.3=6``, ``wintest:name=STN1``,
``flex:192.168.1.50``, ``flex:Shack,a=1,b=2``.

The server runs rigctld, flrig and OTRSP sources too: from its configuration's
``Rigctld``, ``Flrig`` and ``OTRSP`` entries, whose names are these options'
(:mod:`moas_gui.config.rigs`), and from ``moas-server --source``, which needs
``station=N`` (:func:`server_spec`).  :func:`config_specs` turns the entries
into the same :class:`SourceSpec` a command line gives.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Final

from moas_gui.config.rigs import (
    FLRIG_PORT,
    HIGHEST_RATE,
    HIGHEST_RETRY,
    LOWEST_RATE,
    LOWEST_RETRY,
    RIGCTLD_PORT,
    split_address,
)
from moas_gui.sources.base import DEFAULT_RETRY, Source, SourceSink

if TYPE_CHECKING:  # the client's --source reads no configuration file
    from moas_gui.config.model import Config

KINDS: Final = ("rigctld", "flrig", "otrsp", "n1mm", "dxlog", "wintest", "flex")
SERVER_KINDS: Final = ("rigctld", "flrig", "otrsp")
"""What ``moas-server --source`` runs (the loggers' listeners have their own keys)."""
_NAMES: Final[dict[str, frozenset[str]]] = {
    "rigctld": frozenset({"station", "radio", "rate", "retry"}),
    "flrig": frozenset({"station", "radio", "rate", "retry"}),
    "otrsp": frozenset({"station", "radio1", "radio2", "retry"}),
    "n1mm": frozenset({"bind"}),
    "dxlog": frozenset({"bind"}),
    "wintest": frozenset({"name", "radio", "bind"}),
    "flex": frozenset({"station", "radio1", "radio2", "retry", *"abcdefgh"}),
}


@dataclass(frozen=True, slots=True)
class SourceSpec:
    """One parsed ``KIND[:OPTIONS]``."""

    kind: str
    address: str = ""
    options: Mapping[str, str] = field(default_factory=dict)
    antennas: Mapping[tuple[int, int], int] = field(default_factory=dict)
    """OTRSP only: (radio 1/2, AUX value) to antenna ID."""

    def text(self) -> str:
        """Back to the command-line form (for the menu and QSettings)."""
        items = [self.address] if self.address else []
        items += [f"{k}={v}" for k, v in self.options.items()]
        items += [f"ant{r}.{n}={a}" for (r, n), a in self.antennas.items()]
        return self.kind + (":" + ",".join(items) if items else "")


def parse_spec(text: str) -> SourceSpec:
    """``KIND[:OPTIONS]`` to a :class:`SourceSpec`; :class:`ValueError` saying what is wrong."""
    kind, _, rest = text.strip().partition(":")
    kind = kind.strip().lower()
    if kind not in KINDS:
        raise ValueError(f"{kind or text!r} is not a source; the sources are {', '.join(KINDS)}")
    address, options, antennas = "", {}, {}
    for item in (i.strip() for i in rest.split(",")) if rest else ():
        if not item:
            continue
        name, eq, value = item.partition("=")
        name = name.strip().lower()
        if not eq:
            if address:
                raise ValueError(f"{kind}: two addresses, {address!r} and {item!r}")
            address = item
        elif kind == "otrsp" and name.startswith("ant"):
            antennas[_aux_key(name, item)] = _number(value, item, 0)
        elif name in _NAMES[kind]:
            options[name] = value.strip()
        else:
            raise ValueError(f"{kind}: {name!r} is not one of its options "
                             f"({', '.join(sorted(_NAMES[kind]))})")
    spec = SourceSpec(kind, address, options, antennas)
    _check(spec)
    return spec


def _aux_key(name: str, item: str) -> tuple[int, int]:
    radio, dot, value = name[3:].partition(".")
    if not dot or radio not in ("1", "2"):
        raise ValueError(f"otrsp: {item!r} should be ant1.N=ID or ant2.N=ID")
    return int(radio), _number(value, item, 0, 255)


def _number(text: str, item: str, low: int, high: int = 2_147_483_647) -> int:
    try:
        value = int(text.strip())
    except ValueError:
        raise ValueError(f"{item!r}: {text.strip()!r} is not a whole number") from None
    if not low <= value <= high:
        raise ValueError(f"{item!r}: {value} is not between {low} and {high}")
    return value


def _host_port(spec: SourceSpec, default: int) -> tuple[str, int]:
    try:
        return split_address(spec.address, default)
    except ValueError as exc:
        raise ValueError(f"{spec.address!r}: {exc}") from None


def _decimal(text: str, name: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{name}={text} is not a number") from None
    return value  # NaN and infinities fail the range checks


def _check(spec: SourceSpec) -> None:
    if spec.kind == "otrsp" and not spec.address:
        raise ValueError("otrsp needs the serial port: otrsp:/dev/ttyUSB1 or otrsp:COM5")
    if spec.kind == "flex" and not spec.address:
        raise ValueError("flex needs the radio: flex:192.168.1.50, or its serial number or "
                         "nickname")
    if spec.kind == "wintest" and not spec.options.get("name"):
        raise ValueError("wintest needs the Win-Test station name: wintest:name=STN1")
    for name in ("station", "radio", "radio1", "radio2", *"abcdefgh"):
        if name in spec.options:
            _number(spec.options[name], f"{name}={spec.options[name]}", 0)
    if "rate" in spec.options:
        rate = _decimal(spec.options["rate"], "rate")
        if not LOWEST_RATE <= rate <= HIGHEST_RATE:
            raise ValueError(f"rate={rate:g}: polls a second must be between 0.1 and 100")
    if "retry" in spec.options:
        retry = _decimal(spec.options["retry"], "retry")
        if not LOWEST_RETRY <= retry <= HIGHEST_RETRY:
            raise ValueError(f"retry={retry:g}: the first pause after a failure must be "
                             "between 0.01 and 10 seconds")
    if spec.kind in ("rigctld", "flrig", "n1mm", "dxlog", "wintest") and spec.address:
        _host_port(spec, 1)


def server_spec(text: str) -> SourceSpec:
    """``moas-server --source``: a rigctld, flrig or OTRSP source naming its ``station``."""
    spec = parse_spec(text)
    if spec.kind not in SERVER_KINDS:
        raise ValueError(f"the server's --source runs {', '.join(SERVER_KINDS)}; {spec.kind} "
                         "is turned on in the configuration (docs/sources.md)")
    if "station" not in spec.options:
        raise ValueError(f"{spec.kind}: the server needs the station this source feeds: "
                         f"{spec.text()},station=N")
    return spec


def config_specs(config: Config) -> list[SourceSpec]:
    """The configuration's enabled ``Rigctld``, ``Flrig`` and ``OTRSP`` entries, as specs."""
    specs = []
    for kind, rigs in (("rigctld", config.rigctld), ("flrig", config.flrig)):
        for rig in rigs:
            if rig.enabled:
                specs.append(SourceSpec(kind, rig.address, {
                    "station": str(rig.station), "radio": str(rig.radio),
                    "rate": f"{rig.rate:g}", "retry": f"{rig.retry:g}"}))
    for otrsp in config.otrsp:
        if otrsp.enabled:
            specs.append(SourceSpec("otrsp", otrsp.port, {
                "station": str(otrsp.station), "radio1": str(otrsp.radio1),
                "radio2": str(otrsp.radio2), "retry": f"{otrsp.retry:g}"}, otrsp.antennas()))
    return specs


def make_source(spec: SourceSpec, station: int, sink: SourceSink) -> Source:
    """The running-to-be source of ``spec`` for ``station`` (unless the spec names its own),
    handing its events to ``sink``."""
    o = spec.options
    station = int(o.get("station", station))
    radio = int(o.get("radio", "1"))
    interval = 1.0 / float(o.get("rate", "10"))
    retry = float(o.get("retry", str(DEFAULT_RETRY)))
    if spec.kind in ("rigctld", "flrig"):
        from moas_gui.sources.flrig import FlrigSource
        from moas_gui.sources.rigctld import RigctldSource

        rig = RigctldSource if spec.kind == "rigctld" else FlrigSource
        host, port = _host_port(spec, RIGCTLD_PORT if spec.kind == "rigctld" else FLRIG_PORT)
        return rig(station, radio, sink, host=host, port=port, interval=interval, retry=retry)
    if spec.kind == "otrsp":
        from moas_gui.sources.otrsp import OtrspMap, OtrspSource

        radios = {1: int(o.get("radio1", "1")), 2: int(o.get("radio2", "2"))}
        return OtrspSource(spec.address, OtrspMap(station, radios, dict(spec.antennas)), sink,
                           retry=retry)
    if spec.kind == "flex":
        return _flex_source(spec, station, retry, sink)
    bind = o.get("bind", "0.0.0.0")
    if spec.kind == "wintest":
        from moas_gui.sources.wintest import WinTestListener
        from moas_gui.sources.wintest_frame import DEFAULT_PORT as WT_PORT

        _, port = _host_port(spec, WT_PORT)
        return WinTestListener({o["name"]: (station, radio)}, sink, port=port, host=bind)
    from moas_gui.sources.dxlog import DXLogListener
    from moas_gui.sources.n1mm import DEFAULT_PORT as N1MM_PORT
    from moas_gui.sources.n1mm import N1MMListener

    _, port = _host_port(spec, N1MM_PORT)
    listener = DXLogListener if spec.kind == "dxlog" else N1MMListener
    return listener({}, on_event=sink, every_sender=station, port=port, host=bind)


def _flex_source(spec: SourceSpec, station: int, retry: float, sink: SourceSink) -> Source:
    from moas_gui.sources.flex import FlexSource
    from moas_gui.sources.flex_api import SliceMap

    o = spec.options
    letters = {k.upper(): (station, int(v)) for k, v in o.items() if len(k) == 1}
    if letters:
        mapping = SliceMap(by_letter=letters)
    else:
        second = int(o.get("radio2", "2"))
        mapping = SliceMap((station, int(o.get("radio1", "1"))),
                           (station, second) if second else None)
    return FlexSource(spec.address, mapping, sink, retry=retry)


__all__ = ["KINDS", "SERVER_KINDS", "SourceSpec", "config_specs", "make_source", "parse_spec",
           "server_spec"]
