"""An in-memory :class:`~moas_gui.net.backend.ClientBackend` for tests and demos.

It runs a :class:`~moas_gui.testing.fake_station.FakeStation` with simple rules
that are nonetheless real:

* an antenna in use by another radio (transmit or receive) is ``unavailable``,
  as is one that does not cover the radio's frequency, a receive-only antenna
  asked to transmit, a transmit-only one asked to receive, and any change of
  the transmit antenna while the radio transmits;
* a frequency change keeps antennas that still cover it, and otherwise takes
  the lowest-numbered free antenna that does (never a transmit-only one); a
  radio left without a transmit antenna is inhibited with a note saying why;
* functions ``swap`` (with the other station's radio, when each antenna covers
  the other's frequency) and ``rx_tx``; relative lists per frequency range,
  circular, skipping antennas that are unavailable (manual appendix G);
* the closest layout by rows and columns; rotators that turn when told
  (:meth:`FakeBackend.settle` makes them arrive).

There are no systems: ``exclusive`` is accepted and changes nothing.  Every
change is told to the attached :class:`~moas_gui.net.backend.EventSink` (a
``radio`` event for each radio that changed, then ``layouts_may_have_changed``),
as the application does after the engine answers.  Test hooks:
:meth:`set_transmitting`, :meth:`set_switch_status`, :meth:`set_rotator_online`,
:meth:`stop_switches`, :meth:`start_switches`, :meth:`unload`, :meth:`load`,
and ``calls`` (every backend call received, in order).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from moas_gui.net.backend import (
    ErrorCode,
    EventSink,
    FocusKind,
    JSONObject,
    RequestError,
    SwitchAction,
    Target,
)
from moas_gui.net.identity import Action, Forbidden, enforce

from .fake_station import DEMO_STATION, FakeAntenna, FakeLayout, FakeRelative, FakeStation


@dataclass(slots=True)
class _Radio:
    station: int
    radio: int
    khz: float
    tx_khz: float
    tx: int | None
    rx: int | None
    transmitting: bool = False
    active: bool = False
    focus: bool = False
    held_by: str | None = None
    held_since: str | None = None

    def view(self) -> JSONObject:
        inhibited = self.tx is None
        held: JSONObject = {"held_by": self.held_by} if self.held_by is not None else {}
        if self.held_since is not None:
            held["held_since"] = self.held_since
        return {
            "station": self.station, "radio": self.radio, "khz": self.khz,
            "tx_khz": self.tx_khz, "tx": self.tx, "rx": self.rx, "alt": None,
            "transmitting": self.transmitting, "inhibited": inhibited,
            "note": f"no free antenna covers {self.tx_khz:g} kHz" if inhibited else "",
            "active": self.active, "focus": self.focus, **held,
        }

    def __str__(self) -> str:
        return f"station {self.station} radio {self.radio}"


@dataclass(slots=True)
class _Rotator:
    id: int
    short: str
    heading: float
    online: bool
    target: float | None = None
    moving: bool = False

    def view(self) -> JSONObject:
        return {"id": self.id, "short": self.short, "heading": self.heading,
                "target": self.target, "moving": self.moving, "online": self.online}


def _err(code: ErrorCode, message: str) -> RequestError:
    return RequestError(code, message)


class FakeBackend:
    """A complete backend over an in-memory station; see the module's docstring."""

    def __init__(self, station: FakeStation = DEMO_STATION, sink: EventSink | None = None) -> None:
        self.station = station
        self.sink = sink
        self.calls: list[tuple[str, tuple[Any, ...]]] = []
        self.loaded = True
        self.closed = False
        """:meth:`close_configuration` was called: the state names no configuration."""
        self.running = True
        self._antennas = {a.id: a for a in station.antennas}
        self._functions = {f.id: f for f in station.functions}
        self._radios = {
            (r.station, r.radio): _Radio(r.station, r.radio, r.khz, r.khz, r.tx, r.rx)
            for r in station.radios
        }
        self._rotators = {r.id: _Rotator(r.id, r.short, r.heading, r.online)
                          for r in station.rotators}
        self._switches = {s: "ok" for s in station.switches}

    def attach(self, sink: EventSink | None) -> None:
        self.sink = sink

    # ---- ClientBackend --------------------------------------------------------------

    def snapshot(self) -> JSONObject:
        self.calls.append(("snapshot", ()))
        self._need_config()
        if self.closed:
            return {"config": None, "radios": [], "antennas": [], "rotators": [],
                    "switches": []}
        return {
            "config": self.station.name,
            "radios": [r.view() for r in self._radios.values()],
            "antennas": [{"id": a.id, "short": a.short, "long": a.long, "rotator": a.rotator}
                         for a in self.station.antennas],
            "rotators": [r.view() for r in self._rotators.values()],
            "switches": [{"id": s, "status": st} for s, st in self._switches.items()],
        }

    def frequency(self, station: int, radio: int, khz: float, tx_khz: float | None) -> None:
        self.calls.append(("frequency", (station, radio, khz, tx_khz)))
        _may(Action(f"tuning radio {station}/{radio}", frozenset({(station, radio)})))
        r = self._radio(station, radio, need_running=True)
        before = r.view()
        r.khz, r.tx_khz = khz, khz if tx_khz is None else tx_khz
        if not r.transmitting and not self._fits(r, r.tx, "tx"):
            r.tx = self._first_free(r, "tx")
        if not self._fits(r, r.rx, "rx"):
            r.rx = r.tx if self._fits(r, r.tx, "rx") else self._first_free(r, "rx")
        self._changed([r] if r.view() != before else [])

    def set_focus(self, station: int, radio: int, kind: FocusKind) -> None:
        self.calls.append(("set_focus", (station, radio, kind)))
        _may(Action(f"{kind} on radio {station}/{radio}", frozenset({(station, radio)})))
        self._radio(station, radio)
        changed = []
        for r in self._radios.values():
            if r.station == station and getattr(r, kind) != (r.radio == radio):
                setattr(r, kind, r.radio == radio)
                changed.append(r)
        if self.sink is not None:
            for r in changed:
                self.sink.publish_radio(r.view())

    def select(
        self, station: int, radio: int, antenna: int, target: Target, exclusive: bool
    ) -> JSONObject:
        self.calls.append(("select", (station, radio, antenna, target, exclusive)))
        _may(Action(f"selecting antennas of radio {station}/{radio}",
                    frozenset({(station, radio)})))
        r = self._radio(station, radio, need_running=True)
        a = self._antenna(antenna)
        for role in ("tx", "rx") if target == "both" else (target,):
            self._check_usable(r, a, role)
        before = r.view()
        if target in ("both", "tx"):
            r.tx = a.id
        if target in ("both", "rx"):
            r.rx = a.id
        self._changed([r] if r.view() != before else [])
        return {"tx": r.tx, "rx": r.rx}

    def release(self, station: int, radio: int) -> None:
        self.calls.append(("release", (station, radio)))
        _may(Action(f"releasing the hold of radio {station}/{radio}",
                    frozenset({(station, radio)})))
        self.set_held(station, radio, None)

    def function(self, station: int, radio: int, function: int) -> None:
        self.calls.append(("function", (station, radio, function)))
        _may(Action(f"function {function} for radio {station}/{radio}",
                    frozenset({(station, radio)})))
        r = self._radio(station, radio, need_running=True)
        f = self._functions.get(function)
        if f is None:
            raise _err(ErrorCode.NOT_FOUND, f"there is no function {function}")
        changed = self._swap(r) if f.kind == "swap" else self._rx_tx(r)
        self._changed(changed)

    def relative(
        self, station: int, radio: int, step: int | None, index: int | None
    ) -> JSONObject:
        self.calls.append(("relative", (station, radio, step, index)))
        _may(Action(f"selecting antennas of radio {station}/{radio}",
                    frozenset({(station, radio)})))
        r = self._radio(station, radio, need_running=True)
        ids = self._relative_list(r).ids
        if index is not None:
            if index >= len(ids):
                raise _err(ErrorCode.NOT_FOUND, f"the relative list of {r} at {r.khz:g} kHz "
                           f"has {len(ids)} antennas; there is no index {index}")
            choice = self._antennas[ids[index]]
            self._check_usable(r, choice, "tx")
            self._check_usable(r, choice, "rx")
        else:
            assert step is not None
            start = ids.index(r.tx) if r.tx in ids else -step  # none yet: from the top
            candidates = [ids[(start + step * n) % len(ids)] for n in range(1, len(ids) + 1)]
            usable = [i for i in candidates if self._usable(r, self._antennas[i])]
            if not usable:
                raise _err(ErrorCode.UNAVAILABLE, f"no relative antenna is available for {r}")
            choice = self._antennas[usable[0]]
        before = r.view()
        r.tx = r.rx = choice.id
        self._changed([r] if r.view() != before else [])
        return {"tx": r.tx, "rx": r.rx}

    def layout(self, station: int, radio: int, rows: int, columns: int) -> JSONObject:
        self.calls.append(("layout", (station, radio, rows, columns)))
        r = self._radio(station, radio)
        chosen = self._closest_layout(r, rows, columns)
        buttons: list[JSONObject] = []
        for entry in chosen.matrix:
            if not entry.holds(r.khz):
                continue
            for b in entry.buttons:
                if b.type == "Antenna":
                    a = self._antennas.get(b.id)
                    label = a.short if a is not None else f"#{b.id}"
                    state = self._button_state(r, a)
                else:
                    a = None
                    f = self._functions.get(b.id)
                    label = f.name if f is not None else f"#{b.id}"
                    state = "available" if f is not None and self._function_ok(r, f.kind) \
                        else "unavailable"
                shown: JSONObject = {"row": b.row, "column": b.column, "type": b.type,
                                     "id": b.id, "label": label, "state": state}
                if state == "unavailable":
                    shown["reason"] = self._unavailable_reason(r, b.type, label, a)
                buttons.append(shown)
        return {"station": station, "radio": radio, "rows": chosen.rows,
                "columns": chosen.columns, "buttons": buttons}

    def rotate(self, rotator: int, heading: float) -> None:
        self.calls.append(("rotate", (rotator, heading)))
        _may(Action(f"turning rotator {rotator}"))
        rot = self._rotator(rotator)
        if not rot.online:
            raise _err(ErrorCode.UNAVAILABLE, f"rotator {rot.id} ({rot.short}) is offline")
        rot.target, rot.moving = heading % 360.0, True
        self._tell_rotator(rot)

    def stop(self, rotator: int) -> None:
        self.calls.append(("stop", (rotator,)))
        _may(Action(f"stopping rotator {rotator}"))
        rot = self._rotator(rotator)
        if rot.moving or rot.target is not None:
            rot.target, rot.moving = None, False
            self._tell_rotator(rot)

    def switches(self, action: SwitchAction, force: bool = False) -> None:
        self.calls.append(("switches", (action,)))
        _may(Action(f"{action} the switches", admin=True))
        if action == "stop":
            self.stop_switches()
        elif action == "start":
            self.start_switches()

    # ---- test hooks -----------------------------------------------------------------

    def set_transmitting(self, station: int, radio: int, transmitting: bool) -> None:
        r = self._radio(station, radio)
        if r.transmitting != transmitting:
            r.transmitting = transmitting
            self._changed([r])

    def set_held(self, station: int, radio: int, by: str | None,
                 since: str | None = None) -> None:
        """An operator holds the radio's antennas (``by``, since ``since``: ISO 8601 UTC),
        or releases them (None)."""
        r = self._radio(station, radio)
        since = since if by is not None else None
        if (r.held_by, r.held_since) != (by, since):
            r.held_by, r.held_since = by, since
            self._changed([r])

    def set_switch_status(self, switch: int, status: str) -> None:
        self._switches[switch] = status
        if self.sink is not None:
            self.sink.publish_switch({"id": switch, "status": status})

    def set_rotator_online(self, rotator: int, online: bool) -> None:
        rot = self._rotator(rotator)
        rot.online = online
        self._tell_rotator(rot)

    def settle(self, rotator: int) -> None:
        """The rotator arrives at its target."""
        rot = self._rotator(rotator)
        if rot.target is not None:
            rot.heading, rot.target, rot.moving = rot.target, None, False
            self._tell_rotator(rot)

    def stop_switches(self) -> None:
        self.running = False
        for s in self._switches:
            self.set_switch_status(s, "stopped")

    def start_switches(self) -> None:
        self.running = True
        for s in self._switches:
            self.set_switch_status(s, "ok")

    def unload(self) -> None:
        self.loaded = False

    def close_configuration(self) -> None:
        """As the real server with no configuration open: its state names none."""
        self.closed = True
        if self.sink is not None:
            self.sink.publish_state()

    def load(self) -> None:
        self.loaded = True
        self.closed = False
        if self.sink is not None:
            self.sink.publish_state()

    # ---- rules ----------------------------------------------------------------------

    def _need_config(self) -> None:
        if not self.loaded:
            raise _err(ErrorCode.NOT_RUNNING, "no configuration is loaded")

    def _radio(self, station: int, radio: int, need_running: bool = False) -> _Radio:
        self._need_config()
        r = self._radios.get((station, radio))
        if r is None:
            raise _err(ErrorCode.NOT_FOUND, f"there is no station {station} radio {radio}")
        if need_running and not self.running:
            raise _err(ErrorCode.NOT_RUNNING, "the switches are stopped")
        return r

    def _antenna(self, antenna: int) -> FakeAntenna:
        a = self._antennas.get(antenna)
        if a is None:
            raise _err(ErrorCode.NOT_FOUND, f"there is no antenna {antenna}")
        return a

    def _rotator(self, rotator: int) -> _Rotator:
        self._need_config()
        rot = self._rotators.get(rotator)
        if rot is None:
            raise _err(ErrorCode.NOT_FOUND, f"there is no rotator {rotator}")
        return rot

    def _user(self, r: _Radio, a: FakeAntenna) -> _Radio | None:
        """Another radio using ``a``."""
        return next((o for o in self._radios.values()
                     if o is not r and a.id in (o.tx, o.rx)), None)

    def _check_usable(self, r: _Radio, a: FakeAntenna, role: str) -> None:
        khz = r.tx_khz if role == "tx" else r.khz
        if role == "tx" and a.rx_only:
            raise _err(ErrorCode.UNAVAILABLE, f"{a} is receive-only")
        if role == "rx" and a.tx_only:
            raise _err(ErrorCode.UNAVAILABLE, f"{a} is transmit-only")
        if not a.covers(khz):
            raise _err(ErrorCode.UNAVAILABLE, f"{a} does not cover {khz:g} kHz")
        other = self._user(r, a)
        if other is not None:
            raise _err(ErrorCode.UNAVAILABLE, f"{a} is in use by {other}")
        if role == "tx" and r.transmitting and r.tx != a.id:
            raise _err(ErrorCode.UNAVAILABLE, f"{r} is transmitting")

    def _fits(self, r: _Radio, antenna: int | None, role: str) -> bool:
        a = self._antennas.get(antenna) if antenna is not None else None
        if a is None:
            return False
        try:
            self._check_usable(r, a, role)
        except RequestError:
            return False
        return True

    def _usable(self, r: _Radio, a: FakeAntenna) -> bool:
        return self._fits(r, a.id, "tx") and self._fits(r, a.id, "rx")

    def _first_free(self, r: _Radio, role: str) -> int | None:
        """Automatic choice: never a transmit-only antenna (a dummy load, say)."""
        return next((a.id for a in sorted(self.station.antennas, key=lambda a: a.id)
                     if not a.tx_only and self._fits(r, a.id, role)), None)

    def _button_state(self, r: _Radio, a: FakeAntenna | None) -> str:
        if a is None:
            return "unavailable"
        if a.id in (r.tx, r.rx):
            return "selected"
        return "available" if self._fits(r, a.id, "rx") or self._fits(r, a.id, "tx") \
            else "unavailable"

    def _unavailable_reason(self, r: _Radio, kind: str, label: str,
                            a: FakeAntenna | None) -> str:
        """What a press of an unavailable button would be told, as the engine says it."""
        if kind != "Antenna":
            return f"{label} is not available: the radios' antennas do not allow it now"
        if a is None:
            return f"there is no antenna {label}"
        for role in ("rx", "tx"):
            try:
                self._check_usable(r, a, role)
            except RequestError as exc:
                return exc.message
        return f"{a} cannot be used now"

    def _other(self, r: _Radio) -> _Radio | None:
        return next((o for o in self._radios.values() if o.station != r.station), None)

    def _function_ok(self, r: _Radio, kind: str) -> bool:
        if kind == "rx_tx":
            return r.tx is not None and r.rx != r.tx and self._fits(r, r.tx, "rx")
        o = self._other(r)
        if o is None or r.transmitting or o.transmitting:
            return False
        rtx, rrx, otx, orx = (self._antennas.get(i) if i is not None else None
                              for i in (r.tx, r.rx, o.tx, o.rx))
        if rtx is None or rrx is None or otx is None or orx is None:
            return False
        return (otx.covers(r.tx_khz) and orx.covers(r.khz)
                and rtx.covers(o.tx_khz) and rrx.covers(o.khz))

    def _swap(self, r: _Radio) -> list[_Radio]:
        o = self._other(r)
        if o is None or not self._function_ok(r, "swap"):
            raise _err(ErrorCode.UNAVAILABLE, f"Swap is not possible now for {r}: both radios "
                       "need antennas that cover the other's frequency, and neither may transmit")
        r.tx, r.rx, o.tx, o.rx = o.tx, o.rx, r.tx, r.rx
        return [r, o]

    def _rx_tx(self, r: _Radio) -> list[_Radio]:
        if not self._function_ok(r, "rx_tx"):
            raise _err(ErrorCode.UNAVAILABLE, f"RX=TX is not applicable now for {r}")
        r.rx = r.tx
        return [r]

    def _relative_list(self, r: _Radio) -> FakeRelative:
        for entry in self.station.relative:
            if entry.low_khz <= r.khz <= entry.high_khz and entry.ids:
                return entry
        raise _err(ErrorCode.UNAVAILABLE, f"{r} has no relative antennas at {r.khz:g} kHz")

    def _closest_layout(self, r: _Radio, rows: int, columns: int) -> FakeLayout:
        fitting = [lay for lay in self.station.layouts
                   if lay.station in (None, r.station) and lay.radio in (None, r.radio)]
        if not fitting:
            raise _err(ErrorCode.NOT_FOUND, f"there is no layout for {r}")
        return min(fitting, key=lambda lay: (abs(lay.rows - rows) + abs(lay.columns - columns),
                                             lay.station is None, lay.radio is None))

    def _changed(self, radios: list[_Radio]) -> None:
        if self.sink is None or not radios:
            return
        for r in radios:
            self.sink.publish_radio(r.view())
        self.sink.layouts_may_have_changed()

    def _tell_rotator(self, rot: _Rotator) -> None:
        if self.sink is not None:
            self.sink.publish_rotator(rot.view())


def _may(action: Action) -> None:
    """The role check, as the real server's one door makes it (a refusal is ``forbidden``)."""
    try:
        enforce(action)
    except Forbidden as exc:
        raise RequestError(ErrorCode.FORBIDDEN, exc.message) from None


__all__ = ["FakeBackend"]
