"""Typed, read-only views of what the server tells a client.

The client protocol (``docs/client-protocol.md``) sends plain JSON objects.
This module turns them into frozen dataclasses, checking each field on the way
in, so a window never has to guess whether ``heading`` is a number.  A field
the contract names but the server left out, or one of the wrong type, raises
:class:`~moas_gui.errors.ProtocolError` with a sentence saying which field of
which entry was wrong; fields the contract does not know are ignored (the
protocol may grow).

A few optional fields are read when present, because the protocol is expected
to grow them; without them the views fall back to plain defaults:

``antennas[].offset``
    degrees the antenna points clockwise of its rotator's heading (default 0).
``rotators[].long``, ``ccw_limit``, ``rotation``, ``has_stop``
    the rotator's travel (``CCWLimit``, ``Rotation``, ``HasStop`` of the
    configuration); when ``ccw_limit`` or ``rotation`` is missing the travel is
    unknown and no dead zone is drawn.
``rotators[].electrical``
    true for an electrically switched system (a 4-square): its directions are
    the offsets of the antennas that use it.
``radios[].relative``
    the radio's relative antenna list for its frequency, as antenna IDs.
``radios[].alt_why``
    why the radio has no alternate receive antenna while a transmitting radio would switch
    it to one (default "").

The view classes copy the server's (``engine/views.py``, ``engine/why.py``'s
``Why``, ``hw/rotators/base.py``'s ``RotatorView``) on purpose: the client never
imports the engine.  ``tests/client/test_client_views_in_step.py`` fails when an
engine view gains a field this copy lacks, unless its ``LEFT_OUT`` list says why.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from datetime import datetime
from enum import StrEnum
from typing import Any, TypeVar

from moas_gui.errors import ProtocolError

__all__ = [
    "AntennaView",
    "ButtonState",
    "ButtonType",
    "ButtonView",
    "LayoutView",
    "RadioKey",
    "RadioView",
    "RotatorView",
    "Snapshot",
    "SwitchView",
    "WhyView",
    "explain",
    "local_time",
    "may_release",
    "parse_antenna",
    "parse_layout",
    "parse_radio",
    "parse_rotator",
    "parse_snapshot",
    "parse_switch",
]

_T = TypeVar("_T")

RadioKey = tuple[int, int]
"""A radio's (station, radio) numbers."""


class ButtonType(StrEnum):
    """What a layout button does when pressed."""

    ANTENNA = "Antenna"
    FUNCTION = "Function"


class ButtonState(StrEnum):
    """How a layout button is shown (manual 5.16)."""

    SELECTED = "selected"
    AVAILABLE = "available"
    UNAVAILABLE = "unavailable"


# -- field readers ----------------------------------------------------------------------------


class _Fields:
    """Reads the fields of one JSON object, naming it in every complaint."""

    __slots__ = ("_obj", "_where")

    def __init__(self, obj: object, where: str) -> None:
        if not isinstance(obj, Mapping):
            raise ProtocolError(f"{where} is {_describe(obj)}, not a JSON object")
        self._obj: Mapping[str, Any] = obj
        self._where = where

    def _get(self, name: str, optional: bool) -> tuple[bool, Any]:
        if name not in self._obj:
            if optional:
                return False, None
            raise ProtocolError(f"{self._where} has no '{name}' field")
        return True, self._obj[name]

    def _fail(self, name: str, value: object, wanted: str) -> ProtocolError:
        return ProtocolError(f"{self._where}: '{name}' is {_describe(value)}, not {wanted}")

    def whole(self, name: str) -> int:
        _, value = self._get(name, optional=False)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self._fail(name, value, "a whole number")
        return value

    def opt_int(self, name: str) -> int | None:
        _, value = self._get(name, optional=True)
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, int):
            raise self._fail(name, value, "a whole number or null")
        return value

    def opt_float(self, name: str) -> float | None:
        _, value = self._get(name, optional=True)
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self._fail(name, value, "a number or null")
        return float(value)

    def number(self, name: str, default: float) -> float:
        value = self.opt_float(name)
        return default if value is None else value

    def flag(self, name: str, default: bool = False, optional: bool = True) -> bool:
        present, value = self._get(name, optional)
        if not present or value is None:
            return default
        if not isinstance(value, bool):
            raise self._fail(name, value, "true or false")
        return value

    def text(self, name: str, default: str = "", optional: bool = True) -> str:
        present, value = self._get(name, optional)
        if not present or value is None:
            return default
        if not isinstance(value, str):
            raise self._fail(name, value, "a string")
        return value

    def items(self, name: str, optional: bool = False) -> list[Any]:
        present, value = self._get(name, optional)
        if not present or value is None:
            return []
        if not isinstance(value, list):
            raise self._fail(name, value, "a list")
        return value


def _describe(value: object) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        shown = value if len(value) <= 20 else value[:17] + "..."
        return f"the string {shown!r}"
    if isinstance(value, int | float):
        return f"the number {value!r}"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, Mapping):
        return "an object"
    return type(value).__name__


# -- views --------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class WhyView:
    """Why the server gave a radio its antennas (a radio entry's ``why``)."""

    rule: str
    text: str
    passed_over: tuple[tuple[int, str], ...] = ()


@dataclass(frozen=True, slots=True)
class RadioView:
    """One radio as the server reports it (snapshot ``radios`` / ``radio`` event)."""

    station: int
    radio: int
    khz: float | None = None
    tx_khz: float | None = None
    tx: int | None = None
    rx: int | None = None
    alt: int | None = None
    transmitting: bool = False
    inhibited: bool = False
    note: str = ""
    relative: tuple[int, ...] | None = None
    radio_rx_antenna: bool = False
    """The receive antenna is on the radio's own RX-antenna input (switch that input on)."""
    active: bool = False
    """This radio has its station's transmit focus (an SO2R logger's active radio)."""
    focus: bool = False
    """This radio has its station's receive focus (the operator is on it)."""
    why: WhyView | None = None
    """Why the radio has these antennas (None when the server did not say)."""
    held_by: str | None = None
    """Who holds the radio's antennas against its frequency changes (an Antenna Genius
    client's ``auto=0``), None when they follow the frequency."""
    held_since: str | None = None
    """When that hold began (ISO 8601 in UTC, as the server says it), None when not held."""
    alt_why: str = ""
    """Why the radio has no alternate receive antenna while a transmitting radio would
    switch it to one ("" when it has one or needs none)."""

    @property
    def held_text(self) -> str:
        """The hold in words for a display line, empty when none."""
        if not self.held_by:
            return ""
        since = local_time(self.held_since)
        return (f"Held by {self.held_by}{f' since {since}' if since else ''}: "
                "the antennas do not follow the frequency")

    @property
    def key(self) -> RadioKey:
        return (self.station, self.radio)


@dataclass(frozen=True, slots=True)
class AntennaView:
    """One antenna (or antenna system choice) of the configuration."""

    id: int
    short: str = ""
    long: str = ""
    rotator: int | None = None
    offset: float = 0.0

    @property
    def name(self) -> str:
        """The long name, else the short one, else its number."""
        return self.long or self.short or f"Antenna {self.id}"


@dataclass(frozen=True, slots=True)
class RotatorView:
    """One rotator: where it points, where it is going, and (when sent) its travel."""

    id: int
    short: str = ""
    long: str = ""
    heading: float | None = None
    target: float | None = None
    moving: bool = False
    online: bool = True
    ccw_limit: float | None = None
    rotation: float | None = None
    has_stop: bool = False
    electrical: bool = False

    @property
    def name(self) -> str:
        return self.short or self.long or f"Rotator {self.id}"

    @property
    def travel_known(self) -> bool:
        return self.ccw_limit is not None and self.rotation is not None


@dataclass(frozen=True, slots=True)
class SwitchView:
    """One MOAS II switch's link status: connecting, ok, unresponsive or stopped."""

    id: int
    status: str


@dataclass(frozen=True, slots=True)
class ButtonView:
    """One button of a layout."""

    row: int
    column: int
    type: ButtonType
    id: int
    label: str
    state: ButtonState
    reason: str = ""
    """Why an unavailable button is unavailable (the server's words; "" when not said)."""


@dataclass(frozen=True, slots=True)
class LayoutView:
    """The layout the server chose for one radio and a wanted grid size."""

    station: int
    radio: int
    rows: int
    columns: int
    buttons: tuple[ButtonView, ...] = ()

    @property
    def key(self) -> RadioKey:
        return (self.station, self.radio)

    def button_at(self, row: int, column: int) -> ButtonView | None:
        for button in self.buttons:
            if button.row == row and button.column == column:
                return button
        return None


@dataclass(frozen=True, slots=True)
class Snapshot:
    """The whole state (``state`` result or event), kept current by the change events."""

    config: str = ""
    radios: tuple[RadioView, ...] = ()
    antennas: tuple[AntennaView, ...] = ()
    rotators: tuple[RotatorView, ...] = ()
    switches: tuple[SwitchView, ...] = ()
    _antenna_index: dict[int, AntennaView] = field(
        default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        self._antenna_index.update((a.id, a) for a in self.antennas)

    def radio(self, station: int, radio: int) -> RadioView | None:
        for entry in self.radios:
            if entry.station == station and entry.radio == radio:
                return entry
        return None

    def antenna(self, antenna_id: int | None) -> AntennaView | None:
        if antenna_id is None:
            return None
        return self._antenna_index.get(antenna_id)

    def rotator(self, rotator_id: int | None) -> RotatorView | None:
        if rotator_id is None:
            return None
        for entry in self.rotators:
            if entry.id == rotator_id:
                return entry
        return None

    @property
    def stations(self) -> tuple[int, ...]:
        return tuple(sorted({r.station for r in self.radios}))

    def radios_of(self, station: int) -> tuple[int, ...]:
        return tuple(sorted(r.radio for r in self.radios if r.station == station))

    def with_radio(self, entry: RadioView) -> Snapshot:
        """This snapshot with one radio replaced (or added when new)."""
        radios = _replace_by(self.radios, entry, lambda r: r.key == entry.key)
        return replace(self, radios=radios)

    def with_rotator(self, entry: RotatorView) -> Snapshot:
        rotators = _replace_by(self.rotators, entry, lambda r: r.id == entry.id)
        return replace(self, rotators=rotators)

    def with_switch(self, entry: SwitchView) -> Snapshot:
        switches = _replace_by(self.switches, entry, lambda s: s.id == entry.id)
        return replace(self, switches=switches)

    def antennas_with_rotator(self, rotator_id: int) -> tuple[AntennaView, ...]:
        return tuple(a for a in self.antennas if a.rotator == rotator_id)


def _replace_by(items: tuple[_T, ...], new: _T, same: Callable[[_T], bool]) -> tuple[_T, ...]:
    out = [new if same(item) else item for item in items]
    if not any(same(item) for item in items):
        out.append(new)
    return tuple(out)


# -- parsers -----------------------------------------------------------------------------------


def parse_radio(obj: object, where: str = "radio") -> RadioView:
    f = _Fields(obj, where)
    relative_raw = obj.get("relative") if isinstance(obj, Mapping) else None
    relative: tuple[int, ...] | None = None
    if relative_raw is not None:
        items = f.items("relative", optional=True)
        for index, item in enumerate(items):
            if isinstance(item, bool) or not isinstance(item, int):
                raise ProtocolError(
                    f"{where}: relative[{index}] is {_describe(item)}, not an antenna number")
        relative = tuple(items)
    return RadioView(
        station=f.whole("station"),
        radio=f.whole("radio"),
        khz=f.opt_float("khz"),
        tx_khz=f.opt_float("tx_khz"),
        tx=f.opt_int("tx"),
        rx=f.opt_int("rx"),
        alt=f.opt_int("alt"),
        transmitting=f.flag("transmitting"),
        inhibited=f.flag("inhibited"),
        note=f.text("note"),
        relative=relative,
        radio_rx_antenna=f.flag("radio_rx_antenna"),
        active=f.flag("active"),
        focus=f.flag("focus"),
        why=_parse_why(obj.get("why") if isinstance(obj, Mapping) else None, f"{where}: why"),
        held_by=f.text("held_by") or None,
        held_since=f.text("held_since") or None,
        alt_why=f.text("alt_why"),
    )


def local_time(utc: str | None) -> str:
    """A moment the server gave in UTC (``2026-11-29T08:14:03Z``) as this computer's
    clock shows it (``09:14``, with the date when it is not today); empty when there
    is none or it cannot be read."""
    if not utc:
        return ""
    try:
        moment = datetime.fromisoformat(utc).astimezone()  # Python 3.11 reads the Z
    except ValueError:
        return ""
    today = datetime.now().astimezone().date()
    return moment.strftime("%H:%M" if moment.date() == today else "%Y-%m-%d %H:%M")


def may_release(operator: Mapping[str, Any] | None, station: int, radio: int) -> bool:
    """Whether the one a client acts as may release a hold on that radio: anonymous
    (no ``operator`` in the hello's result: this computer, or an open LAN) yes; an
    operator by its role, ``admin`` always, ``operate`` on its radios, ``view`` never."""
    if not isinstance(operator, Mapping):
        return True
    role = operator.get("role")
    if role == "admin":
        return True
    if role != "operate":
        return False
    radios = operator.get("radios")
    return radios is None or (isinstance(radios, list) and [station, radio] in radios)


def _parse_why(obj: object, where: str) -> WhyView | None:
    """A radio entry's ``why`` (None when absent: servers before 0.1 do not send it)."""
    if obj is None:
        return None
    f = _Fields(obj, where)
    passed = []
    for index, item in enumerate(f.items("passed_over", optional=True)):
        g = _Fields(item, f"{where}: passed_over[{index}]")
        passed.append((g.whole("antenna"), g.text("reason")))
    return WhyView(f.text("rule"), f.text("text"), tuple(passed))


def explain(radio: RadioView, snapshot: Snapshot | None) -> str:
    """The radio's ``why`` in words for a tooltip: the reason, then each antenna passed over,
    then why it has no alternate antenna (when the server says)."""
    why = radio.why
    lines = []
    if why is not None:
        lines.append(why.text[:1].upper() + why.text[1:])
        for antenna, reason in why.passed_over:
            found = snapshot.antenna(antenna) if snapshot is not None else None
            lines.append(f"  {found.name if found is not None else f'Antenna {antenna}'}: "
                         f"{reason}")
    if radio.alt_why:
        lines.append(f"No alternate antenna {radio.alt_why}")
    return "\n".join(lines)


def parse_antenna(obj: object, where: str = "antenna") -> AntennaView:
    f = _Fields(obj, where)
    return AntennaView(
        id=f.whole("id"),
        short=f.text("short"),
        long=f.text("long"),
        rotator=f.opt_int("rotator"),
        offset=f.number("offset", 0.0),
    )


def parse_rotator(obj: object, where: str = "rotator") -> RotatorView:
    f = _Fields(obj, where)
    return RotatorView(
        id=f.whole("id"),
        short=f.text("short"),
        long=f.text("long"),
        heading=f.opt_float("heading"),
        target=f.opt_float("target"),
        moving=f.flag("moving"),
        online=f.flag("online", default=True),
        ccw_limit=f.opt_float("ccw_limit"),
        rotation=f.opt_float("rotation"),
        has_stop=f.flag("has_stop"),
        electrical=f.flag("electrical"),
    )


def parse_switch(obj: object, where: str = "switch") -> SwitchView:
    f = _Fields(obj, where)
    return SwitchView(id=f.whole("id"), status=f.text("status", optional=False))


def parse_button(obj: object, where: str = "button") -> ButtonView:
    f = _Fields(obj, where)
    kind = f.text("type", optional=False)
    state = f.text("state", optional=False)
    try:
        button_type = ButtonType(kind)
    except ValueError:
        raise ProtocolError(f"{where}: 'type' is {kind!r}, not Antenna or Function") from None
    try:
        button_state = ButtonState(state)
    except ValueError:
        raise ProtocolError(
            f"{where}: 'state' is {state!r}, not selected, available or unavailable") from None
    return ButtonView(
        row=f.whole("row"),
        column=f.whole("column"),
        type=button_type,
        id=f.whole("id"),
        label=f.text("label"),
        state=button_state,
        reason=f.text("reason"),
    )


def parse_layout(obj: object, where: str = "layout") -> LayoutView:
    f = _Fields(obj, where)
    buttons = tuple(
        parse_button(item, f"{where} buttons[{index}]")
        for index, item in enumerate(f.items("buttons")))
    return LayoutView(
        station=f.whole("station"),
        radio=f.whole("radio"),
        rows=f.whole("rows"),
        columns=f.whole("columns"),
        buttons=buttons,
    )


def parse_snapshot(obj: object, where: str = "state") -> Snapshot:
    f = _Fields(obj, where)
    return Snapshot(
        config=f.text("config"),
        radios=tuple(parse_radio(item, f"{where} radios[{i}]")
                     for i, item in enumerate(f.items("radios"))),
        antennas=tuple(parse_antenna(item, f"{where} antennas[{i}]")
                       for i, item in enumerate(f.items("antennas"))),
        rotators=tuple(parse_rotator(item, f"{where} rotators[{i}]")
                       for i, item in enumerate(f.items("rotators"))),
        switches=tuple(parse_switch(item, f"{where} switches[{i}]")
                       for i, item in enumerate(f.items("switches", optional=True))),
    )
