"""A one-screen description of a valid configuration, for ``moas-server --check``."""

from __future__ import annotations

from .model import Config, Radio, Rotator, RotatorControl
from .relays import relay_span
from .rigs import DEFAULT_RETRY, FLRIG_PORT, RIGCTLD_PORT, split_address

BANDS = (
    ("160 m", 1800, 2000), ("80 m", 3500, 4000), ("60 m", 5330, 5410), ("40 m", 7000, 7300),
    ("30 m", 10100, 10150), ("20 m", 14000, 14350), ("17 m", 18068, 18168),
    ("15 m", 21000, 21450), ("12 m", 24890, 24990), ("10 m", 28000, 29700),
    ("6 m", 50000, 54000),
)


def _covers(config: Config, antenna_id: int, low: float, high: float) -> bool:
    antenna = config.antenna(antenna_id)
    if antenna is None:
        return False
    for control in antenna.control:
        r = control.range
        if (r.lower is None or r.lower <= high) and (r.upper is None or r.upper >= low):
            return True
    return False


def summarize(config: Config) -> str:
    """The station in a few lines: switches, radios, antennas per band, rotators."""
    lines = [(f"{config.name}: {len(config.antennas)} antennas, {len(config.systems)} systems, "
              f"{len(config.radios)} radios, {len(config.switches)} switches, "
              f"{len(config.rotators)} rotators, {len(config.functions)} functions, "
              f"{len(config.layouts)} layouts")]
    lines.append("Switches:")
    for s in config.switches:
        echo = f", unit id {s.echo}" if s.echo is not None else ""
        lines.append(f"  {s.id}: port {s.port}, relays {relay_span(s.id)}{echo}")
    lines.append("Radios:")
    single = config.switches[0].id if len(config.switches) == 1 else 0
    for r in config.radios:
        ports = ", ".join(f"switch {p.switch or single} port {p.port}" for p in r.switches)
        mode = "interrupt" if r.interrupt else "wait"
        extra = _radio_extras(config, r)
        tail = f"; {'; '.join(extra)}" if extra else ""
        lines.append(f"  station {r.station} radio {r.radio}: {ports}, {mode} mode{tail}")
    lines.append("Antennas per band:")
    lines.extend(_band_lines(config))
    if config.rotators:
        lines.append("Rotators:")
        lines.extend(_rotator_line(rot) for rot in config.rotators)
    lines.extend(_logger_lines(config))
    lines.extend(_rig_lines(config))
    return "\n".join(lines)


def _radio_extras(config: Config, r: Radio) -> list[str]:
    """What a radio's line adds after its mode: who inhibits it, its sub receiver and how
    that follows it, its partners, its alternate rules."""
    extra = []
    if r.always:
        extra.append("inhibited by " + ", ".join(str(x) for x in r.always))
    if r.sub_receiver is not None:
        sub = config.radio(r.station, r.sub_receiver)
        how = [text for on, text in (
            (r.use_main_freq or bool(sub and sub.use_main_freq), "on this radio's frequency"),
            (r.persist_sub_receiver or bool(sub and sub.persist_sub_receiver),
             "relays kept during transmit")) if on]
        extra.append(f"sub receiver radio {r.sub_receiver}"
                     + (f" ({', '.join(how)})" if how else ""))
    if r.partner:
        extra.append("partner " + ", ".join(str(x) for x in r.partner))
    if r.alternate:
        extra.append(f"{len(r.alternate)} alternate rule{'s' if len(r.alternate) > 1 else ''}"
                     + (" (AltActive " + ", ".join(str(x) for x in r.alt_active) + ")"
                        if r.alt_active else ""))
    return extra


def _band_lines(config: Config) -> list[str]:
    """Per band some antenna covers: how many do and the first eight's labels."""
    lines = []
    for name, low, high in BANDS:
        ids = [a.id for a in config.antennas if _covers(config, a.id, low, high)]
        if ids:
            labels = ", ".join(config.antenna(i).label for i in ids[:8])  # type: ignore[union-attr]
            more = f" and {len(ids) - 8} more" if len(ids) > 8 else ""
            lines.append(f"  {name:>5}: {len(ids):3d}  {labels}{more}")
    return lines


def _rotator_line(rot: Rotator) -> str:
    """A rotator: its label, how it is driven and where, its rotation and stop."""
    where = ""
    if rot.control is RotatorControl.SERIAL:
        where = f" {rot.model} on {rot.comm_port} via {rot.address}"
    elif rot.control in (RotatorControl.ROTATOR_GENIUS, RotatorControl.HAMLIB):
        where = f" at {rot.address}"
    return (f"  {rot.id}: {rot.label} ({rot.control.value}{where}), "
            f"{rot.rotation} degrees from {rot.ccw_limit}"
            f"{', with a stop' if rot.has_stop else ''}")


def _logger_lines(config: Config) -> list[str]:
    """The client port and the loggers listened to: N1MM Logger, DXLog.net, Win-Test and
    N1MM's rotor window."""
    n1mm = "on" if config.use_n1mm_logger else "off"
    lines = [f"Clients on TCP {config.tcp_port}; N1MM Logger on UDP {config.udp_port}: {n1mm}"]
    if config.use_dxlog:
        lines.append(f"DXLog.net on UDP {config.dxlog_port}")
    if config.use_wintest:
        names = ", ".join(f"{w.station_name} = station {w.station} radio {w.radio}"
                          for w in config.wintest) or "no station names"
        lines.append(f"Win-Test on UDP {config.wintest_port}: {names}")
    if config.use_n1mm_rotor:
        where = ", ".join(config.n1mm_rotor_headings) or "nowhere"
        lines.append(f"N1MM rotor window: commands on UDP {config.n1mm_rotor_port}, "
                     f"headings to {where}")
    return lines


def _rig_lines(config: Config) -> list[str]:
    """One line per rig daemon the server polls and per OTRSP port it reads."""
    lines = []
    for name, entries, default_port in (("rigctld", config.rigctld, RIGCTLD_PORT),
                                        ("flrig", config.flrig, FLRIG_PORT)):
        for rig in entries:
            host, port = split_address(rig.address, default_port)
            off = "" if rig.enabled else " (Enabled: false, not polled)"
            lines.append(f"{name} at {host}:{port}: station {rig.station} radio {rig.radio}, "
                         f"{rig.rate:g} polls a second{_retry(rig.retry)}{off}")
    for otrsp in config.otrsp:
        aux = [f"AUX{n} {e.value} = {_antenna(config, e.antenna)}"
               for n, table in ((1, otrsp.aux1), (2, otrsp.aux2)) for e in table]
        off = "" if otrsp.enabled else " (Enabled: false, not read)"
        lines.append(f"OTRSP on {otrsp.port}: station {otrsp.station}, radio 1 = radio "
                     f"{otrsp.radio1}, radio 2 = radio {otrsp.radio2}"
                     f"{'; ' + ', '.join(aux) if aux else '; no AUX antennas'}"
                     f"{_retry(otrsp.retry)}{off}")
    for flex in config.flex_radios:
        slices = f"slices {flex.slices}" if flex.slices.strip() else (
            f"the transmitting slice station {flex.station} radio 1, the other radio 2")
        off = "" if flex.enabled else " (Enabled: false, not read)"
        lines.append(f"FlexRadio {flex.address}: {slices}{_retry(flex.retry)}{off}")
    return lines


def _retry(seconds: float) -> str:
    return "" if seconds == DEFAULT_RETRY else f", first retry after {seconds:g} s"


def _antenna(config: Config, antenna_id: int) -> str:
    antenna = config.antenna(antenna_id)
    return f"antenna {antenna_id}" + (f" ({antenna.label})" if antenna is not None else "")


__all__ = ["summarize"]
