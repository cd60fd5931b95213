"""The station plan: what a configuration does, band by band, radio by radio, before the
contest (``moas-server --plan FILE``, View > Station plan).

Every answer comes from the real engine: each scenario runs on a fresh copy of a new
:class:`~moas_gui.engine.Engine` for the file (nothing is carried from one scenario to the
next, and no switch is touched).  The scenarios:

* each radio alone on each band (the bands its antennas cover, and always the contest
  bands 160-10 m), tuned to the band's probe frequency (25 kHz above the band's lower
  edge, or inside the first range an antenna covers there);
* each pair of radios that can meet (the same station, antennas or conflicts in common,
  or an inhibit relation between them): both on the same band, and on every two different
  bands; the lower-numbered radio tunes first.  Then each radio of the pair is keyed in
  turn, to see whether the other is inhibited while it transmits.

From the scenarios come *findings*: things a configuration author most likely did not
mean, each with the line of the file to look at.  The plan is deterministic: the same
file gives the same text and the same JSON.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from moas_gui.config.jsontree import JArray, JObject, JScalar, Member, Node, parse
from moas_gui.config.model import Config, RadioRef
from moas_gui.engine import Engine, EngineError
from moas_gui.engine.index import ConfigIndex, RadioKind
from moas_gui.engine.views import RadioView
from moas_gui.errors import MoasError

BANDS: tuple[tuple[str, float, float], ...] = (
    ("160 m", 1800, 2000), ("80 m", 3500, 4000), ("60 m", 5330, 5410), ("40 m", 7000, 7300),
    ("30 m", 10100, 10150), ("20 m", 14000, 14350), ("17 m", 18068, 18168),
    ("15 m", 21000, 21450), ("12 m", 24890, 24990), ("10 m", 28000, 29700),
    ("6 m", 50000, 54000), ("4 m", 70000, 70500), ("2 m", 144000, 148000),
    ("70 cm", 420000, 450000),
)
"""Amateur bands the plan knows (name, lower and upper edge in kHz)."""
CONTEST_BANDS = frozenset({"160 m", "80 m", "40 m", "20 m", "15 m", "10 m"})
"""Always in the plan, covered or not."""

FINDING_KINDS: dict[str, str] = {
    "unreachable_antenna": "an antenna no radio can ever get",
    "radio_without_antenna": "a radio with no antenna on a band its antennas cover for others",
    "band_pair_blocked": "two bands on which two radios cannot both have an antenna",
    "band_taken": "a conflict or system that takes a whole band from another radio",
    "inhibit_every_same_band": "an inhibit that fires whenever two radios share a band",
    "alternate_never_usable": "an alternate that is never usable",
    "alternate_can_be_transmitted_on": "an alternate receive antenna another radio can "
                                       "transmit on",
}
"""Every kind of finding, and what it means."""


@dataclass(frozen=True, slots=True)
class Band:
    name: str
    low: float
    high: float
    probe: float
    """The frequency the scenarios tune to."""

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "low": self.low, "high": self.high, "probe_khz": self.probe}


@dataclass(frozen=True, slots=True)
class Outcome:
    """What one radio got in one scenario."""

    radio: RadioRef
    band: str
    khz: float
    tx: int | None
    rx: int | None
    inhibited: bool
    note: str
    rule: str
    text: str
    passed_over: tuple[tuple[int, str], ...]
    suitable: bool = False
    """The radio has antennas covering its frequency (not merely the nearest ones)."""
    inhibited_by: str = ""
    """In a pair: why this radio is inhibited while the other transmits (empty: it is not)."""

    @property
    def has_antenna(self) -> bool:
        """The radio has an antenna that covers its frequency."""
        return self.suitable

    def to_dict(self) -> dict[str, Any]:
        return {"station": self.radio.station, "radio": self.radio.radio, "band": self.band,
                "khz": self.khz, "tx": self.tx, "rx": self.rx, "suitable": self.suitable,
                "inhibited": self.inhibited,
                "note": self.note,
                "why": {"rule": self.rule, "text": self.text,
                        "passed_over": [{"antenna": a, "reason": r}
                                        for a, r in self.passed_over]},
                "inhibited_while_other_transmits": self.inhibited_by or None}


@dataclass(frozen=True, slots=True)
class PairScenario:
    first: Outcome
    second: Outcome

    @property
    def same_band(self) -> bool:
        return self.first.band == self.second.band

    def to_dict(self) -> dict[str, Any]:
        return {"same_band": self.same_band, "first": self.first.to_dict(),
                "second": self.second.to_dict()}


@dataclass(frozen=True, slots=True)
class Finding:
    kind: str
    line: int
    """The line of the file to look at (0: the file as a whole)."""
    text: str
    radios: tuple[RadioRef, ...] = ()
    bands: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "line": self.line, "text": self.text,
                "radios": [[r.station, r.radio] for r in self.radios], "bands": list(self.bands)}


@dataclass(slots=True)
class Plan:
    """The whole plan of one configuration."""

    file: str
    bands: tuple[Band, ...]
    radios: tuple[RadioRef, ...]
    antennas: dict[int, str]
    alone: list[Outcome] = field(default_factory=list)
    pairs: list[tuple[RadioRef, RadioRef, str, list[PairScenario]]] = field(default_factory=list)
    """(first radio, second radio, why they can meet, scenarios)."""
    findings: list[Finding] = field(default_factory=list)

    def name(self, antenna: int | None) -> str:
        return "none" if antenna is None else self.antennas.get(antenna, f"Antenna {antenna}")

    # -- output -----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {
            "file": self.file,
            "bands": [b.to_dict() for b in self.bands],
            "radios": [[r.station, r.radio] for r in self.radios],
            "antennas": [{"id": a, "name": n} for a, n in sorted(self.antennas.items())],
            "alone": [o.to_dict() for o in self.alone],
            "pairs": [{"first": [a.station, a.radio], "second": [b.station, b.radio],
                       "meet": meet, "scenarios": [s.to_dict() for s in scenarios]}
                      for a, b, meet, scenarios in self.pairs],
            "findings": [f.to_dict() for f in self.findings],
        }

    def to_json(self) -> str:
        """:meth:`to_dict` as JSON text, one scenario or finding a line (small, and easy to
        compare line by line)."""
        data = self.to_dict()

        def one(value: object) -> str:
            return json.dumps(value, ensure_ascii=False, separators=(", ", ": "))

        def rows(items: list[Any], indent: str) -> str:
            if not items:
                return "[]"
            return "[\n" + ",\n".join(indent + " " + one(i) for i in items) + "\n" + indent + "]"

        parts = [f' "file": {one(data["file"])}', f' "bands": {rows(data["bands"], " ")}',
                 f' "radios": {one(data["radios"])}',
                 f' "antennas": {rows(data["antennas"], " ")}',
                 f' "alone": {rows(data["alone"], " ")}']
        pairs = []
        for p in data["pairs"]:
            head = {k: v for k, v in p.items() if k != "scenarios"}
            pairs.append("  " + one(head)[:-1] + ', "scenarios": '
                         + rows(p["scenarios"], "   ") + "}")
        parts.append(' "pairs": ' + ("[\n" + ",\n".join(pairs) + "\n ]" if pairs else "[]"))
        parts.append(f' "findings": {rows(data["findings"], " ")}')
        return "{\n" + ",\n".join(parts) + "\n}\n"

    def passed_over(self, o: Outcome) -> str:
        """The antennas ``o`` passed over, grouped by reason, lowest first."""
        groups: dict[str, list[str]] = {}
        for a, reason in o.passed_over:
            groups.setdefault(reason, []).append(self.name(a))
        return "; ".join(f"{', '.join(names)}: {reason}" for reason, names in groups.items())

    def _antennas(self, o: Outcome) -> str:
        if o.tx is None and o.rx is None:
            return "no antenna"
        if o.tx == o.rx:
            return self.name(o.tx)
        return f"TX {self.name(o.tx)}, RX {self.name(o.rx)}"

    def _line(self, o: Outcome) -> str:
        text = f"{_radio(o.radio)}: {self._antennas(o)} \u2014 {o.text} [{o.rule}]"
        if o.inhibited and not o.inhibited_by:
            text += f"; inhibited: {o.note}" if o.note else "; inhibited"
        if o.inhibited_by:
            text += f"; {o.inhibited_by}"
        return text

    def to_text(self) -> str:
        out = [f"Station plan of {self.file}",
               "Bands: " + ", ".join(f"{b.name} ({b.probe:g} kHz)" for b in self.bands), ""]
        out.append("Each radio alone")
        for band in self.bands:
            out.append(f"  {band.name} at {band.probe:g} kHz")
            for o in self.alone:
                if o.band != band.name:
                    continue
                out.append(f"    {self._line(o)}")
                if o.passed_over:
                    out.append(f"      passed over: {self.passed_over(o)}")
        for a, b, meet, scenarios in self.pairs:
            out.append("")
            out.append(f"{_radio(a)} and {_radio(b)} ({meet}; {_radio(a)} tunes first)")
            for s in scenarios:
                where = (f"both on {s.first.band}" if s.same_band
                         else f"{s.first.band} + {s.second.band}")
                out.append(f"  {where}:")
                out.append(f"    {self._line(s.first)}")
                out.append(f"    {self._line(s.second)}")
        out.append("")
        out.append(findings_text(self.findings, self.file))
        return "\n".join(out) + "\n"


def findings_text(findings: Iterable[Finding], file: str) -> str:
    """The findings, one a line with the file's line to look at, then the count."""
    items = list(findings)
    lines = [f"Findings ({len(items)})"]
    for f in items:
        where = f"{file}:{f.line}" if f.line else file
        lines.append(f"  {where}: {f.text} [{f.kind}]")
    if not items:
        lines.append("  none")
    return "\n".join(lines)


def _radio(ref: RadioRef) -> str:
    return f"Station {ref.station} radio {ref.radio}"


# -- where things are in the file ---------------------------------------------------------------

class Lines:
    """Lines of the configuration's groups and keys, read from the file's text."""

    def __init__(self, text: str | None) -> None:
        self._text = text
        self._read = False
        self._tree: JObject | None = None

    @property
    def _root(self) -> JObject | None:
        """The file's tree, read when a finding first asks for a line (reading a large
        file again costs more than many a plan)."""
        if not self._read:
            self._read = True
            if self._text is not None:
                root, _problems = parse(self._text, "")
                if isinstance(root, JObject):
                    self._tree = root
        return self._tree

    def _top(self, key: str) -> Node | None:
        member = _member(self._root, key)
        return member.value if member is not None else None

    def key(self, key: str) -> int:
        member = _member(self._root, key)
        return member.line if member is not None else 0

    def _group(self, array: str, match: dict[str, int]) -> JObject | None:
        node = self._top(array)
        if not isinstance(node, JArray):
            return None
        for item in node.items:
            if isinstance(item, JObject) and all(
                    _scalar(item, k) == v for k, v in match.items()):
                return item
        return None

    def antenna(self, antenna: int, key: str | None = None) -> int:
        return self._line(self._group("Antennas", {"ID": antenna}), key)

    def radio(self, ref: RadioRef, key: str | None = None) -> int:
        return self._line(self._group("Radios", {"Station": ref.station, "Radio": ref.radio}),
                          key)

    def system(self, system: int) -> int:
        return self._line(self._group("Systems", {"ID": system}), None)

    @staticmethod
    def _line(group: JObject | None, key: str | None) -> int:
        if group is None:
            return 0
        if key is not None:
            member = _member(group, key)
            if member is not None:
                return member.line
        return group.line


def _member(group: JObject | None, key: str) -> Member | None:
    if group is None:
        return None
    wanted = key.lower()
    for member in group.members:
        if member.key.lower() == wanted:
            return member
    return None


def _scalar(group: JObject, key: str) -> object:
    member = _member(group, key)
    if member is None or not isinstance(member.value, JScalar):
        return None
    return member.value.value


# -- the scenarios ------------------------------------------------------------------------------

def bands_of(ix: ConfigIndex) -> tuple[Band, ...]:
    """The contest bands and every other band some radio's antenna covers part of."""
    segments = [seg for ref in ix.mains for seg in ix.radios[ref].bands]
    out = []
    for name, low, high in BANDS:
        touching = sorted(s for s in segments if s[0] <= high and s[1] >= low)
        if not touching and name not in CONTEST_BANDS:
            continue
        probe = low + 25 if high - low > 50 else (low + high) / 2
        if touching and not any(s[0] <= probe <= s[1] for s in touching):
            first = touching[0]
            probe = (max(first[0], low) + min(first[1], high)) / 2
        out.append(Band(name, float(low), float(high), float(probe)))
    return tuple(out)


def _outcome(e: Engine, ix: ConfigIndex, ref: RadioRef, band: Band) -> Outcome:
    v: RadioView = e.radio_view(ref.station, ref.radio)
    why = v.why
    info = ix.radios[ref]
    suitable = v.tx is not None and info.covers(v.tx, band.probe) and (
        v.rx is None or info.covers(v.rx, band.probe))
    return Outcome(ref, band.name, band.probe, v.tx, v.rx, v.inhibited, v.note,
                   why.rule if why is not None else "", why.text if why is not None else "",
                   why.passed_over if why is not None else (), suitable)


def _keyed(e: Engine, ix: ConfigIndex, talker: RadioRef, listener: RadioRef) -> str:
    """Why ``listener`` is inhibited while ``talker`` transmits (empty when it is not)."""
    ports = ix.radios[talker].ports
    if not ports:
        return ""
    before = e.radio_view(listener.station, listener.radio)
    switch, port = ports[0]
    try:
        e.set_transmitting(switch, port, True)
        after = e.radio_view(listener.station, listener.radio)
    finally:
        e.set_transmitting(switch, port, False)
    if after.inhibited and not before.inhibited:
        return after.note or "inhibited"
    return ""


def meeting(ix: ConfigIndex, a: RadioRef, b: RadioRef) -> str:
    """Why radios ``a`` and ``b`` can meet (empty when they cannot)."""
    ia, ib = ix.radios[a], ix.radios[b]
    if a.station == b.station:
        return "same station"
    ca = {ix.canon[x] for x in ia.antennas}
    cb = {ix.canon[x] for x in ib.antennas}
    if ca & cb:
        return "antennas in common"
    if any(ix.conflict(x, y) for x in ia.antennas for y in ib.antennas):
        return "conflicting antennas"
    ra, rb = ia.radio, ib.radio
    if b in ra.always or a in rb.always or b in ra.same_band or a in rb.same_band \
            or set(ra.inhibit_buss) & set(rb.inhibit_buss):
        return "an inhibit relation"
    return ""


class PlanTooLong(MoasError):
    """The plan was not finished within the time it was given (``--check`` on a huge
    station: the whole plan is for ``--plan``)."""


def deadline_after(seconds: float | None) -> Callable[[], None]:
    """A check to call as the plan goes: raises :class:`PlanTooLong` once this process has
    spent ``seconds`` of processor time (never, for None).  Processor time measures the
    work, so a machine busy with other programs gives the same answer as an idle one."""
    if seconds is None:
        return lambda: None
    end = time.process_time() + seconds

    def check() -> None:
        if time.process_time() > end:
            raise PlanTooLong(f"not finished within {seconds:.1f} s")
    return check


def build_plan(config: Config, file: str = "", text: str | None = None,
               in_time: Callable[[], None] = lambda: None) -> Plan:
    """The station plan of ``config`` (``text``: the file's text, for the findings' lines;
    ``in_time``: called as the plan goes, it may stop it by raising :class:`PlanTooLong`)."""
    template = Engine(config)
    in_time()
    ix: ConfigIndex = template._ix
    bands = bands_of(ix)
    radios = tuple(ref for ref in ix.order if ix.radios[ref].kind is RadioKind.MAIN)
    antennas = {a: ix.antennas[a].title for a in ix.ids}
    plan = Plan(file or (config.path.name if config.path else "configuration"), bands, radios,
                antennas)
    for band in bands:
        for ref in radios:
            in_time()
            e = template.clone()
            e.set_frequency(ref.station, ref.radio, band.probe)
            plan.alone.append(_outcome(e, ix, ref, band))
    for i, a in enumerate(radios):
        for b in radios[i + 1:]:
            meet = meeting(ix, a, b)
            if not meet:
                continue
            scenarios = []
            for ba in bands:
                for bb in bands:
                    in_time()
                    e = template.clone()
                    e.set_frequency(a.station, a.radio, ba.probe)
                    e.set_frequency(b.station, b.radio, bb.probe)
                    first = _outcome(e, ix, a, ba)
                    second = _outcome(e, ix, b, bb)
                    first = _with_inhibit(first, _keyed(e, ix, b, a))
                    second = _with_inhibit(second, _keyed(e, ix, a, b))
                    scenarios.append(PairScenario(first, second))
            scenarios.sort(key=lambda s: (not s.same_band, _order(bands, s.first.band),
                                          _order(bands, s.second.band)))
            plan.pairs.append((a, b, meet, scenarios))
    from .findings import find

    plan.findings = find(plan, template, Lines(text), in_time)
    return plan


def _order(bands: tuple[Band, ...], name: str) -> int:
    return next(i for i, b in enumerate(bands) if b.name == name)


def _with_inhibit(o: Outcome, reason: str) -> Outcome:
    if not reason:
        return o
    return Outcome(o.radio, o.band, o.khz, o.tx, o.rx, o.inhibited, o.note, o.rule, o.text,
                   o.passed_over, o.suitable, reason)


def plan_file(path: str | Path) -> tuple[Plan | None, str]:
    """The plan of the file at ``path``, or None and every problem in words."""
    from moas_gui.config import load_config

    path = Path(path)
    result = load_config(path)
    if result.config is None:
        return None, "\n".join(str(p) for p in result.problems)
    return plan_of(result.config, path)


def plan_of(config: Config, path: Path | None,
            in_time: Callable[[], None] = lambda: None) -> tuple[Plan | None, str]:
    """The plan of a loaded configuration (``path``: its file, read again for the findings'
    lines), or None and why it could not be made.  :class:`PlanTooLong` from ``in_time``
    goes through to the caller."""
    text = None
    if path is not None:
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            text = None
    try:
        return build_plan(config, path.name if path is not None else "", text, in_time), ""
    except EngineError as exc:  # a scenario the engine refuses is a bug, said plainly
        return None, f"{path or 'the configuration'}: the plan could not be made: {exc}"


__all__ = [
    "BANDS",
    "CONTEST_BANDS",
    "FINDING_KINDS",
    "Band",
    "Finding",
    "Lines",
    "Outcome",
    "PairScenario",
    "Plan",
    "PlanTooLong",
    "RadioRef",
    "bands_of",
    "build_plan",
    "deadline_after",
    "findings_text",
    "meeting",
    "plan_file",
    "plan_of",
]
