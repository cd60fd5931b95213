"""The station plan: what a configuration does, band by band, radio by radio, before the
contest (``moas-server --plan FILE``, View > Station plan).

Every answer comes from the real engine: each scenario runs on a fresh copy of a new
:class:`~moas_gui.engine.Engine` for the file (nothing is carried from one scenario to the
next, and no switch is touched).  The scenarios:

* each radio alone on each band its station's antennas cover, at the band's CW and phone
  frequencies (:data:`FREQUENCIES`, those an antenna covers) or at the frequencies the
  operator names (``--plan-khz``);
* each pair of radios that can meet (the same station, antennas or conflicts in common,
  or an inhibit relation between them): both on one band at each of its frequencies, and
  on every two different bands at their first frequencies; the lower-numbered radio tunes
  first.  Then each radio of the pair is keyed in turn, to see whether the other is
  inhibited while it transmits.

The text (:meth:`Plan.to_text`) and the window show an operator what matters: a pair only
where it differs from each radio alone, no rule codes (``--json`` has every scenario with
its rule, and each finding's kind).

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
FREQUENCIES: dict[str, tuple[tuple[float, str], ...]] = {
    "160 m": ((1825, "CW"), (1850, "phone")), "80 m": ((3525, "CW"), (3800, "phone")),
    "60 m": ((5370, ""),), "40 m": ((7025, "CW"), (7200, "phone")),
    "30 m": ((10125, "CW"),), "20 m": ((14025, "CW"), (14250, "phone")),
    "17 m": ((18080, "CW"), (18130, "phone")), "15 m": ((21025, "CW"), (21300, "phone")),
    "12 m": ((24900, "CW"), (24950, "phone")), "10 m": ((28025, "CW"), (28400, "phone")),
    "6 m": ((50090, "CW"), (50150, "phone")), "4 m": ((70250, ""),),
    "2 m": ((144050, "CW"), (144300, "phone")), "70 cm": ((432050, "CW"), (432200, "phone")),
}
"""The frequencies a band is planned on (kHz, mode), where the station's antennas cover them."""

FINDING_KINDS: dict[str, str] = {
    "unreachable_antenna": "an antenna no radio can ever get",
    "radio_without_antenna": "a radio with no antenna on a band its antennas cover for others",
    "band_pair_blocked": "two bands on which two radios cannot both have an antenna "
                         "(or cannot both transmit)",
    "band_taken": "a band on which two radios cannot both have an antenna "
                  "(or cannot both transmit)",
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
    """The band's first planned frequency (the one the pairs of radios on two bands use)."""
    frequencies: tuple[tuple[float, str], ...] = ()
    """Every planned frequency (kHz, mode: "CW", "phone" or "" for one the operator named
    or one inside the only range an antenna covers)."""
    uncovered: tuple[tuple[float, str], ...] = ()
    """The band's usual frequencies no antenna of the station covers (left out)."""

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "low": self.low, "high": self.high, "probe_khz": self.probe,
                "frequencies": [{"khz": k, "mode": m} for k, m in self.frequencies],
                "uncovered": [{"khz": k, "mode": m} for k, m in self.uncovered]}

    def at(self, khz: float) -> str:
        """``"14025 kHz CW"``: a planned frequency in words."""
        mode = dict(self.frequencies).get(khz, "")
        return f"{khz:g} kHz {mode}".rstrip()


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
    receives: bool = False
    """The radio has a receive antenna covering its frequency (whether or not it can transmit)."""

    @property
    def has_antenna(self) -> bool:
        """The radio has an antenna that covers its frequency."""
        return self.suitable

    def same_antennas(self, other: Outcome) -> bool:
        return (self.tx, self.rx, self.inhibited) == (other.tx, other.rx, other.inhibited)

    def to_dict(self) -> dict[str, Any]:
        return {"station": self.radio.station, "radio": self.radio.radio, "band": self.band,
                "khz": self.khz, "tx": self.tx, "rx": self.rx, "suitable": self.suitable,
                "receives": self.receives,
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
class PairNote:
    """One thing a pair of radios changes from each radio alone (what the plan's text and
    window show of a pair)."""

    where: str
    """``"both on 20 m at 14025 kHz CW"``, ``"160 m + 80 m"``, or ``"every band"``."""
    bands: frozenset[str]
    radio: RadioRef | None
    outcome: Outcome | None
    """The radio's outcome (None: a note on both radios)."""
    text: str


@dataclass(frozen=True, slots=True)
class Finding:
    kind: str
    """The finding's rule code (one of :data:`FINDING_KINDS`): shown in ``--json`` only."""
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

    def band(self, name: str) -> Band:
        return next(b for b in self.bands if b.name == name)

    def alone_at(self, ref: RadioRef, khz: float) -> Outcome | None:
        """What ``ref`` gets alone at ``khz`` (None: not planned there)."""
        return next((o for o in self.alone if o.radio == ref and o.khz == khz), None)

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
        """The antennas ``o`` passed over for a reason other than not covering its frequency
        (those are many and say nothing), grouped by reason, lowest first."""
        groups: dict[str, list[str]] = {}
        for a, reason in o.passed_over:
            if not reason.startswith("does not cover"):
                groups.setdefault(reason, []).append(self.name(a))
        return "; ".join(f"{', '.join(names)}: {reason}" for reason, names in groups.items())

    def antennas_of(self, o: Outcome) -> str:
        """The antennas of ``o`` in words, transmit and receive told apart."""
        if o.tx is None and o.rx is None:
            return "no antenna"
        if o.tx == o.rx:
            return self.name(o.tx)
        if o.tx is None:
            return f"no transmit antenna, receives on {self.name(o.rx)}"
        if o.rx is None:
            return f"transmits on {self.name(o.tx)}, no receive antenna"
        return f"transmits on {self.name(o.tx)}, receives on {self.name(o.rx)}"

    def describe(self, o: Outcome, alone: bool = True) -> str:
        """What ``o`` got and why, without the radio (``alone``: leave out what the other
        radio of a pair does while it transmits)."""
        text = f"{self.antennas_of(o)} \u2014 {o.text}"
        if o.inhibited and not o.inhibited_by:
            plain = not o.note or o.tx is None or \
                o.note == f"{self.name(o.tx)} does not cover {o.khz:g} kHz"
            text += "; cannot transmit" if plain else f"; cannot transmit: {o.note}"
        if o.inhibited_by and not alone:
            text += f"; {_cannot_transmit(o.inhibited_by)}"
        return text

    def pair_notes(self, a: RadioRef, b: RadioRef,
                   scenarios: list[PairScenario]) -> list[PairNote]:
        """What the pair ``a``, ``b`` changes from each radio alone: a note per radio that
        gets other antennas than alone, and one for an inhibit while the other transmits
        (once for the pair when it holds wherever the radio is not inhibited anyway, on every
        band or on every band they share).  Where a band's frequencies give the same notes,
        they are one note for the band."""
        summed = self._summed_inhibits(a, b, scenarios)
        notes: list[PairNote] = []
        every = frozenset(x.name for x in self.bands)
        if len(set(summed.values())) == 1 and len(summed) == 2:
            notes.append(PairNote(summed[a], every, None, None,
                                  "while one transmits, the other cannot (it is inhibited)"))
        else:
            for ref, where in summed.items():
                other = b if ref == a else a
                notes.append(PairNote(where, every, ref, None,
                                      f"{_radio(ref)} cannot transmit while "
                                      f"{_radio(other).lower()} transmits (it is inhibited)"))
        groups: dict[tuple[bool, RadioRef, str], list[tuple[PairScenario, Outcome, str]]] = {}
        for s in scenarios:
            for o in (s.first, s.second):
                text = self._pair_text(o, o.radio in summed)
                if text:
                    key = (s.same_band, o.radio, _generic(text, o.khz))
                    groups.setdefault(key, []).append((s, o, text))
        ordered = sorted(groups.items(), key=lambda item: not item[0][0])
        for (same, ref, generic), found in ordered:
            where = (self._same_where([o for _s, o, _t in found]) if same
                     else self._cross_where([s for s, _o, _t in found], scenarios))
            bands = frozenset(b for s, _o, _t in found for b in (s.first.band, s.second.band))
            text = found[0][2] if len(found) == 1 else generic
            notes.append(PairNote(where, bands, ref, found[0][1], text))
        return notes

    def _same_where(self, outcomes: list[Outcome]) -> str:
        """Where a pair on one band gives the same: whole bands by name, a frequency of a
        band where the band's others differ, or "any band"."""
        khz = {o.khz for o in outcomes}
        whole = [b.name for b in self.bands if all(k in khz for k, _m in b.frequencies)]
        parts = [b.name if b.name in whole else f"{b.name} at {b.at(k)}"
                 for b in self.bands for k, _m in b.frequencies[:1 if b.name in whole else None]
                 if k in khz]
        if len(whole) == len(self.bands) > 1:
            return "both on any band"
        return "both on " + _or(parts)

    @staticmethod
    def _cross_where(found: list[PairScenario], scenarios: list[PairScenario]) -> str:
        every = [s for s in scenarios if not s.same_band]
        if len(found) == len(every) > 1:
            return "any two bands"
        return _or([f"{s.first.band} + {s.second.band}" for s in found])

    def _summed_inhibits(self, a: RadioRef, b: RadioRef,
                         scenarios: list[PairScenario]) -> dict[RadioRef, str]:
        """The radios of a pair inhibited while the other transmits in every scenario where
        they are not inhibited anyway (or in every same-band one, and no other), and where."""
        summed: dict[RadioRef, str] = {}
        for ref in (a, b):
            same = [o for s in scenarios if s.same_band for o in (s.first, s.second)
                    if o.radio == ref]
            others = [o for s in scenarios if not s.same_band for o in (s.first, s.second)
                      if o.radio == ref]
            if _always_inhibited(same + others):
                summed[ref] = "every band and every two bands" if others else "every band"
            elif _always_inhibited(same) and not any(o.inhibited_by for o in others):
                summed[ref] = "every band they share"
        return summed

    def _pair_text(self, o: Outcome, summed: bool) -> str:
        """What a radio of a pair gets that differs from it alone (empty: nothing)."""
        alone = self.alone_at(o.radio, o.khz)
        moved = alone is None or not o.same_antennas(alone)
        if not moved and (not o.inhibited_by or summed):
            return ""
        if not moved:
            return f"{_radio(o.radio)}: {_cannot_transmit(o.inhibited_by)}"
        text = f"{_radio(o.radio)}: {self.describe(o, alone=summed)}"
        return text + (f" (alone: {self.antennas_of(alone)})" if alone is not None else "")

    def not_planned(self) -> str:
        """The bands' usual frequencies no antenna covers, in words (empty: none)."""
        gaps = [f"{b.name} {k:g} kHz {m}".rstrip() for b in self.bands for k, m in b.uncovered]
        return "Not planned (no antenna covers them): " + ", ".join(gaps) if gaps else ""

    def to_text(self) -> str:
        """The plan as an operator reads it: the frequencies, what each radio gets alone,
        what each pair of radios changes, and the findings."""
        named = any(m == "" for b in self.bands for _k, m in b.frequencies)
        out = [f"Station plan of {self.file}",
               "Bands: " + ", ".join(b.name for b in self.bands)
               + (" (at the frequencies below)" if named
                  else " (the bands the antennas cover, at their CW and phone frequencies)")]
        if self.not_planned():
            out.append(self.not_planned())
        if not self.bands:
            out[1] = "Bands: none (no antenna of the station covers a band the plan knows)"
        out += ["", "Each radio alone"] if self.bands else []
        for band in self.bands:
            out += self._alone_band(band)
        for a, b, meet, scenarios in self.pairs if self.bands else ():
            out += ["", (f"{_radio(a)} and {_radio(b).lower()} ({meet}; "
                         f"{_radio(a).lower()} tunes first)")]
            notes = self.pair_notes(a, b, scenarios)
            where = ""
            for n in notes:
                if n.outcome is None:
                    out.append(f"  on {n.where}: {n.text}")
                    where = ""
                    continue
                if n.where != where:
                    where = n.where
                    out.append(f"  {where}:")
                out.append(f"    {n.text}")
            summed = self._summed_inhibits(a, b, scenarios)
            quiet = [s for s in scenarios if not any(
                self._pair_text(o, o.radio in summed) for o in (s.first, s.second))]
            if len(quiet) == len(scenarios):
                out.append("  each gets the antennas it gets alone, on every band"
                           + (" and every two bands" if len(self.bands) > 1 else ""))
            elif quiet:
                out.append("  otherwise each gets the antennas it gets alone")
        out.append("")
        out.append(findings_text(self.findings, self.file))
        return "\n".join(out) + "\n"

    def _alone_band(self, band: Band) -> list[str]:
        """A band's lines of the radios alone: one block for the band when its frequencies
        read the same (the frequency said as "its frequency"), else a block per frequency."""
        blocks = [self._alone_groups([o for o in self.alone if o.khz == k], k)
                  for k, _m in band.frequencies]
        if not blocks:
            return []
        if len(blocks) > 1 and all(
                [(_generic(t, k), _generic(p, k), r) for t, p, r in block]
                == [(_generic(t, band.probe), _generic(p, band.probe), r)
                    for t, p, r in blocks[0]]
                for block, (k, _m) in zip(blocks, band.frequencies, strict=True)):
            heads: list[tuple[str, float | None, list[list[tuple[str, str, list[RadioRef]]]]]] \
                = [(f"  {band.name} at " + " and ".join(
                    band.at(k) for k, _m in band.frequencies), band.probe, blocks[:1])]
        else:
            heads = [(f"  {band.name} at {band.at(k)}", None, [block])
                     for (k, _m), block in zip(band.frequencies, blocks, strict=True)]
        out = []
        for head, generic, (block,) in heads:
            out.append(head)
            for text, passed, refs in block:
                if generic is not None:
                    text, passed = _generic(text, generic), _generic(passed, generic)
                out.append(f"    {_radios(refs)}: {text}")
                if passed:
                    out.append(f"      passed over: {passed}")
        return out

    def _alone_groups(self, outcomes: list[Outcome],
                      khz: float) -> list[tuple[str, str, list[RadioRef]]]:
        """The radios at one frequency, those that get the same for the same reason as one
        group: (what they get, what they passed over, the radios)."""
        del khz
        groups: dict[tuple[str, str], list[RadioRef]] = {}
        for o in outcomes:
            groups.setdefault((self.describe(o), self.passed_over(o)), []).append(o.radio)
        return [(t, p, refs) for (t, p), refs in groups.items()]


def _always_inhibited(outcomes: list[Outcome]) -> bool:
    """Whether the other radio's transmit inhibits this one in some of ``outcomes`` and in
    every one where it is not inhibited anyway."""
    return any(o.inhibited_by for o in outcomes) and all(
        o.inhibited_by or o.inhibited for o in outcomes)


def _generic(text: str, khz: float) -> str:
    """``text`` with ``khz`` said as "its frequency" (to tell whether two frequencies of a
    band read the same)."""
    return text.replace(f"{khz:g} kHz", "its frequency")


def findings_text(findings: Iterable[Finding], file: str) -> str:
    """The findings, one a line with the file's line to look at, then the count."""
    items = list(findings)
    lines = [f"Findings ({len(items)})"]
    for f in items:
        where = f"{file}:{f.line}" if f.line else file
        lines.append(f"  {where}: {f.text}")
    if not items:
        lines.append("  none")
    return "\n".join(lines)


def _radio(ref: RadioRef) -> str:
    return f"Station {ref.station} radio {ref.radio}"


def _radios(refs: list[RadioRef]) -> str:
    """``"Station 1 radios 1 and 2, station 2 radio 1"``."""
    by: dict[int, list[int]] = {}
    for ref in refs:
        by.setdefault(ref.station, []).append(ref.radio)
    parts = []
    for st, numbers in by.items():
        if len(numbers) == 1:
            parts.append(f"station {st} radio {numbers[0]}")
        else:
            parts.append(f"station {st} radios {_and([str(n) for n in numbers])}")
    text = _and(parts)
    return text[:1].upper() + text[1:]


def _and(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _or(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " or " + items[-1]


def _cannot_transmit(reason: str) -> str:
    """An inhibit while another radio transmits, in words that say it is about transmit."""
    if reason.startswith("inhibited while "):
        return f"cannot transmit while {reason.removeprefix('inhibited while ')}"
    return f"cannot transmit: {reason}"


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

def bands_of(ix: ConfigIndex, khz: Iterable[float] | None = None) -> tuple[Band, ...]:
    """The bands the station's antennas cover, each with its CW and phone frequencies
    (:data:`FREQUENCIES`) that some antenna covers; or, for ``khz``, the bands of those
    frequencies, each planned at the ones named (:class:`ValueError` for a frequency in no
    band the plan knows)."""
    if khz is not None:
        return _named_bands(sorted(set(khz)))
    segments = [seg for ref in ix.mains for seg in ix.radios[ref].bands]
    out = []
    for name, low, high in BANDS:
        touching = sorted(s for s in segments if s[0] <= high and s[1] >= low)
        if not touching:
            continue
        usual = FREQUENCIES[name]
        covered = tuple(f for f in usual if any(s[0] <= f[0] <= s[1] for s in touching))
        uncovered = tuple(f for f in usual if f not in covered)
        if not covered:
            first = touching[0]
            covered = (((max(first[0], low) + min(first[1], high)) / 2, ""),)
        out.append(Band(name, float(low), float(high), float(covered[0][0]),
                        tuple((float(k), m) for k, m in covered),
                        tuple((float(k), m) for k, m in uncovered)))
    return tuple(out)


def _named_bands(khz: list[float]) -> tuple[Band, ...]:
    out = []
    for k in khz:
        if not any(low <= k <= high for _n, low, high in BANDS):
            raise ValueError(f"{k:g} kHz is in no amateur band the plan knows "
                             "(160 m to 70 cm)")
    for name, low, high in BANDS:
        here = tuple((float(k), "") for k in khz if low <= k <= high)
        if here:
            out.append(Band(name, float(low), float(high), here[0][0], here))
    return tuple(out)


def _outcome(e: Engine, ix: ConfigIndex, ref: RadioRef, band: Band, khz: float) -> Outcome:
    v: RadioView = e.radio_view(ref.station, ref.radio)
    why = v.why
    info = ix.radios[ref]
    suitable = v.tx is not None and info.covers(v.tx, khz) and (
        v.rx is None or info.covers(v.rx, khz))
    heard = v.rx if v.rx is not None else v.tx
    receives = heard is not None and info.covers(heard, khz)
    return Outcome(ref, band.name, khz, v.tx, v.rx, v.inhibited, v.note,
                   why.rule if why is not None else "", why.text if why is not None else "",
                   why.passed_over if why is not None else (), suitable, "", receives)


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
               in_time: Callable[[], None] = lambda: None,
               khz: Iterable[float] | None = None) -> Plan:
    """The station plan of ``config`` (``text``: the file's text, for the findings' lines;
    ``in_time``: called as the plan goes, it may stop it by raising :class:`PlanTooLong`;
    ``khz``: the frequencies to plan instead of each covered band's CW and phone ones)."""
    template = Engine(config)
    in_time()
    ix: ConfigIndex = template._ix
    bands = bands_of(ix, khz)
    radios = tuple(ref for ref in ix.order if ix.radios[ref].kind is RadioKind.MAIN)
    antennas = {a: ix.antennas[a].title for a in ix.ids}
    plan = Plan(file or (config.path.name if config.path else "configuration"), bands, radios,
                antennas)
    for band in bands:
        for k, _mode in band.frequencies:
            for ref in radios:
                in_time()
                e = template.clone()
                e.set_frequency(ref.station, ref.radio, k)
                plan.alone.append(_outcome(e, ix, ref, band, k))
    # a pair on one band: at each of its frequencies; on two bands: at their first ones
    tries = [(ba, k, ba, k) for ba in bands for k, _m in ba.frequencies]
    tries += [(ba, ba.probe, bb, bb.probe) for ba in bands for bb in bands if ba is not bb]
    for i, a in enumerate(radios):
        for b in radios[i + 1:]:
            meet = meeting(ix, a, b)
            if not meet:
                continue
            scenarios = []
            for ba, ka, bb, kb in tries:
                in_time()
                e = template.clone()
                e.set_frequency(a.station, a.radio, ka)
                e.set_frequency(b.station, b.radio, kb)
                first = _outcome(e, ix, a, ba, ka)
                second = _outcome(e, ix, b, bb, kb)
                first = _with_inhibit(first, _keyed(e, ix, b, a))
                second = _with_inhibit(second, _keyed(e, ix, a, b))
                scenarios.append(PairScenario(first, second))
            plan.pairs.append((a, b, meet, scenarios))
    from .findings import find

    plan.findings = find(plan, template, Lines(text), in_time)
    return plan


def _with_inhibit(o: Outcome, reason: str) -> Outcome:
    if not reason:
        return o
    return Outcome(o.radio, o.band, o.khz, o.tx, o.rx, o.inhibited, o.note, o.rule, o.text,
                   o.passed_over, o.suitable, reason, o.receives)


def plan_file(path: str | Path,
              khz: Iterable[float] | None = None) -> tuple[Plan | None, str]:
    """The plan of the file at ``path`` (``khz``: see :func:`build_plan`), or None and every
    problem in words."""
    from moas_gui.config import load_config

    path = Path(path)
    result = load_config(path)
    if result.config is None:
        return None, "\n".join(str(p) for p in result.problems)
    return plan_of(result.config, path, khz=khz)


def plan_of(config: Config, path: Path | None,
            in_time: Callable[[], None] = lambda: None,
            khz: Iterable[float] | None = None) -> tuple[Plan | None, str]:
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
        return build_plan(config, path.name if path is not None else "", text, in_time,
                          khz), ""
    except EngineError as exc:  # a scenario the engine refuses is a bug, said plainly
        return None, f"{path or 'the configuration'}: the plan could not be made: {exc}"


__all__ = [
    "BANDS",
    "FINDING_KINDS",
    "FREQUENCIES",
    "Band",
    "Finding",
    "Lines",
    "Outcome",
    "PairNote",
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
